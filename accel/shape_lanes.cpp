// Compiled once per SIMD target by Highway's foreach_target.h; see accel/shape_lanes.h.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "accel/shape_lanes.cpp"
#include <hwy/foreach_target.h>  // must come before highway.h
#include <hwy/highway.h>

#include "accel/double_lanes-inl.h"
#include "accel/float_lanes-inl.h"
#include "accel/shape.h"
#include "accel/shape_lanes.h"

HWY_BEFORE_NAMESPACE();
namespace ember::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

using D = hn::CappedTag<float, RayLanes::kMaxLanes>;  // never wider than RayLanes' arrays
using V = hn::Vec<D>;
using M = hn::Mask<D>;

constexpr float kEps = 0x1p-24f;
// gamma(n), rounded up generously: every bound below is multiplied by these, never trusted to
// the last ulp.
constexpr float gamma(int n) {
  return 1.01f * float(n) * kEps / (1.0f - float(n) * kEps);
}

struct Vec3V {
  V x, y, z;
};

HWY_INLINE V dot(const Vec3V& a, const Vec3V& b) {
  return hn::MulAdd(a.z, b.z, hn::MulAdd(a.y, b.y, hn::Mul(a.x, b.x)));
}
HWY_INLINE V absDot(D /*d*/, const Vec3V& a, const Vec3V& b) {
  return hn::MulAdd(hn::Abs(a.z), hn::Abs(b.z),
                    hn::MulAdd(hn::Abs(a.y), hn::Abs(b.y), hn::Mul(hn::Abs(a.x), hn::Abs(b.x))));
}
HWY_INLINE V maxAbs(const Vec3V& a) {
  return hn::Max(hn::Abs(a.x), hn::Max(hn::Abs(a.y), hn::Abs(a.z)));
}
HWY_INLINE Vec3V splat(D d, const Vec3& v) {
  return {hn::Set(d, v.x), hn::Set(d, v.y), hn::Set(d, v.z)};
}

struct LaneBlock {
  Vec3V o, dir;
  V tMin, tMax;
  M live;
};

HWY_INLINE LaneBlock loadBlock(D d, const RayLanes& r, unsigned i) {
  LaneBlock b;
  b.o = {hn::LoadU(d, r.org[0] + i), hn::LoadU(d, r.org[1] + i), hn::LoadU(d, r.org[2] + i)};
  b.dir = {hn::LoadU(d, r.dir[0] + i), hn::LoadU(d, r.dir[1] + i), hn::LoadU(d, r.dir[2] + i)};
  b.tMin = hn::LoadU(d, r.tnear + i);
  b.tMax = hn::LoadU(d, r.tfar + i);
  b.live = validLanes(d, r, i);
  return b;
}

// The rays are read in blocks of Lanes(d), which D caps at kMaxLanes and which divides it: a block
// never reads past RayLanes' arrays, and lanes at or beyond n are not live.
template <typename Block>
HWY_INLINE uint32_t forEachBlock(D d, const RayLanes& rays, Block block) {
  const unsigned step = unsigned(hn::Lanes(d));
  uint32_t bits = 0;
  for (unsigned i = 0; i < rays.n; i += step) {
    const LaneBlock b = loadBlock(d, rays, i);
    if (hn::AllFalse(d, b.live)) continue;
    bits |= maskBits(d, hn::And(b.live, block(b))) << i;
  }
  const uint32_t inRange = rays.n >= 32 ? ~0u : (1u << rays.n) - 1u;
  return bits & inRange;
}

unsigned RayLanesStep() {
  return unsigned(hn::Lanes(D()));
}

uint32_t LiveLanes(const RayLanes& rays) {
  const D d;
  const unsigned step = unsigned(hn::Lanes(d));
  uint32_t bits = 0;
  for (unsigned i = 0; i < rays.n; i += step) bits |= maskBits(d, validLanes(d, rays, i)) << i;
  const uint32_t inRange = rays.n >= 32 ? ~0u : (1u << rays.n) - 1u;
  return bits & inRange;
}

