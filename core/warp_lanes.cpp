// Compiled once per SIMD target by Highway's foreach_target.h; see core/warp_lanes.h.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "core/warp_lanes.cpp"
#include <hwy/foreach_target.h>  // must come before highway.h
#include <hwy/highway.h>

#include <hwy/contrib/math/math-inl.h>  // per target, like this file: after highway.h

#include "core/warp_lanes.h"

HWY_BEFORE_NAMESPACE();
namespace ember::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

using D = hn::CappedTag<float, CosineLanes::kGroup>;
using V = hn::Vec<D>;
using M = hn::Mask<D>;

void SampleCosineLanes(CosineLanes& lanes, unsigned count) {
  const D d;
  const V zero = hn::Zero(d), one = hn::Set(d, 1.0f), quarterPi = hn::Set(d, 0.25f * kPi);
  for (unsigned i = 0; i < count; i += unsigned(hn::Lanes(d))) {
    // The concentric map: the square's point (ox, oy) onto the disc's radius r and angle theta.
    const V ox = hn::Sub(hn::Add(hn::Load(d, lanes.u[0] + i), hn::Load(d, lanes.u[0] + i)), one);
    const V oy = hn::Sub(hn::Add(hn::Load(d, lanes.u[1] + i), hn::Load(d, lanes.u[1] + i)), one);
    const M centre = hn::And(hn::Eq(ox, zero), hn::Eq(oy, zero));
    const M wide = hn::Gt(hn::Abs(ox), hn::Abs(oy));
    const V r = hn::IfThenElse(wide, ox, oy);
    // At the centre 0/0 is NaN, which Highway's Cos and Sin convert to an integer in their range
    // reduction (undefined behaviour in its scalar target): the angle is zeroed there, and the
    // centre's direction does not read it.
    const V theta = hn::IfThenZeroElse(
        centre, hn::IfThenElse(wide, hn::Mul(quarterPi, hn::Div(oy, ox)),
                               hn::Sub(hn::Set(d, 0.5f * kPi), hn::Mul(quarterPi, hn::Div(ox, oy)))));
    const V dx = hn::IfThenZeroElse(centre, hn::Mul(r, hn::Cos(d, theta)));
    const V dy = hn::IfThenZeroElse(centre, hn::Mul(r, hn::Sin(d, theta)));
    const V z = hn::Sqrt(hn::Max(zero, hn::Sub(hn::Sub(one, hn::Mul(dx, dx)), hn::Mul(dy, dy))));

    // Duff et al.'s branchless frame about n.
    const V nx = hn::Load(d, lanes.normal[0] + i), ny = hn::Load(d, lanes.normal[1] + i);
    const V nz = hn::Load(d, lanes.normal[2] + i);
    const V sign = hn::CopySign(one, nz);
    const V a = hn::Div(hn::Set(d, -1.0f), hn::Add(sign, nz));
    const V b = hn::Mul(hn::Mul(nx, ny), a);
    const V sx = hn::Add(one, hn::Mul(hn::Mul(hn::Mul(sign, nx), nx), a)), sy = hn::Mul(sign, b);
    const V sz = hn::Neg(hn::Mul(sign, nx));
    const V tx = b, ty = hn::Add(sign, hn::Mul(hn::Mul(ny, ny), a)), tz = hn::Neg(ny);
    auto world = [&](V s, V t, V n) {
      return hn::Add(hn::Add(hn::Mul(s, dx), hn::Mul(t, dy)), hn::Mul(n, z));
    };
    hn::Store(world(sx, tx, nx), d, lanes.wi[0] + i);
    hn::Store(world(sy, ty, ny), d, lanes.wi[1] + i);
    hn::Store(world(sz, tz, nz), d, lanes.wi[2] + i);
    hn::Store(hn::Mul(z, hn::Set(d, kInvPi)), d, lanes.pdf + i);
  }
}

}  // namespace ember::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace ember {

HWY_EXPORT(SampleCosineLanes);

void sampleCosineLanes(CosineLanes& lanes, unsigned count) {
  HWY_DYNAMIC_DISPATCH(SampleCosineLanes)(lanes, count);
}

}  // namespace ember
#endif
