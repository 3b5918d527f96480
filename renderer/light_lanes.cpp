// Compiled once per SIMD target by Highway's foreach_target.h; see renderer/light_lanes.h.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "renderer/light_lanes.cpp"
#include <hwy/foreach_target.h>  // must come before highway.h
#include <hwy/highway.h>

#include "accel/float_lanes-inl.h"  // maskBits, namedLanes
#include "renderer/light_lanes.h"

#include <bit>

HWY_BEFORE_NAMESPACE();
namespace ember::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

using D = hn::CappedTag<float, SolidAngleLanes::kMaxLanes>;
using V = hn::Vec<D>;

// glm's dot of two vec3: (x + y) + z of the products.
HWY_INLINE V dot3(V ax, V ay, V az, V bx, V by, V bz) {
  return hn::Add(hn::Add(hn::Mul(ax, bx), hn::Mul(ay, by)), hn::Mul(az, bz));
}

// AreaLight::fromShapeSample's direction for the lanes [i, i + Lanes(d)): d = s.p - ref,
// dist = length(d), wi = d / dist, facing: dot(-wi, s.n) > 0.
struct Directions {
  V wx, wy, wz, dist;
  hn::Mask<D> facing;
};
HWY_INLINE Directions directionsAt(D d, const SolidAngleLanes& lanes, size_t i) {
  auto at = [&](const float* p) { return hn::LoadU(d, p + i); };
  const V dx = hn::Sub(at(lanes.p[0]), at(lanes.ref[0])), dy = hn::Sub(at(lanes.p[1]), at(lanes.ref[1])),
          dz = hn::Sub(at(lanes.p[2]), at(lanes.ref[2]));
  const V dist = hn::Sqrt(dot3(dx, dy, dz, dx, dy, dz));
  const V wx = hn::Div(dx, dist), wy = hn::Div(dy, dist), wz = hn::Div(dz, dist);
  const V cosine = dot3(hn::Neg(wx), hn::Neg(wy), hn::Neg(wz), at(lanes.normal[0]), at(lanes.normal[1]),
                        at(lanes.normal[2]));
  return {wx, wy, wz, dist, hn::Gt(cosine, hn::Zero(d))};
}

void LightDirectionKernel(const SolidAngleLanes& lanes, LightDirectionLanes& out) {
  const D d;
  out.facing = 0;
  for (unsigned i = 0; i < SolidAngleLanes::kMaxLanes; i += unsigned(hn::Lanes(d))) {
    const Directions dirs = directionsAt(d, lanes, i);
    hn::StoreU(dirs.dist, d, out.dist + i);
    hn::StoreU(dirs.wx, d, out.wi[0] + i);
    hn::StoreU(dirs.wy, d, out.wi[1] + i);
    hn::StoreU(dirs.wz, d, out.wi[2] + i);
    out.facing |= maskBits(d, dirs.facing) << i;
  }
}

uint32_t LoadSolidAngleRowsKernel(const float* const refRows[3], const Vec2* us, size_t first,
                                  const BackPlane* back, SolidAngleLanes& lanes) {
  const D d;
  const hn::RebindToUnsigned<D> du;
  uint32_t live = 0;
  for (size_t i = 0; i < SolidAngleLanes::kMaxLanes; i += hn::Lanes(d)) {
    V r[3], u0, u1;
    for (int k = 0; k < 3; ++k) {
      r[k] = hn::LoadU(d, refRows[k] + first + i);
      hn::StoreU(r[k], d, lanes.ref[k] + i);
    }
    hn::LoadInterleaved2(d, &us[first + i].x, u0, u1);
    hn::StoreU(u0, d, lanes.u[0] + i);
    hn::StoreU(u1, d, lanes.u[1] + i);
    if (!back) continue;
    // clearlyBehind: dot(ref - point, n) < -(margin + 1e-5 maxAbsComponent(ref)), in its float
    // operations; maxAbsComponent compares the magnitudes' bits as integers.
    const V dx = hn::Sub(r[0], hn::Set(d, back->point.x)), dy = hn::Sub(r[1], hn::Set(d, back->point.y)),
            dz = hn::Sub(r[2], hn::Set(d, back->point.z));
    const V side =
        dot3(dx, dy, dz, hn::Set(d, back->normal.x), hn::Set(d, back->normal.y), hn::Set(d, back->normal.z));
    const auto magnitude = hn::Max(hn::BitCast(du, hn::Abs(r[0])),
                                   hn::Max(hn::BitCast(du, hn::Abs(r[1])), hn::BitCast(du, hn::Abs(r[2]))));
    const V limit = hn::Neg(hn::Add(hn::Set(d, back->margin), hn::Mul(hn::Set(d, kClearlyBehindPerMagnitude),
                                                                      hn::BitCast(d, magnitude))));
    live |= maskBits(d, hn::Not(hn::Lt(side, limit))) << i;
  }
  constexpr uint32_t kAll = (1u << SolidAngleLanes::kMaxLanes) - 1u;
  if (!back) return kAll;
  if (live == 0 || live == kAll) return live;
  const unsigned model = unsigned(std::countr_zero(live));
  for (unsigned lane = 0; lane < SolidAngleLanes::kMaxLanes; ++lane)
    if (!((live >> lane) & 1u))
      lanes.set(lane, Vec3(lanes.ref[0][model], lanes.ref[1][model], lanes.ref[2][model]),
                Vec2(lanes.u[0][model], lanes.u[1][model]));
  return live;
}

