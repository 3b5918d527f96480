// Compiled once per SIMD target by Highway's foreach_target.h; see accel/quadric_lanes.h. Each
// kernel below is its scalar routine (at the end of the file) with every branch turned into a
// lane mask, operation for operation.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "accel/quadric_lanes.cpp"
#include <hwy/foreach_target.h>  // must come before highway.h
#include <hwy/highway.h>

#include "accel/double_lanes-inl.h"
#include "accel/float_lanes-inl.h"
#include "accel/quadric_lanes.h"

HWY_BEFORE_NAMESPACE();
namespace ember::HWY_NAMESPACE {

HWY_INLINE Vec3V64 loadRays(D64 d, const float* const* xyz, unsigned i) {
  return {loadPromoted(d, xyz[0], i), loadPromoted(d, xyz[1], i), loadPromoted(d, xyz[2], i)};
}
HWY_INLINE Vec3V64 splat64(D64 d, const glm::dvec3& v) {
  return splat64(d, v.x, v.y, v.z);
}
HWY_INLINE Vec3V64 sub(const Vec3V64& a, const Vec3V64& b) {
  return {hn::Sub(a.x, b.x), hn::Sub(a.y, b.y), hn::Sub(a.z, b.z)};
}
// a + t b, per component.
HWY_INLINE Vec3V64 along(const Vec3V64& a, const V64& t, const Vec3V64& b) {
  return {hn::Add(a.x, hn::Mul(t, b.x)), hn::Add(a.y, hn::Mul(t, b.y)), hn::Add(a.z, hn::Mul(t, b.z))};
}

uint32_t DiscCrossingsKernel(const RayLanes& rays, const ExactDisc& disc, const float* tMaxLanes,
                             uint32_t lanes, DiscLanes& out) {
  const D64 d;
  const unsigned step = unsigned(hn::Lanes(d));
  const Vec3V64 center = splat64(d, disc.center), n = splat64(d, disc.n), s = splat64(d, disc.s),
                t = splat64(d, disc.t);
  const V64 zero = hn::Zero(d), r2 = hn::Set(d, disc.radius * disc.radius);
  uint32_t hits = 0;
  for (unsigned i = 0; i < rays.n; i += step) {
    const M64 live = blockMask(d, lanes, i);
    if (hn::AllFalse(d, live)) continue;
    const Vec3V64 o = loadRays(d, rays.org, i), dir = loadRays(d, rays.dir, i);
    const V64 denom = dot64(dir, n);
    const V64 tHit = hn::Div(dot64(sub(center, o), n), denom);
    const M64 outside = outsideInterval(tHit, loadPromoted(d, rays.tnear, i), loadPromoted(d, tMaxLanes, i));
    const Vec3V64 rel = sub(along(o, tHit, dir), center);
    const V64 x = dot64(rel, s), y = dot64(rel, t);
    const M64 beyondRim = hn::Gt(hn::Add(hn::Mul(x, x), hn::Mul(y, y)), r2);
    const M64 hit = hn::AndNot(hn::Or(hn::Eq(denom, zero), hn::Or(outside, beyondRim)), live);
    hn::StoreU(tHit, d, out.t + i);
    hn::StoreU(x, d, out.x + i);
    hn::StoreU(y, d, out.y + i);
    hits |= blockBits(d, hit, i);
  }
  return hits;
}

uint32_t LateralRootsKernel(const RayLanes& rays, const LateralQuadric& quadric, uint32_t lanes,
                            LateralLanes& out) {
  const D64 d;
  const unsigned step = unsigned(hn::Lanes(d));
  const Vec3V64 base = splat64(d, quadric.base), s = splat64(d, quadric.s), t = splat64(d, quadric.t),
                n = splat64(d, quadric.n);
  const V64 zero = hn::Zero(d), two = hn::Set(d, 2.0), h = hn::Set(d, quadric.height),
            r2 = hn::Set(d, quadric.r2), k2 = hn::Set(d, quadric.k2);
  uint32_t hits = 0;
  for (unsigned i = 0; i < rays.n; i += step) {
    const M64 live = blockMask(d, lanes, i);
    if (hn::AllFalse(d, live)) continue;
    const Vec3V64 rel = sub(loadRays(d, rays.org, i), base), dir = loadRays(d, rays.dir, i);
    const V64 ox = dot64(rel, s), oy = dot64(rel, t), oz = dot64(rel, n);
    const V64 dx = dot64(dir, s), dy = dot64(dir, t), dz = dot64(dir, n);
    const V64 radial = hn::Add(hn::Mul(dx, dx), hn::Mul(dy, dy));
    const V64 crossed = hn::Add(hn::Mul(ox, dx), hn::Mul(oy, dy));
    const V64 spread = hn::Add(hn::Mul(ox, ox), hn::Mul(oy, oy));
    V64 a, b, c;
    M64 solvable;
    if (quadric.cone) {
      const V64 hz = hn::Sub(h, oz);
      a = hn::Sub(radial, hn::Mul(hn::Mul(k2, dz), dz));
      b = hn::Mul(two, hn::Add(crossed, hn::Mul(hn::Mul(k2, hz), dz)));
      c = hn::Sub(spread, hn::Mul(hn::Mul(k2, hz), hz));
      solvable = live;
    } else {
      a = radial;
      b = hn::Mul(two, crossed);
      c = hn::Sub(spread, r2);
      solvable = hn::And(live, hn::Gt(a, zero));
    }
    const QuadraticRoots roots = solveQuadraticLanes(d, a, b, c);
    const V64 tMin = loadPromoted(d, rays.tnear, i), tMax = loadPromoted(d, rays.tfar, i);
    // A root counts within the interval and between the base (z = 0) and the top (z = h).
    const auto usable = [&](const V64& root) {
      const V64 z = hn::Add(oz, hn::Mul(root, dz));
      return hn::Not(hn::Or(outsideInterval(root, tMin, tMax), hn::Or(hn::Lt(z, zero), hn::Gt(z, h))));
    };
    const M64 first = usable(roots.t0);
    const V64 root = hn::IfThenElse(first, roots.t0, roots.t1);
    const M64 hit = hn::And(hn::And(solvable, roots.real), hn::Or(first, usable(roots.t1)));
    hn::StoreU(root, d, out.t + i);
    hn::StoreU(hn::Add(ox, hn::Mul(root, dx)), d, out.x + i);
    hn::StoreU(hn::Add(oy, hn::Mul(root, dy)), d, out.y + i);
    hn::StoreU(hn::Add(oz, hn::Mul(root, dz)), d, out.z + i);
    hits |= blockBits(d, hit, i);
  }
  return hits;
}

uint32_t BoxCrossingsKernel(const RayLanes& rays, const ExactBox& box, uint32_t lanes, BoxLanes& out) {
  const D64 d;
  const unsigned step = unsigned(hn::Lanes(d));
  const Vec3V64 center = splat64(d, box.center);
  const Vec3V64 axes[3] = {splat64(d, box.axes[0]), splat64(d, box.axes[1]), splat64(d, box.axes[2])};
  const V64 zero = hn::Zero(d), infinity = hn::Set(d, double(kInfinity));
  uint32_t hits = 0;
  for (unsigned i = 0; i < rays.n; i += step) {
    const M64 live = blockMask(d, lanes, i);
    if (hn::AllFalse(d, live)) continue;
    const Vec3V64 rel = sub(loadRays(d, rays.org, i), center), dir = loadRays(d, rays.dir, i);
    V64 tNear = hn::Neg(infinity), tFar = infinity;
    V64 nearAxis = hn::Set(d, -1.0), farAxis = nearAxis;
    M64 parallelOutside = hn::FirstN(d, 0);
    V64 o[3], dl[3];
    for (int k = 0; k < 3; ++k) {
      o[k] = dot64(axes[k], rel);
      dl[k] = dot64(axes[k], dir);
      const V64 half = hn::Set(d, box.half[k]);
      const M64 parallel = hn::Eq(dl[k], zero);
      parallelOutside = hn::Or(parallelOutside, hn::And(parallel, hn::Gt(hn::Abs(o[k]), half)));
      V64 t0 = hn::Div(hn::Sub(hn::Neg(half), o[k]), dl[k]);
      V64 t1 = hn::Div(hn::Sub(half, o[k]), dl[k]);
      const M64 swap = hn::Gt(t0, t1);
      const V64 lo = hn::IfThenElse(swap, t1, t0), hi = hn::IfThenElse(swap, t0, t1);
      t0 = lo;
      t1 = hi;
      const V64 axis = hn::Set(d, double(k));
      const M64 nearer = hn::AndNot(parallel, hn::Gt(t0, tNear));
      tNear = hn::IfThenElse(nearer, t0, tNear);
      nearAxis = hn::IfThenElse(nearer, axis, nearAxis);
      const M64 farther = hn::AndNot(parallel, hn::Lt(t1, tFar));
      tFar = hn::IfThenElse(farther, t1, tFar);
      farAxis = hn::IfThenElse(farther, axis, farAxis);
    }
    const V64 tMin = loadPromoted(d, rays.tnear, i), tMax = loadPromoted(d, rays.tfar, i);
    const auto within = [&](const V64& t) { return hn::And(hn::Gt(t, tMin), hn::Lt(t, tMax)); };
    const M64 entry = within(tNear);
    const V64 t = hn::IfThenElse(entry, tNear, tFar);
    const V64 axis = hn::IfThenElse(entry, nearAxis, farAxis);
    const M64 crossed = hn::And(hn::Not(hn::Gt(tNear, tFar)), hn::Or(entry, within(tFar)));
    const M64 hit = hn::AndNot(parallelOutside, hn::And(live, hn::And(crossed, hn::Not(hn::Lt(axis, zero)))));
    hn::StoreU(t, d, out.t + i);
    for (int k = 0; k < 3; ++k) hn::StoreU(hn::Add(o[k], hn::Mul(t, dl[k])), d, out.local[k] + i);
    hn::StoreU(axis, d, out.axis + i);
    hits |= blockBits(d, hit, i);
  }
  return hits;
}

// The rectangle's test (AxisRectangle::cross) for every lane of `rays` in float vectors: live
// where `lanes` has a bit (kLiveFromValid: where the ray is valid), each lane's t into tOut when
// given, and with uvCorners its texture coordinates (Quad::rectangleUv) into u and v.
template <bool kLiveFromValid>
HWY_INLINE uint32_t axisRectangleLanes(const RayLanes& rays, const AxisRectangle& rect, uint32_t lanes,
                                       float* tOut, const Vec2* uvCorners = nullptr, float* u = nullptr,
                                       float* v = nullptr) {
  const hn::CappedTag<float, RayLanes::kMaxLanes> d;
  using VF = hn::Vec<decltype(d)>;
  const unsigned step = unsigned(hn::Lanes(d));
  const unsigned k = unsigned(rect.axis), ia = unsigned(rect.across[0]), ib = unsigned(rect.across[1]);
  const VF c = hn::Set(d, rect.c), zero = hn::Zero(d), margin = hn::Set(d, AxisRectangle::kMargin);
  const VF loA = hn::Set(d, rect.lo[0]), hiA = hn::Set(d, rect.hi[0]);
  const VF loB = hn::Set(d, rect.lo[1]), hiB = hn::Set(d, rect.hi[1]);
  uint32_t hits = 0;
  for (unsigned i = 0; i < rays.n; i += step) {
    const auto live =
        hn::And(hn::FirstN(d, rays.n - i), kLiveFromValid ? validLanes(d, rays, i) : namedLanes(d, lanes, i));
    if (hn::AllFalse(d, live)) continue;
    const VF denom = hn::LoadU(d, rays.dir[k] + i);
    const VF t = hn::Div(hn::Sub(c, hn::LoadU(d, rays.org[k] + i)), denom);
    const auto within =
        hn::And(hn::Gt(t, hn::LoadU(d, rays.tnear + i)), hn::Lt(t, hn::LoadU(d, rays.tfar + i)));
    // The crossing's coordinate along one axis, and whether it lies within [lo, hi] widened by the margin.
    const auto coordinate = [&](unsigned axis, VF lo, VF hi, VF& x) {
      const VF o = hn::LoadU(d, rays.org[axis] + i);
      const VF step = hn::Mul(t, hn::LoadU(d, rays.dir[axis] + i));
      x = hn::Add(o, step);
      const VF slack = hn::Mul(margin, hn::Add(hn::Abs(o), hn::Abs(step)));
      return hn::And(hn::Ge(hn::Add(x, slack), lo), hn::Le(hn::Sub(x, slack), hi));
    };
    VF a, b;
    const auto insideA = coordinate(ia, loA, hiA, a);
    const auto insideB = coordinate(ib, loB, hiB, b);
    const auto hit = hn::And(hn::And(live, hn::Ne(denom, zero)), hn::And(within, hn::And(insideA, insideB)));
    if (tOut) hn::StoreU(t, d, tOut + i);
    if (uvCorners) {
      // Quad::rectangleUv: (s, r) = edgeCoordinates(a, b) along v1 - v0 and v3 - v0, the half
      // (v0, v1, v2) where s >= r, with barycentrics (s - r, r); the other (v0, v2, v3) with
      // (s, r - s). Then uvAt: (1 - b1 - b2) uv0 + b1 uvA + b2 uvB.
      const VF one = hn::Set(d, 1.0f);
      const auto unit = [&](VF x) { return hn::Min(hn::Max(x, zero), one); };  // std::min(std::max(x, 0), 1)
      const VF s = unit(hn::Div(hn::Sub(a, hn::Set(d, rect.corner[0])), hn::Set(d, rect.edge[0])));
      const VF r = unit(hn::Div(hn::Sub(b, hn::Set(d, rect.corner[1])), hn::Set(d, rect.edge[1])));
      const auto first = hn::Ge(s, r);
      const VF b1 = hn::IfThenElse(first, hn::Sub(s, r), s);
      const VF b2 = hn::IfThenElse(first, r, hn::Sub(r, s));
      const VF w0 = hn::Sub(hn::Sub(one, b1), b2);
      float* const outs[2] = {u, v};
      for (int m = 0; m < 2; ++m) {
        const VF uvA = hn::IfThenElse(first, hn::Set(d, uvCorners[1][m]), hn::Set(d, uvCorners[2][m]));
        const VF uvB = hn::IfThenElse(first, hn::Set(d, uvCorners[2][m]), hn::Set(d, uvCorners[3][m]));
        const VF sum =
            hn::Add(hn::Add(hn::Mul(w0, hn::Set(d, uvCorners[0][m])), hn::Mul(b1, uvA)), hn::Mul(b2, uvB));
        hn::StoreU(sum, d, outs[m] + i);
      }
    }
    hits |= maskBits(d, hit) << i;
  }
  return hits;
}

uint32_t AxisRectangleCrossingsKernel(const RayLanes& rays, const AxisRectangle& rect, uint32_t lanes) {
  return axisRectangleLanes<false>(rays, rect, lanes, nullptr);
}

uint32_t AxisRectangleHitsKernel(const RayLanes& rays, const AxisRectangle& rect, float* t,
                                 const Vec2* uvCorners, float* u, float* v) {
  return axisRectangleLanes<true>(rays, rect, 0, t, uvCorners, u, v);
}

}  // namespace ember::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
#include "accel/solve.h"

