// PCG32 random number generator (O'Neill 2014, "PCG: A Family of Simple Fast Space-Efficient
// Statistically Good Algorithms for Random Number Generation"), the XSH-RR 64/32 variant.
// Every (pixel, sample index) pair gets its own stream derived from the scene seed, so an image
// is bit-identical whatever the thread count or the order in which tiles are rendered, and any
// range of sample indices can be rendered separately and merged later.
#pragma once

#include <cstdint>

namespace ember {

// SplitMix64 finaliser (Steele et al. 2014): a bijective 64-bit mix used to decorrelate seeds.
inline uint64_t mix64(uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

class Rng {
 public:
  Rng() : Rng(0, 0) {}
  Rng(uint64_t seed, uint64_t stream) {
    inc_ = (stream << 1u) | 1u;
    state_ = 0;
    nextU32();
    state_ += seed;
    nextU32();
  }

  // The stream for one camera sample: independent of thread and tile.
  static Rng forSample(uint64_t sceneSeed, uint64_t pixelIndex, uint64_t sampleIndex) {
    return Rng(mix64(sceneSeed ^ mix64(sampleIndex)), mix64(pixelIndex + (sceneSeed << 32)));
  }

  uint32_t nextU32() {
    const uint64_t old = state_;
    state_ = old * 6364136223846793005ull + inc_;
    const auto xorshifted = static_cast<uint32_t>(((old >> 18u) ^ old) >> 27u);
    const auto rot = static_cast<uint32_t>(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((-rot) & 31u));
  }

  // Uniform in [0, 1): the top 24 bits scaled exactly, so 1.0 is never returned.
  float uniform() { return static_cast<float>(nextU32() >> 8) * 0x1p-24f; }

 private:
  uint64_t state_;
  uint64_t inc_;
};

}  // namespace ember