void TriangleLanesKernel(const RayLanes& rays, const TriangleFilter& tri, TriangleLanes& out) {
  const D d;
  const Vec3V n = splat(d, tri.n), v0 = splat(d, tri.v0), g1 = splat(d, tri.g1), g2 = splat(d, tri.g2);
  const V planeD = hn::Set(d, tri.d), dError = hn::Set(d, tri.dError);
  const V v0Max = hn::Set(d, tri.v0Max), g1Sum = hn::Set(d, tri.g1Sum), g2Sum = hn::Set(d, tri.g2Sum);
  const V zero = hn::Zero(d), one = hn::Set(d, 1.0f);
  const unsigned step = unsigned(hn::Lanes(d));
  out.candidates = out.inside = 0;
  for (unsigned i = 0; i < rays.n; i += step) {
    const LaneBlock b = loadBlock(d, rays, i);
    if (hn::AllFalse(d, b.live)) continue;
    // The plane: t = (d - n.o) / (n.dir). With num = num_f + a and den = den_f + b the exact t
    // differs from num_f / den_f by at most (|a| + |t| |b|) / (|den_f| - |b|), plus the division's
    // rounding.
    const V den = dot(n, b.dir);
    const V denError = hn::Mul(hn::Set(d, gamma(4)), absDot(d, n, b.dir));
    const V num = hn::Sub(planeD, dot(n, b.o));
    const V numError = hn::MulAdd(hn::Set(d, gamma(5)), hn::Add(hn::Abs(planeD), absDot(d, n, b.o)),
                                  hn::MulAdd(hn::Set(d, 2.02f * kEps), maxAbs(b.o), dError));
    const V t = hn::Div(num, den);
    const V absT = hn::Abs(t);
    const V slack = hn::Sub(hn::Abs(den), denError);
    const V tError =
        hn::MulAdd(hn::Set(d, 4.0f * kEps), absT,
                   hn::Mul(hn::Set(d, 1.1f), hn::Div(hn::MulAdd(absT, denError, numError), slack)));
    // Only certain verdicts count: a lane whose bound is not finite, or whose denominator may be
    // zero, stays a candidate (every comparison with NaN is false).
    const M planeMiss = hn::And(
        hn::Gt(slack, zero), hn::Or(hn::Le(hn::Add(t, tError), b.tMin), hn::Ge(hn::Sub(t, tError), b.tMax)));
    // The barycentrics of p = o + t dir, which is within pError of the plane's exact point in
    // each coordinate; b = dot(p - v0, g) then has error <= sum|g_i| (pError + rounding).
    const Vec3V p{hn::MulAdd(t, b.dir.x, b.o.x), hn::MulAdd(t, b.dir.y, b.o.y),
                  hn::MulAdd(t, b.dir.z, b.o.z)};
    const Vec3V rel{hn::Sub(p.x, v0.x), hn::Sub(p.y, v0.y), hn::Sub(p.z, v0.z)};
    const V pError = hn::MulAdd(
        tError, maxAbs(b.dir),
        hn::Mul(hn::Set(d, gamma(3)),
                hn::Add(hn::Add(maxAbs(b.o), hn::Mul(absT, maxAbs(b.dir))), hn::Add(v0Max, maxAbs(rel)))));
    const V b1 = dot(rel, g1), b2 = dot(rel, g2);
    const V b1Error = hn::MulAdd(g1Sum, pError, hn::Mul(hn::Set(d, gamma(4)), absDot(d, rel, g1)));
    const V b2Error = hn::MulAdd(g2Sum, pError, hn::Mul(hn::Set(d, gamma(4)), absDot(d, rel, g2)));
    const M below = hn::Or(hn::Lt(hn::Add(b1, b1Error), zero), hn::Lt(hn::Add(b2, b2Error), zero));
    const M beyond =
        tri.parallelogram
            ? hn::Or(hn::Gt(hn::Sub(b1, b1Error), one), hn::Gt(hn::Sub(b2, b2Error), one))
            : hn::Gt(hn::Sub(hn::Add(b1, b2), hn::Add(hn::Add(b1Error, b2Error), hn::Set(d, gamma(2)))), one);
    const M outside = hn::Or(below, beyond);
    const M certainMiss = hn::Or(planeMiss, hn::And(hn::Gt(slack, zero), outside));
    // Certainly inside: every edge test passes with its error bound, the mirror of `outside`.
    const M above = hn::And(hn::Gt(hn::Sub(b1, b1Error), zero), hn::Gt(hn::Sub(b2, b2Error), zero));
    const M within =
        tri.parallelogram
            ? hn::And(hn::Lt(hn::Add(b1, b1Error), one), hn::Lt(hn::Add(b2, b2Error), one))
            : hn::Lt(hn::Add(hn::Add(b1, b2), hn::Add(hn::Add(b1Error, b2Error), hn::Set(d, gamma(2)))), one);
    const M inside = hn::And(hn::Gt(slack, zero), hn::And(above, within));
    out.candidates |= maskBits(d, hn::AndNot(certainMiss, b.live)) << i;
    out.inside |= maskBits(d, hn::And(b.live, inside)) << i;
  }
  const uint32_t inRange = rays.n >= 32 ? ~0u : (1u << rays.n) - 1u;
  out.candidates &= inRange;
  out.inside &= out.candidates;
}

