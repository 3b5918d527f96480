// Float building blocks of the shapes' lane kernels (accel/shape_lanes.cpp, the axis-aligned
// rectangle's in accel/quadric_lanes.cpp): a block's live lanes and its result as bits. Included
// once per Highway target, in the "-inl.h" way: the include guard toggles with HWY_TARGET_TOGGLE
// so foreach_target.h can include it again.
#if defined(EMBER_ACCEL_FLOAT_LANES_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef EMBER_ACCEL_FLOAT_LANES_INL_H_
#undef EMBER_ACCEL_FLOAT_LANES_INL_H_
#else
#define EMBER_ACCEL_FLOAT_LANES_INL_H_
#endif

#include <hwy/highway.h>

#include "accel/shape_lanes.h"

#include <cstdint>

HWY_BEFORE_NAMESPACE();
namespace ember::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// The lanes of the block starting at lane i whose ray is valid (Embree's -1).
template <class D>
HWY_INLINE hn::Mask<D> validLanes(D d, const RayLanes& rays, unsigned i) {
  const hn::RebindToSigned<D> di;
  return hn::RebindMask(d, hn::Eq(hn::LoadU(di, rays.valid + i), hn::Set(di, -1)));
}

// The bits of `lanes` for the block starting at lane i, as a mask.
template <class D>
HWY_INLINE hn::Mask<D> namedLanes(D d, uint32_t lanes, unsigned i) {
  const uint8_t bits[8] = {uint8_t(lanes >> i), uint8_t(lanes >> (i + 8))};  // LoadMaskBits may read 8 bytes
  return hn::LoadMaskBits(d, bits);
}

// A block's mask as bits, lane 0 the lowest.
template <class D>
HWY_INLINE uint32_t maskBits(D d, hn::Mask<D> m) {
  uint8_t bytes[8] = {};
  hn::StoreMaskBits(d, m, bytes);
  uint32_t bits = 0;
  for (size_t k = 0; k < (hn::Lanes(d) + 7) / 8; ++k) bits |= uint32_t(bytes[k]) << (8 * k);
  return bits;
}

}  // namespace ember::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // EMBER_ACCEL_FLOAT_LANES_INL_H_
