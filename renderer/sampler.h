// The random numbers of one camera sample, dimension by dimension.
//
// Independent: every number from the sample's own PCG32 stream (core/rng.h), as Mitsuba's
//   `independent` sampler.
// Sobol: each successive 1D or 2D request is a dimension (pair) of an Owen-scrambled Sobol
//   (0,2)-sequence over the pixel's sample indices, with the sample order shuffled independently per
//   dimension ("padding"): Burley 2020, "Practical Hash-based Owen Scrambling" (JCGT 9(4)), with the
//   Laine-Karras style hash of that paper. The first two Sobol dimensions (van der Corput, and the
//   x+1 polynomial) are all it needs. Each 2D projection of a pixel's samples is stratified, so
//   low-dimensional integrands (pixel area, direct light) converge faster than with independent
//   numbers; past kMaxSobolDimensions the PCG32 stream takes over. The default sampler.
// Both are deterministic in (seed, pixel, sample index), so images do not depend on threads, and a
// range of sample indices rendered separately merges exactly with the rest.
#pragma once

#include "core/math.h"
#include "core/rng.h"

#include <cstdint>

namespace ember {

enum class SamplerType { Independent, Sobol };

class Sampler {
 public:
  Sampler(SamplerType type, uint64_t seed, uint64_t pixel, uint64_t sampleIndex)
      : rng_(Rng::forSample(seed, pixel, sampleIndex)),
        pixelSeed_(uint32_t(mix64(seed * 0x9e3779b97f4a7c15ull + pixel))),
        index_(uint32_t(sampleIndex)),
        sobol_(type == SamplerType::Sobol) {}

  float get1D() {
    if (!sobol_ || dimension_ >= kMaxSobolDimensions) return rng_.uniform();
    const uint32_t seed = dimensionSeed();
    const uint32_t i = shuffledIndex(seed);
    // van der Corput: reverseBits(i), Owen-scrambled: reverse(LK(reverse(reverse(i)))).
    return toFloat(reverseBits(laineKarras(i, seed * 0x9e3779b9u)));
  }

  Vec2 get2D() {
    if (!sobol_ || dimension_ >= kMaxSobolDimensions) {
      const float x = rng_.uniform();
      return {x, rng_.uniform()};
    }
    const uint32_t seed = dimensionSeed();
    const uint32_t i = shuffledIndex(seed);
    return {toFloat(reverseBits(laineKarras(i, seed * 0x9e3779b9u))),
            toFloat(reverseBits(laineKarras(sobolSecondReversed(i), seed * 0x85ebca6bu)))};
  }

  // Pass over the next 1D or 2D request as get1D / get2D would, without computing its value: a
  // request whose number nobody reads (renderer/sampler_lanes.h). Every later request then
  // returns exactly what it would after the full draw: a Sobol request only moves to the next
  // dimension, and a PCG32 one takes the same steps of the stream (one per number).
  void skip1D() {
    if (nextIsSobol())
      ++dimension_;
    else
      rng_.nextU32();
  }
  void skip2D() {
    if (nextIsSobol()) {
      ++dimension_;
    } else {
      rng_.nextU32();
      rng_.nextU32();
    }
  }

  // Dimensions (1D or 2D requests) drawn from the Sobol sequence before the PCG32 stream takes
  // over: the camera jitter, the first bounce and the second bounce's light sample, where
  // stratification pays. Measured (docs/performance.md): 8 keeps the error of 64 within noise on
  // the shared scenes and costs about a third as much time.
  static constexpr uint32_t kMaxSobolDimensions = 8;

  // For renderer/sampler_lanes.h, which draws the Sobol requests of many samplers at once: whether
  // the next request is a Sobol dimension, the state it is computed from, and the step past it.
  bool nextIsSobol() const { return sobol_ && dimension_ < kMaxSobolDimensions; }
  uint32_t pixelSeed() const { return pixelSeed_; }
  uint32_t sampleIndex() const { return index_; }
  uint32_t dimension() const { return dimension_; }
  void skipDimension() { ++dimension_; }

 private:
  static uint32_t reverseBits(uint32_t x) {
    x = __builtin_bswap32(x);  // bytes in one instruction, then bits within each byte
    x = ((x >> 4) & 0x0f0f0f0fu) | ((x & 0x0f0f0f0fu) << 4);
    x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
    return ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
  }
  // Second Sobol dimension, bit-reversed. Its reversed direction numbers are w_k = (1 + x)^k over
  // GF(2), so bit j of w_k is set iff j is a bit-subset of k (Lucas' theorem), and the point is the
  // superset-parity ("zeta") transform of the index's bits: five shift-mask-xor steps instead of a
  // loop over 32 bits (the shuffled index has all 32 bits in use).
  static uint32_t sobolSecondReversed(uint32_t i) {
    i ^= (i >> 1) & 0x55555555u;
    i ^= (i >> 2) & 0x33333333u;
    i ^= (i >> 4) & 0x0f0f0f0fu;
    i ^= (i >> 8) & 0x00ff00ffu;
    i ^= (i >> 16) & 0x0000ffffu;
    return i;
  }
  // Burley 2020, listing 2: each output bit depends only on less significant input bits.
  static uint32_t laineKarras(uint32_t x, uint32_t seed) {
    x += seed;
    x ^= x * 0x6c50b47cu;
    x ^= x * 0xb82f1e52u;
    x ^= x * 0xc7afe638u;
    x ^= x * 0x8d22f6e6u;
    return x;
  }
  // Nested uniform (Owen) scrambling of a 32-bit fraction: the hash runs on the bit-reversed value
  // so that each digit is permuted depending on the more significant digits only.
  static uint32_t scramble(uint32_t x, uint32_t seed) {
    return reverseBits(laineKarras(reverseBits(x), seed));
  }
  uint32_t dimensionSeed() { return uint32_t(mix64((uint64_t(pixelSeed_) << 32) | dimension_++)); }
  // Owen-scrambled sample index: a per-dimension shuffle of the pixel's sample order.
  uint32_t shuffledIndex(uint32_t seed) const { return scramble(index_, seed * 0xc2b2ae35u); }
  static float toFloat(uint32_t x) { return float(x >> 8) * 0x1p-24f; }

  Rng rng_;
  uint32_t pixelSeed_;
  uint32_t index_;
  uint32_t dimension_ = 0;
  bool sobol_;
};

}  // namespace ember