uint32_t SphereCandidates(const RayLanes& rays, const Vec3& center, float radius) {
  const D d;
  const Vec3V c = splat(d, center);
  const V cMax = hn::Set(d, maxAbsComponent(center));
  const V r2 = hn::Set(d, radius * radius);
  return forEachBlock(d, rays, [&](const LaneBlock& b) {
    // disc = (oc.dir)^2 - |dir|^2 (|oc|^2 - r^2), the sign of solveQuadratic's discriminant / 4.
    // Each oc_i = o_i - c_i is off by <= eps (|o_i| + |c_i|) =: e; the products and sums add
    // gamma-sized relative errors of the absolute values.
    const Vec3V oc{hn::Sub(b.o.x, c.x), hn::Sub(b.o.y, c.y), hn::Sub(b.o.z, c.z)};
    const V e = hn::Mul(hn::Set(d, gamma(1)), hn::Add(maxAbs(b.o), cMax));
    const V dirSum = hn::Add(hn::Add(hn::Abs(b.dir.x), hn::Abs(b.dir.y)), hn::Abs(b.dir.z));
    const V ocSum = hn::Add(hn::Add(hn::Abs(oc.x), hn::Abs(oc.y)), hn::Abs(oc.z));
    const V bb = dot(oc, b.dir);
    const V bError = hn::MulAdd(hn::Set(d, gamma(4)), absDot(d, oc, b.dir),
                                hn::Mul(hn::Set(d, 1.01f), hn::Mul(e, dirSum)));
    const V a = dot(b.dir, b.dir);
    const V aError = hn::Mul(hn::Set(d, gamma(4)), a);
    const V ocLen2 = dot(oc, oc);
    const V cc = hn::Sub(ocLen2, r2);
    const V cError = hn::MulAdd(
        hn::Set(d, gamma(5)), hn::Add(ocLen2, r2),
        hn::MulAdd(hn::Set(d, 3.03f), hn::Mul(e, e), hn::Mul(hn::Set(d, 2.02f), hn::Mul(e, ocSum))));
    const V disc = hn::Sub(hn::Mul(bb, bb), hn::Mul(a, cc));
    const V absB = hn::Abs(bb), absC = hn::Abs(cc);
    const V discError =
        hn::Mul(hn::Set(d, 1.1f),
                hn::Add(hn::Add(hn::MulAdd(hn::Set(d, 2.0f), hn::Mul(absB, bError), hn::Mul(bError, bError)),
                                hn::MulAdd(a, cError, hn::Mul(absC, aError))),
                        hn::MulAdd(aError, cError,
                                   hn::Mul(hn::Set(d, gamma(3)), hn::MulAdd(absB, absB, hn::Mul(a, absC))))));
    return hn::Not(hn::Lt(hn::Add(disc, discError), hn::Zero(d)));
  });
}