#include <algorithm>
#include <cmath>

namespace ember {

HWY_EXPORT(DiscCrossingsKernel);
HWY_EXPORT(LateralRootsKernel);
HWY_EXPORT(BoxCrossingsKernel);
HWY_EXPORT(AxisRectangleCrossingsKernel);
HWY_EXPORT(AxisRectangleHitsKernel);

bool ExactDisc::cross(const Ray& ray, float tMin, float tMax, DiscCrossing& out) const {
  const glm::dvec3 o(ray.origin), dir(ray.dir);
  const double denom = glm::dot(dir, n);
  if (denom == 0.0) return false;  // parallel: a zero-thickness disc is never hit edge-on
  const double tHit = glm::dot(center - o, n) / denom;
  if (tHit <= tMin || tHit >= tMax) return false;
  const glm::dvec3 rel = o + tHit * dir - center;
  const double x = glm::dot(rel, s), y = glm::dot(rel, t);
  if (x * x + y * y > radius * radius) return false;
  out = {tHit, x, y};
  return true;
}

bool LateralQuadric::nearestRoot(const Ray& ray, float tMin, float tMax, LateralRoot& out) const {
  const glm::dvec3 rel = glm::dvec3(ray.origin) - base, dir(ray.dir);
  const double ox = glm::dot(rel, s), oy = glm::dot(rel, t), oz = glm::dot(rel, n);
  const double dx = glm::dot(dir, s), dy = glm::dot(dir, t), dz = glm::dot(dir, n);
  double a, b, c;
  if (cone) {
    const double hz = height - oz;
    a = dx * dx + dy * dy - k2 * dz * dz;
    b = 2.0 * (ox * dx + oy * dy + k2 * hz * dz);
    c = ox * ox + oy * oy - k2 * hz * hz;
  } else {
    a = dx * dx + dy * dy;
    if (!(a > 0.0)) return false;  // along the axis: the ray never meets the side
    b = 2.0 * (ox * dx + oy * dy);
    c = ox * ox + oy * oy - r2;
  }
  double roots[2];
  if (!solveQuadratic(a, b, c, roots[0], roots[1])) return false;
  for (double root : roots) {
    if (root <= tMin || root >= tMax) continue;
    const double z = oz + root * dz;
    if (z < 0.0 || z > height) continue;  // also rejects a cone's mirror-image nappe above the apex
    out = {root, ox + root * dx, oy + root * dy, z};
    return true;
  }
  return false;
}

bool ExactBox::cross(const Ray& ray, float tMin, float tMax, BoxCrossing& out) const {
  const glm::dvec3 rel = glm::dvec3(ray.origin) - center, dir(ray.dir);
  double tNear = -double(kInfinity), tFar = double(kInfinity);
  int nearAxis = -1, farAxis = -1;
  glm::dvec3 o, dl;
  for (int k = 0; k < 3; ++k) {
    o[k] = glm::dot(axes[k], rel);
    dl[k] = glm::dot(axes[k], dir);
  }
  for (int k = 0; k < 3; ++k) {
    if (dl[k] == 0.0) {
      if (std::abs(o[k]) > half[k]) return false;
      continue;
    }
    double t0 = (-half[k] - o[k]) / dl[k];
    double t1 = (half[k] - o[k]) / dl[k];
    if (t0 > t1) std::swap(t0, t1);
    if (t0 > tNear) {
      tNear = t0;
      nearAxis = k;
    }
    if (t1 < tFar) {
      tFar = t1;
      farAxis = k;
    }
  }
  if (tNear > tFar) return false;
  double t;
  int axis;
  if (tNear > tMin && tNear < tMax) {
    t = tNear;
    axis = nearAxis;
  } else if (tFar > tMin && tFar < tMax) {
    t = tFar;  // the ray starts inside the box
    axis = farAxis;
  } else {
    return false;
  }
  if (axis < 0) return false;
  out = {t, o + t * dl, axis};
  return true;
}

bool AxisRectangle::of(const Vec3& v0, const Vec3& v1, const Vec3& v2, const Vec3& v3, AxisRectangle& out) {
  const Vec3 e1 = v1 - v0, e2 = v3 - v0;
  for (int k = 0; k < 3; ++k) {
    if (!(v0[k] == v1[k] && v0[k] == v2[k] && v0[k] == v3[k])) continue;
    const int p = (k + 1) % 3, q = (k + 2) % 3;
    int first;  // the axis v1 - v0 runs along
    if (e1[p] != 0.0f && e1[q] == 0.0f && e2[p] == 0.0f && e2[q] != 0.0f) {
      first = p;
    } else if (e1[q] != 0.0f && e1[p] == 0.0f && e2[q] == 0.0f && e2[p] != 0.0f) {
      first = q;
    } else {
      return false;
    }
    const int second = first == p ? q : p;
    // Double adds floats of similar magnitude without rounding: v2 closes the parallelogram.
    if (glm::dvec3(v1) + glm::dvec3(v3) - glm::dvec3(v0) != glm::dvec3(v2)) return false;
    AxisRectangle r;
    r.axis = k;
    r.across[0] = first;
    r.across[1] = second;
    r.c = v0[k];
    r.corner[0] = v0[first];
    r.corner[1] = v0[second];
    r.edge[0] = e1[first];
    r.edge[1] = e2[second];
    const float ends[2][2] = {{v0[first], v1[first]}, {v0[second], v3[second]}};
    for (int j = 0; j < 2; ++j) {
      r.lo[j] = std::min(ends[j][0], ends[j][1]);
      r.hi[j] = std::max(ends[j][0], ends[j][1]);
      if (!std::isfinite(r.edge[j]) || !std::isfinite(r.lo[j]) || !std::isfinite(r.hi[j])) return false;
    }
    if (!std::isfinite(r.c)) return false;
    out = r;
    return true;
  }
  return false;
}

bool AxisRectangle::cross(const Ray& ray, float tMin, float tMax, RectangleCrossing& out) const {
  const float denom = ray.dir[axis];
  if (denom == 0.0f) return false;  // parallel: a zero-thickness rectangle is never hit edge-on
  const float t = (c - ray.origin[axis]) / denom;
  if (!(t > tMin && t < tMax)) return false;
  // The crossing's coordinates, each against its bounds widened by the margin (the kernel's order).
  const auto coordinate = [&](int k, float lower, float upper, float& x) {
    const float o = ray.origin[k], step = t * ray.dir[k];
    x = o + step;
    const float slack = kMargin * (std::abs(o) + std::abs(step));
    return x + slack >= lower && x - slack <= upper;
  };
  float a, b;
  const bool insideA = coordinate(across[0], lo[0], hi[0], a);
  const bool insideB = coordinate(across[1], lo[1], hi[1], b);
  if (!(insideA && insideB)) return false;
  out = {t, a, b};
  return true;
}

uint32_t axisRectangleCrossings(const RayLanes& rays, const AxisRectangle& rect, uint32_t lanes) {
  return HWY_DYNAMIC_DISPATCH(AxisRectangleCrossingsKernel)(rays, rect, lanes);
}

uint32_t axisRectangleHits(const RayLanes& rays, const AxisRectangle& rect, float* t, const Vec2* uvCorners,
                           float* u, float* v) {
  return HWY_DYNAMIC_DISPATCH(AxisRectangleHitsKernel)(rays, rect, t, uvCorners, u, v);
}

uint32_t discCrossings(const RayLanes& rays, const ExactDisc& disc, const float* tMax, uint32_t lanes,
                       DiscLanes& out) {
  return HWY_DYNAMIC_DISPATCH(DiscCrossingsKernel)(rays, disc, tMax, lanes, out);
}

uint32_t lateralRoots(const RayLanes& rays, const LateralQuadric& quadric, uint32_t lanes,
                      LateralLanes& out) {
  return HWY_DYNAMIC_DISPATCH(LateralRootsKernel)(rays, quadric, lanes, out);
}

uint32_t boxCrossings(const RayLanes& rays, const ExactBox& box, uint32_t lanes, BoxLanes& out) {
  return HWY_DYNAMIC_DISPATCH(BoxCrossingsKernel)(rays, box, lanes, out);
}

}  // namespace ember
#endif
