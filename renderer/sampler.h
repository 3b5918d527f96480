// The random numbers of one camera sample, dimension by dimension.
//
// Independent: every number from the sample's own PCG32 stream (renderer/rng.h), as Mitsuba's
//   `independent` sampler.
// Sobol: each successive 1D or 2D request is a dimension (pair) of an Owen-scrambled Sobol
//   (0,2)-sequence over the pixel's sample indices, with the sample order shuffled independently per
//   dimension ("padding"): Burley 2020, "Practical Hash-based Owen Scrambling" (JCGT 9(4)), with the
//   Laine-Karras style hash of that paper. The first two Sobol dimensions (van der Corput, and the
//   x+1 polynomial) are all it needs. Each 2D projection of a pixel's samples is stratified, so
//   low-dimensional integrands (pixel area, direct light) converge faster than with independent
//   numbers; past kMaxSobolDimensions the PCG32 stream takes over.
// Both are deterministic in (seed, pixel, sample index), so images do not depend on threads, and a
// range of sample indices rendered separately merges exactly with the rest.
#pragma once

#include "renderer/math.h"
#include "renderer/rng.h"

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
    const uint32_t seed = hash(pixelSeed_, dimension_++);
    const uint32_t i = scramble(index_, hash(seed, 0x5bd1e995u));
    return toFloat(scramble(reverseBits(i), hash(seed, 1)));
  }

  Vec2 get2D() {
    if (!sobol_ || dimension_ >= kMaxSobolDimensions) {
      const float x = rng_.uniform();
      return {x, rng_.uniform()};
    }
    const uint32_t seed = hash(pixelSeed_, dimension_++);
    const uint32_t i = scramble(index_, hash(seed, 0x5bd1e995u));
    return {toFloat(scramble(reverseBits(i), hash(seed, 1))), toFloat(scramble(sobolSecond(i), hash(seed, 2)))};
  }

  static constexpr uint32_t kMaxSobolDimensions = 64;

 private:
  static uint32_t reverseBits(uint32_t x) {
    x = ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
    x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
    x = ((x >> 4) & 0x0f0f0f0fu) | ((x & 0x0f0f0f0fu) << 4);
    x = ((x >> 8) & 0x00ff00ffu) | ((x & 0x00ff00ffu) << 8);
    return (x >> 16) | (x << 16);
  }
  // Second Sobol dimension: direction numbers v_0 = 2^31, v_k = v_{k-1} ^ (v_{k-1} >> 1).
  static uint32_t sobolSecond(uint32_t i) {
    uint32_t r = 0;
    for (uint32_t v = 1u << 31; i; i >>= 1, v ^= v >> 1)
      if (i & 1u) r ^= v;
    return r;
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
  static uint32_t scramble(uint32_t x, uint32_t seed) { return reverseBits(laineKarras(reverseBits(x), seed)); }
  static uint32_t hash(uint32_t a, uint32_t b) { return uint32_t(mix64((uint64_t(a) << 32) | b)); }
  static float toFloat(uint32_t x) { return float(x >> 8) * 0x1p-24f; }

  Rng rng_;
  uint32_t pixelSeed_;
  uint32_t index_;
  uint32_t dimension_ = 0;
  bool sobol_;
};

}  // namespace ember