// Sphere::intersect for every candidate lane at once, in double precision: the same operations
// in the same order (this file is compiled with -ffp-contract=off, and IEEE division and square
// root round exactly), so each lane's hit equals the scalar routine's bit for bit. On the
// HWY_SCALAR and EMU128 targets (CPUs without SSSE3) DemoteTo clamps a t beyond FLT_MAX to
// FLT_MAX where float(t) gives infinity: only a ray whose direction is ~1e-30 long can reach it.
uint32_t SphereHitsKernel(const RayLanes& rays, const Vec3& center, float radius, uint32_t candidates,
                          LaneHits& out) {
  const D64 d;
  const hn::Rebind<float, D64> df;
  const unsigned step = unsigned(hn::Lanes(d));
  const Vec3V64 c = splat64(d, double(center.x), double(center.y), double(center.z));
  const V64 r2 = hn::Set(d, double(radius) * double(radius));
  const V64 inv = hn::Set(d, 1.0 / double(radius));
  const V64 two = hn::Set(d, 2.0);
  uint32_t hits = 0;
  for (unsigned i = 0; i < rays.n; i += step) {
    const M64 live = blockMask(d, candidates, i);
    if (hn::AllFalse(d, live)) continue;
    const V64 ox = hn::Sub(loadPromoted(d, rays.org[0], i), c.x),
              oy = hn::Sub(loadPromoted(d, rays.org[1], i), c.y),
              oz = hn::Sub(loadPromoted(d, rays.org[2], i), c.z);
    const V64 dx = loadPromoted(d, rays.dir[0], i), dy = loadPromoted(d, rays.dir[1], i),
              dz = loadPromoted(d, rays.dir[2], i);
    const V64 tMin = loadPromoted(d, rays.tnear, i), tMax = loadPromoted(d, rays.tfar, i);
    const V64 a = dot64(dx, dy, dz, dx, dy, dz);
    const V64 b = hn::Mul(two, dot64(ox, oy, oz, dx, dy, dz));
    const V64 cc = hn::Sub(dot64(ox, oy, oz, ox, oy, oz), r2);
    const QuadraticRoots roots = solveQuadraticLanes(d, a, b, cc);
    // The nearer root within (tMin, tMax), else the farther one.
    const M64 loOut = outsideInterval(roots.t0, tMin, tMax);
    const V64 t = hn::IfThenElse(loOut, roots.t1, roots.t0);
    const M64 hit =
        hn::And(live, hn::And(roots.real, hn::Not(hn::And(loOut, outsideInterval(roots.t1, tMin, tMax)))));
    // The unit normal (Sphere::intersect): (oc + t d) / radius.
    const V64 lx = hn::Add(ox, hn::Mul(t, dx)), ly = hn::Add(oy, hn::Mul(t, dy)),
              lz = hn::Add(oz, hn::Mul(t, dz));
    hn::StoreU(hn::DemoteTo(df, t), df, out.t + i);
    hn::StoreU(hn::DemoteTo(df, hn::Mul(lx, inv)), df, out.ng[0] + i);
    hn::StoreU(hn::DemoteTo(df, hn::Mul(ly, inv)), df, out.ng[1] + i);
    hn::StoreU(hn::DemoteTo(df, hn::Mul(lz, inv)), df, out.ng[2] + i);
    hits |= blockBits(d, hit, i);
  }
  return hits;
}

// DoublePlane::crossedWithin (the form with an anchor) and PlaneCoordinates::at for the lanes in
// `lanes`, in double precision with the scalar routines' operations in their order, so the
// results equal theirs bit for bit: t = n.(anchor - o) / n.dir, a hit where n.dir != 0 and
// tMin < t < tMax, and with `needsCoords` the plane coordinates of o + t dir.
uint32_t PlaneCrossingsKernel(const RayLanes& rays, const DoublePlane& plane, const PlaneCoordinates& coords,
                              uint32_t lanes, bool needsCoords, PlaneCrossings& out) {
  const D64 d;
  const hn::Rebind<float, D64> df;
  const unsigned step = unsigned(hn::Lanes(d));
  const V64 nx = hn::Set(d, plane.n.x), ny = hn::Set(d, plane.n.y), nz = hn::Set(d, plane.n.z);
  const V64 ax = hn::Set(d, coords.v0.x), ay = hn::Set(d, coords.v0.y), az = hn::Set(d, coords.v0.z);
  const V64 zero = hn::Zero(d);
  uint32_t hits = 0;
  for (unsigned i = 0; i < rays.n; i += step) {
    const M64 live = blockMask(d, lanes, i);
    if (hn::AllFalse(d, live)) continue;
    auto load = [&](const float* p) { return loadPromoted(d, p, i); };
    const V64 ox = load(rays.org[0]), oy = load(rays.org[1]), oz = load(rays.org[2]);
    const V64 dx = load(rays.dir[0]), dy = load(rays.dir[1]), dz = load(rays.dir[2]);
    const V64 denom = dot64(nx, ny, nz, dx, dy, dz);
    const V64 t = hn::Div(dot64(nx, ny, nz, hn::Sub(ax, ox), hn::Sub(ay, oy), hn::Sub(az, oz)), denom);
    const auto within = hn::And(hn::Gt(t, load(rays.tnear)), hn::Lt(t, load(rays.tfar)));
    const auto hit = hn::And(live, hn::AndNot(hn::Eq(denom, zero), within));
    hn::StoreU(hn::DemoteTo(df, t), df, out.t + i);
    if (needsCoords) {
      // PlaneCoordinates::at(o + t dir): rel = p - v0, b_k = rel.g_k.
      const V64 rx = hn::Sub(hn::Add(ox, hn::Mul(t, dx)), ax), ry = hn::Sub(hn::Add(oy, hn::Mul(t, dy)), ay),
                rz = hn::Sub(hn::Add(oz, hn::Mul(t, dz)), az);
      const V64 b1 =
          dot64(rx, ry, rz, hn::Set(d, coords.g1.x), hn::Set(d, coords.g1.y), hn::Set(d, coords.g1.z));
      const V64 b2 =
          dot64(rx, ry, rz, hn::Set(d, coords.g2.x), hn::Set(d, coords.g2.y), hn::Set(d, coords.g2.z));
      hn::StoreU(hn::DemoteTo(df, b1), df, out.b[0] + i);
      hn::StoreU(hn::DemoteTo(df, b2), df, out.b[1] + i);
    }
    hits |= blockBits(d, hit, i);
  }
  return hits;
}

