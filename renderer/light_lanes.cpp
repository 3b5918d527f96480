// Compiled once per SIMD target by Highway's foreach_target.h; see renderer/light_lanes.h.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "renderer/light_lanes.cpp"
#include <hwy/foreach_target.h>  // must come before highway.h
#include <hwy/highway.h>

#include "renderer/light_lanes.h"

HWY_BEFORE_NAMESPACE();
namespace ember::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

using D = hn::CappedTag<float, SolidAngleLanes::kMaxLanes>;
using V = hn::Vec<D>;

// glm's dot of two vec3: (x + y) + z of the products.
HWY_INLINE V dot3(V ax, V ay, V az, V bx, V by, V bz) {
  return hn::Add(hn::Add(hn::Mul(ax, bx), hn::Mul(ay, by)), hn::Mul(az, bz));
}

void LightDirectionKernel(const SolidAngleLanes& lanes, LightDirectionLanes& out) {
  const D d;
  out.facing = 0;
  for (unsigned i = 0; i < SolidAngleLanes::kMaxLanes; i += unsigned(hn::Lanes(d))) {
    auto at = [&](const float* p) { return hn::LoadU(d, p + i); };
    // d = s.p - ref, dist = length(d), wi = d / dist, facing: dot(-wi, s.n) > 0.
    const V dx = hn::Sub(at(lanes.p[0]), at(lanes.ref[0])), dy = hn::Sub(at(lanes.p[1]), at(lanes.ref[1])),
            dz = hn::Sub(at(lanes.p[2]), at(lanes.ref[2]));
    const V dist = hn::Sqrt(dot3(dx, dy, dz, dx, dy, dz));
    const V wx = hn::Div(dx, dist), wy = hn::Div(dy, dist), wz = hn::Div(dz, dist);
    hn::StoreU(dist, d, out.dist + i);
    hn::StoreU(wx, d, out.wi[0] + i);
    hn::StoreU(wy, d, out.wi[1] + i);
    hn::StoreU(wz, d, out.wi[2] + i);
    const V cosine = dot3(hn::Neg(wx), hn::Neg(wy), hn::Neg(wz), at(lanes.normal[0]), at(lanes.normal[1]),
                          at(lanes.normal[2]));
    uint8_t bits[8] = {};
    hn::StoreMaskBits(d, hn::Gt(cosine, hn::Zero(d)), bits);
    uint32_t mask = 0;
    for (size_t k = 0; k < (hn::Lanes(d) + 7) / 8; ++k) mask |= uint32_t(bits[k]) << (8 * k);
    out.facing |= mask << i;
  }
}

}  // namespace ember::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace ember {

HWY_EXPORT(LightDirectionKernel);

void lightDirectionLanes(const SolidAngleLanes& lanes, LightDirectionLanes& out) {
  HWY_DYNAMIC_DISPATCH(LightDirectionKernel)(lanes, out);
}

}  // namespace ember
#endif