void StoreLightSampleRowsKernel(const SolidAngleLanes& lanes, uint32_t live, const Color& radiance,
                                bool twoSided, float pError, const LightSampleRows& rows, size_t first) {
  const D d;
  const hn::RebindToSigned<D> di;
  const V zero = hn::Zero(d);
  for (size_t i = 0; i < SolidAngleLanes::kMaxLanes; i += hn::Lanes(d)) {
    auto at = [&](const float* p) { return hn::LoadU(d, p + i); };
    const Directions dirs = directionsAt(d, lanes, i);
    const V pdf = at(lanes.pdf);
    // sampleBlocks: a lane has a sample where pdf > 0 and the distance is not 0 (a NaN distance
    // included: Highway's Ne is an ordered compare on AVX2 and AVX-512, false for NaN).
    const auto ok = hn::And(namedLanes(d, live, unsigned(i)),
                            hn::And(hn::Gt(pdf, zero), hn::Not(hn::Eq(dirs.dist, zero))));
    const size_t at0 = first + i;
    auto put = [&](V v, float* row) { hn::BlendedStore(v, ok, d, row + at0); };
    for (int k = 0; k < 3; ++k) {
      put(at(lanes.p[k]), rows.p[k]);
      put(at(lanes.normal[k]), rows.n[k]);
    }
    put(dirs.wx, rows.wi[0]);
    put(dirs.wy, rows.wi[1]);
    put(dirs.wz, rows.wi[2]);
    // One-sided: the light emits only towards the side its normal faces.
    const auto lit = twoSided ? ok : hn::And(ok, dirs.facing);
    put(hn::IfThenElseZero(lit, hn::Set(d, radiance.x)), rows.Li[0]);
    put(hn::IfThenElseZero(lit, hn::Set(d, radiance.y)), rows.Li[1]);
    put(hn::IfThenElseZero(lit, hn::Set(d, radiance.z)), rows.Li[2]);
    put(hn::Set(d, pError), rows.pError);
    put(pdf, rows.pdf);
    const auto okInt = hn::RebindMask(di, ok);
    hn::BlendedStore(hn::Zero(di), okInt, di, rows.delta + at0);
    hn::BlendedStore(hn::VecFromMask(di, hn::RebindMask(di, hn::Not(hn::IsFinite(dirs.dist)))), okInt, di,
                     rows.infinite + at0);
  }
}

}  // namespace ember::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace ember {

HWY_EXPORT(LightDirectionKernel);
HWY_EXPORT(LoadSolidAngleRowsKernel);
HWY_EXPORT(StoreLightSampleRowsKernel);

void lightDirectionLanes(const SolidAngleLanes& lanes, LightDirectionLanes& out) {
  HWY_DYNAMIC_DISPATCH(LightDirectionKernel)(lanes, out);
}

uint32_t loadSolidAngleRows(const float* const refRows[3], const Vec2* us, size_t first,
                            const BackPlane* back, SolidAngleLanes& lanes) {
  return HWY_DYNAMIC_DISPATCH(LoadSolidAngleRowsKernel)(refRows, us, first, back, lanes);
}

void storeLightSampleRows(const SolidAngleLanes& lanes, uint32_t live, const Color& radiance, bool twoSided,
                          float pError, const LightSampleRows& rows, size_t first) {
  HWY_DYNAMIC_DISPATCH(StoreLightSampleRowsKernel)(lanes, live, radiance, twoSided, pError, rows, first);
}

}  // namespace ember
#endif