void FillFlatHits(const Vec3& n, bool zeroUv, LaneHits& out) {
  const D d;
  const V nx = hn::Set(d, n.x), ny = hn::Set(d, n.y), nz = hn::Set(d, n.z), zero = hn::Zero(d);
  for (unsigned i = 0; i < LaneHits::kLanes; i += unsigned(hn::Lanes(d))) {
    hn::Store(nx, d, out.ng[0] + i);
    hn::Store(ny, d, out.ng[1] + i);
    hn::Store(nz, d, out.ng[2] + i);
    if (!zeroUv) continue;
    hn::Store(zero, d, out.uv[0] + i);
    hn::Store(zero, d, out.uv[1] + i);
  }
}

}  // namespace ember::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace ember {

HWY_EXPORT(RayLanesStep);
HWY_EXPORT(LiveLanes);
HWY_EXPORT(TriangleLanesKernel);
HWY_EXPORT(SphereCandidates);
HWY_EXPORT(SphereHitsKernel);
HWY_EXPORT(PlaneCrossingsKernel);
HWY_EXPORT(FillFlatHits);

void LaneHits::fillFlat(const Vec3& n, bool zeroUv) {
  HWY_DYNAMIC_DISPATCH(FillFlatHits)(n, zeroUv, *this);
}

TriangleFilter TriangleFilter::of(const Vec3& v0, const Vec3& v1, const Vec3& v2, const DoublePlane& plane,
                                  bool parallelogram) {
  TriangleFilter f;
  f.parallelogram = parallelogram;
  const PlaneCoordinates coords = PlaneCoordinates::of(v0, v1, v2);
  f.v0 = v0;
  f.v0Max = maxAbsComponent(v0);
  f.n = Vec3(plane.n);
  f.d = float(plane.d);
  // float(d) is within eps |d| of d; the rounding of n adds eps |n|_1 max|o| <= 2 eps max|o|, which
  // the kernel adds per ray.
  f.dError = 1.01f * 0x1p-24f * std::abs(f.d);
  if (coords.hasArea) {
    f.g1 = Vec3(coords.g1);
    f.g2 = Vec3(coords.g2);
  } else {
    // A degenerate triangle: the scalar test never hits it; NaN keeps every lane a candidate.
    f.g1 = f.g2 = Vec3(std::numeric_limits<float>::quiet_NaN());
  }
  // The dual vectors' own rounding adds eps |g| to the error of b, counted in the sums.
  f.g1Sum = 1.01f * (std::abs(f.g1.x) + std::abs(f.g1.y) + std::abs(f.g1.z));
  f.g2Sum = 1.01f * (std::abs(f.g2.x) + std::abs(f.g2.y) + std::abs(f.g2.z));
  return f;
}

unsigned rayLanesStep() {
  static const unsigned step = HWY_DYNAMIC_DISPATCH(RayLanesStep)();
  return step;
}

uint32_t liveLanes(const RayLanes& rays) {
  return HWY_DYNAMIC_DISPATCH(LiveLanes)(rays);
}

void triangleLanes(const RayLanes& rays, const TriangleFilter& tri, TriangleLanes& out) {
  HWY_DYNAMIC_DISPATCH(TriangleLanesKernel)(rays, tri, out);
}

uint32_t sphereCandidates(const RayLanes& rays, const Vec3& center, float radius) {
  return HWY_DYNAMIC_DISPATCH(SphereCandidates)(rays, center, radius);
}

uint32_t sphereHits(const RayLanes& rays, const Vec3& center, float radius, uint32_t candidates,
                    LaneHits& out) {
  return HWY_DYNAMIC_DISPATCH(SphereHitsKernel)(rays, center, radius, candidates, out);
}

uint32_t planeCrossings(const RayLanes& rays, const DoublePlane& plane, const PlaneCoordinates& coords,
                        uint32_t lanes, bool needsCoords, PlaneCrossings& out) {
  return HWY_DYNAMIC_DISPATCH(PlaneCrossingsKernel)(rays, plane, coords, lanes, needsCoords, out);
}

}  // namespace ember
#endif
