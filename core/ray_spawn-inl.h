// core/ray_spawn.h's rounding-error bound in Highway vectors, for the lane kernels that settle hit
// points and spawn rays (packet/arrival_lanes.cpp, packet/next_event_lanes.cpp). Included once per
// Highway target, in the "-inl.h" way: the include guard toggles with HWY_TARGET_TOGGLE so
// foreach_target.h can include it again. The kernels that include it are compiled without fused
// multiply-adds, so each lane equals the scalar bound bit for bit.
#if defined(EMBER_CORE_RAY_SPAWN_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef EMBER_CORE_RAY_SPAWN_INL_H_
#undef EMBER_CORE_RAY_SPAWN_INL_H_
#else
#define EMBER_CORE_RAY_SPAWN_INL_H_
#endif

#include <hwy/highway.h>

#include "core/ray_spawn.h"

HWY_BEFORE_NAMESPACE();
namespace ember::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// roundingErrorBound of every lane of m: the same multiply, then the same add.
template <class D>
HWY_INLINE hn::Vec<D> roundingErrorBound(D d, hn::Vec<D> m) {
  return hn::Add(hn::Mul(hn::Set(d, kRoundingErrorPerMagnitude), m), hn::Set(d, kRoundingErrorFloor));
}

}  // namespace ember::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // EMBER_CORE_RAY_SPAWN_INL_H_
