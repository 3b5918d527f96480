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
using D = hn::CappedTag<uint32_t, SobolBlock::kBlock>;  // a block is whole vectors
using V = hn::Vec<D>;

HWY_INLINE V mulBy(D d, V x, uint32_t c) {
  return hn::Mul(x, hn::Set(d, c));
}
#if HWY_TARGET == HWY_SCALAR
// HWY_SCALAR vectors are one lane of their type: there is no bytes view of a 32-bit lane to
// shuffle, so the reversal stays shifts and masks.
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
#else
// Bit reversal by byte shuffles: each byte's two nibbles reversed through a 16-entry table, then
// the bytes of each 32-bit lane reversed by a second shuffle. Fewer operations than the shifts
// and masks above (the hash reverses four times per 2D request): 0.983 of cornell-area's render
// time on an AVX-512 host (docs/performance.md, sixteenth session).
HWY_INLINE V reverseBits32(D d, V x) {
  const hn::Repartition<uint8_t, D> d8;
  // TableLookupBytes looks up within each 16-byte block, so both tables are one block, repeated
  // across the vector by LoadDup128 at any width.
  alignas(16) static constexpr uint8_t kNibbleReversed[16] = {0x0, 0x8, 0x4, 0xc, 0x2, 0xa, 0x6, 0xe,
                                                              0x1, 0x9, 0x5, 0xd, 0x3, 0xb, 0x7, 0xf};
  alignas(16) static constexpr uint8_t kBytesReversed[16] = {3,  2,  1, 0, 7,  6,  5,  4,
                                                             11, 10, 9, 8, 15, 14, 13, 12};
  const auto table = hn::LoadDup128(d8, kNibbleReversed);
  const auto bytes = hn::BitCast(d8, x);
  const auto low = hn::And(bytes, hn::Set(d8, uint8_t{0x0f}));
  const auto high = hn::ShiftRight<4>(bytes);
  const auto reversed =
      hn::Or(hn::ShiftLeft<4>(hn::TableLookupBytes(table, low)), hn::TableLookupBytes(table, high));
  return hn::BitCast(d, hn::TableLookupBytes(reversed, hn::LoadDup128(d8, kBytesReversed)));
}
#endif
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

// Collects Sobol requests (1D or 2D) of many samplers and hashes them in blocks through the
// kernel; requests past the Sobol dimensions are drawn at once from the sampler's PCG32 stream.
// A sampler's Sobol values depend only on its (seed, dimension, index) and never touch that
// stream, so deferring them to the block's flush leaves every number as the scalar order gives it.
class SobolRequests {
 public:
  ~SobolRequests() { flush(); }

  // The sampler's next request into x (and y for a 2D one). One its caller does not `read` is
  // passed over (RequestUse), and its output set to 0.5.
  void request(Sampler& s, bool twoD, float* x, float* y, bool read = true) {
    if (!read) {
      if (twoD) {
        s.skip2D();
        *y = 0.5f;
      } else {
        s.skip1D();
      }
      *x = 0.5f;
      return;
    }
    if (!s.nextIsSobol()) {
      if (twoD) {
        const Vec2 v = s.get2D();
        *x = v.x;
        *y = v.y;
      } else {
        *x = s.get1D();
      }
      return;
    }
    block_.seed[count_] = uint32_t(mix64((uint64_t(s.pixelSeed()) << 32) | s.dimension()));
    block_.index[count_] = s.sampleIndex();
    x_[count_] = x;
    y_[count_] = twoD ? y : nullptr;
    anyTwoD_ |= twoD;
    s.skipDimension();
    if (++count_ == SobolBlock::kBlock) flush();
  }

  void flush() {
    if (count_ == 0) return;
    // Lanes past count_ are hashed too (vectors are whole); their inputs are kept defined. A 1D
    // request is the first number of the 2D formula with the same seed (Sampler::get1D).
    std::fill(block_.seed + count_, block_.seed + SobolBlock::kBlock, 0u);
    std::fill(block_.index + count_, block_.index + SobolBlock::kBlock, 0u);
    HWY_DYNAMIC_DISPATCH(SobolLanes)(block_, SobolBlock::kBlock, anyTwoD_);
    for (size_t k = 0; k < count_; ++k) {
      *x_[k] = toFloat(block_.first[k]);
      if (y_[k]) *y_[k] = toFloat(block_.second[k]);
    }
    count_ = 0;
    anyTwoD_ = false;
  }

 private:
  SobolBlock block_;
  float* x_[SobolBlock::kBlock];
  float* y_[SobolBlock::kBlock];
  size_t count_ = 0;
  bool anyTwoD_ = false;
};

}  // namespace

void draw1DLanes(Sampler* const* samplers, size_t n, float* out) {
  SobolRequests requests;
  for (size_t i = 0; i < n; ++i) requests.request(*samplers[i], false, &out[i], nullptr);
}

void draw2DLanes(Sampler* const* samplers, size_t n, Vec2* out) {
  SobolRequests requests;
  for (size_t i = 0; i < n; ++i) requests.request(*samplers[i], true, &out[i].x, &out[i].y);
}

void draw1DThen2DLanes(Sampler* const* samplers, size_t n, float* first, Vec2* second, RequestUse use) {
  SobolRequests requests;
  for (size_t i = 0; i < n; ++i) {
    requests.request(*samplers[i], false, &first[i], nullptr, use.first);
    requests.request(*samplers[i], true, &second[i].x, &second[i].y, use.second);
  }
}

void draw2DThen1DLanes(Sampler* const* samplers, size_t n, Vec2* first, float* second,
                       const RequestUse* use) {
  SobolRequests requests;
  for (size_t i = 0; i < n; ++i) {
    const RequestUse u = use ? use[i] : RequestUse{};
    requests.request(*samplers[i], true, &first[i].x, &first[i].y, u.first);
    requests.request(*samplers[i], false, &second[i], nullptr, u.second);
  }
}

}  // namespace ember
#endif
