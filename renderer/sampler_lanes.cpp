// Compiled once per SIMD target by Highway's foreach_target.h; see renderer/sampler_lanes.h.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "renderer/sampler_lanes.cpp"
#include <hwy/foreach_target.h>  // must come before highway.h
#include <hwy/highway.h>

#include "renderer/sampler_lanes.h"

#include <algorithm>

HWY_BEFORE_NAMESPACE();
namespace ember::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// The hashes are 32-bit integer arithmetic (wrapping multiplies), 16 lanes per AVX-512 vector.
// The dimension seeds' 64-bit mix64 is done while the block is gathered, once per request.
using D = hn::CappedTag<uint32_t, SobolBlock::kBlock>;  // never wider than a block
using V = hn::Vec<D>;

HWY_INLINE V mulBy(D d, V x, uint32_t c) {
  return hn::Mul(x, hn::Set(d, c));
}
HWY_INLINE V reverseBits32(D d, V x) {
  x = hn::Or(hn::ShiftRight<16>(x), hn::ShiftLeft<16>(x));
  auto swap = [&](V v, int shift, uint32_t mask) {
    const V m = hn::Set(d, mask);
    return hn::Or(hn::And(hn::ShiftRightSame(v, shift), m), hn::ShiftLeftSame(hn::And(v, m), shift));
  };
  x = swap(x, 8, 0x00ff00ffu);
  x = swap(x, 4, 0x0f0f0f0fu);
  x = swap(x, 2, 0x33333333u);
  return swap(x, 1, 0x55555555u);
}
// Burley 2020, listing 2 (renderer/sampler.h, laineKarras).
HWY_INLINE V laineKarras(D d, V x, V seed) {
  x = hn::Add(x, seed);
  x = hn::Xor(x, mulBy(d, x, 0x6c50b47cu));
  x = hn::Xor(x, mulBy(d, x, 0xb82f1e52u));
  x = hn::Xor(x, mulBy(d, x, 0xc7afe638u));
  return hn::Xor(x, mulBy(d, x, 0x8d22f6e6u));
}
// The second Sobol dimension, bit-reversed (renderer/sampler.h, sobolSecondReversed).
HWY_INLINE V sobolSecondReversed(D d, V i) {
  i = hn::Xor(i, hn::And(hn::ShiftRight<1>(i), hn::Set(d, 0x55555555u)));
  i = hn::Xor(i, hn::And(hn::ShiftRight<2>(i), hn::Set(d, 0x33333333u)));
  i = hn::Xor(i, hn::And(hn::ShiftRight<4>(i), hn::Set(d, 0x0f0f0f0fu)));
  i = hn::Xor(i, hn::And(hn::ShiftRight<8>(i), hn::Set(d, 0x00ff00ffu)));
  return hn::Xor(i, hn::And(hn::ShiftRight<16>(i), hn::Set(d, 0x0000ffffu)));
}

void SobolLanes(SobolBlock& b, size_t n, bool twoD) {
  const D d;
  for (size_t i = 0; i < n; i += hn::Lanes(d)) {
    const V seed = hn::LoadU(d, b.seed + i);
    // Owen-scrambled index: a per-dimension shuffle of the pixel's sample order.
    const V index = hn::LoadU(d, b.index + i);
    const V shuffled = reverseBits32(d, laineKarras(d, reverseBits32(d, index), mulBy(d, seed, 0xc2b2ae35u)));
    hn::StoreU(reverseBits32(d, laineKarras(d, shuffled, mulBy(d, seed, 0x9e3779b9u))), d, b.first + i);
    if (twoD) {
      const V second = laineKarras(d, sobolSecondReversed(d, shuffled), mulBy(d, seed, 0x85ebca6bu));
      hn::StoreU(reverseBits32(d, second), d, b.second + i);
    }
  }
}

}  // namespace ember::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace ember {

HWY_EXPORT(SobolLanes);

namespace {

float toFloat(uint32_t x) {
  return float(x >> 8) * 0x1p-24f;
}

// Draws a request for every sampler: the Sobol ones in blocks through the kernel, the others
// from their PCG32 streams; store(i, first, second) receives lane i's numbers.
template <bool kTwoD, typename Store, typename Scalar>
void drawLanes(Sampler* const* samplers, size_t n, Store store, Scalar scalar) {
  SobolBlock block;
  size_t lane[SobolBlock::kBlock];
  size_t count = 0;
  auto flush = [&] {
    // Lanes past `count` are hashed too (vectors are whole); their inputs are kept defined.
    std::fill(block.seed + count, block.seed + SobolBlock::kBlock, 0u);
    std::fill(block.index + count, block.index + SobolBlock::kBlock, 0u);
    HWY_DYNAMIC_DISPATCH(SobolLanes)(block, SobolBlock::kBlock, kTwoD);
    for (size_t k = 0; k < count; ++k)
      store(lane[k], toFloat(block.first[k]), kTwoD ? toFloat(block.second[k]) : 0.0f);
    count = 0;
  };
  for (size_t i = 0; i < n; ++i) {
    Sampler& s = *samplers[i];
    if (!s.nextIsSobol()) {
      scalar(i, s);
      continue;
    }
    block.seed[count] = uint32_t(mix64((uint64_t(s.pixelSeed()) << 32) | s.dimension()));
    block.index[count] = s.sampleIndex();
    lane[count++] = i;
    s.skipDimension();
    if (count == SobolBlock::kBlock) flush();
  }
  if (count > 0) flush();
}

}  // namespace

void draw1DLanes(Sampler* const* samplers, size_t n, float* out) {
  drawLanes<false>(
      samplers, n, [&](size_t i, float x, float) { out[i] = x; },
      [&](size_t i, Sampler& s) { out[i] = s.get1D(); });
}

void draw2DLanes(Sampler* const* samplers, size_t n, Vec2* out) {
  drawLanes<true>(
      samplers, n, [&](size_t i, float x, float y) { out[i] = Vec2(x, y); },
      [&](size_t i, Sampler& s) { out[i] = s.get2D(); });
}

}  // namespace ember
#endif
