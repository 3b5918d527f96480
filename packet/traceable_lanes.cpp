// Compiled once per SIMD target by Highway's foreach_target.h; see packet/traceable_lanes.h.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "packet/traceable_lanes.cpp"
#include <hwy/foreach_target.h>  // must come before highway.h
#include <hwy/highway.h>

#include "packet/traceable_lanes.h"

#include "accel/embree_accel.h"

HWY_BEFORE_NAMESPACE();
namespace ember::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// RTCRayN's fields, in floats from the start of a packet, in units of its width.
enum Field { kOrgX, kOrgY, kOrgZ, kTnear, kDirX, kDirY, kDirZ, kTime, kTfar };

// Vectors of at most `width` floats (D's cap), so that none reaches into the next field.
template <class D>
HWY_INLINE void disableInPackets(D d, float* first, size_t packets, size_t stride, unsigned width) {
  // As accel/embree_accel.h's traceable() compares each coordinate with it.
  const auto large = hn::Set(d, kEmbreeLarge);
  const auto inactiveOrigin = hn::Set(d, InactiveRay::kOrigin),
             inactiveTnear = hn::Set(d, InactiveRay::kTnear), inactiveTfar = hn::Set(d, InactiveRay::kTfar);
  const auto inactiveDirX = hn::Set(d, InactiveRay::kDirX), inactiveDirY = hn::Set(d, InactiveRay::kDirY),
             inactiveDirZ = hn::Set(d, InactiveRay::kDirZ);
  const unsigned step = unsigned(hn::Lanes(d));
  for (size_t k = 0; k < packets; ++k) {
    float* p = first + k * stride;
    for (unsigned i = 0; i < width; i += step) {
      auto field = [&](Field f) { return p + size_t(f) * width + i; };
      // |x| <= FLT_LARGE is false for a NaN, as in traceable().
      auto within = [&](Field f) { return hn::Le(hn::Abs(hn::LoadU(d, field(f))), large); };
      const auto tfar = hn::LoadU(d, field(kTfar));
      const auto origin = hn::And(hn::And(within(kOrgX), within(kOrgY)), within(kOrgZ));
      const auto dir = hn::And(hn::And(within(kDirX), within(kDirY)), within(kDirZ));
      const auto ok = hn::And(hn::And(origin, dir), hn::Eq(tfar, tfar));
      if (hn::AllTrue(d, ok)) continue;
      auto keep = [&](Field f, const hn::Vec<D>& inactive) {
        hn::StoreU(hn::IfThenElse(ok, hn::LoadU(d, field(f)), inactive), d, field(f));
      };
      keep(kOrgX, inactiveOrigin), keep(kOrgY, inactiveOrigin), keep(kOrgZ, inactiveOrigin),
          keep(kTnear, inactiveTnear);
      keep(kDirX, inactiveDirX), keep(kDirY, inactiveDirY), keep(kDirZ, inactiveDirZ),
          keep(kTfar, inactiveTfar);
    }
  }
}

void DisableUntraceableRays(float* first, size_t packets, size_t stride, unsigned width) {
  if (width >= 16)
    disableInPackets(hn::CappedTag<float, 16>(), first, packets, stride, width);
  else
    disableInPackets(hn::CappedTag<float, 8>(), first, packets, stride, width);
}

}  // namespace ember::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace ember {

HWY_EXPORT(DisableUntraceableRays);

void disableUntraceableRays(float* first, size_t packets, size_t stride, unsigned width) {
  HWY_DYNAMIC_DISPATCH(DisableUntraceableRays)(first, packets, stride, width);
}

}  // namespace ember
#endif
