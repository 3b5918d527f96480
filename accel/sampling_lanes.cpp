// Compiled once per SIMD target by Highway's foreach_target.h; see accel/sampling_lanes.h.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "accel/sampling_lanes.cpp"
#include <hwy/foreach_target.h>  // must come before highway.h
#include <hwy/highway.h>

#include <hwy/contrib/math/math-inl.h>  // per target, like this file: after highway.h

#include "accel/sampling_lanes.h"

HWY_BEFORE_NAMESPACE();
namespace ember::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// At most 16 lanes, so that a block of SolidAngleLanes is one or more whole vectors.
using D = hn::CappedTag<float, SolidAngleLanes::kMaxLanes>;
using V = hn::Vec<D>;
using M = hn::Mask<D>;

struct V3 {
  V x, y, z;
};

HWY_INLINE V3 splat(D d, const Vec3& v) {
  return {hn::Set(d, v.x), hn::Set(d, v.y), hn::Set(d, v.z)};
}
HWY_INLINE V3 operator-(const V3& a, const V3& b) {
  return {hn::Sub(a.x, b.x), hn::Sub(a.y, b.y), hn::Sub(a.z, b.z)};
}
HWY_INLINE V dot(const V3& a, const V3& b) {
  return hn::Add(hn::Add(hn::Mul(a.x, b.x), hn::Mul(a.y, b.y)), hn::Mul(a.z, b.z));
}
HWY_INLINE V3 cross(const V3& a, const V3& b) {
  return {hn::Sub(hn::Mul(a.y, b.z), hn::Mul(b.y, a.z)), hn::Sub(hn::Mul(a.z, b.x), hn::Mul(b.z, a.x)),
          hn::Sub(hn::Mul(a.x, b.y), hn::Mul(b.x, a.y))};
}
HWY_INLINE V3 normalize(D d, const V3& a) {
  const V inv = hn::Div(hn::Set(d, 1.0f), hn::Sqrt(dot(a, a)));
  return {hn::Mul(a.x, inv), hn::Mul(a.y, inv), hn::Mul(a.z, inv)};
}
HWY_INLINE V3 select(M m, const V3& a, const V3& b) {
  return {hn::IfThenElse(m, a.x, b.x), hn::IfThenElse(m, a.y, b.y), hn::IfThenElse(m, a.z, b.z)};
}
HWY_INLINE V clamp(V x, V lo, V hi) {
  return hn::Min(hn::Max(x, lo), hi);
}
// atan2(y, x) for y >= 0, from atan on [0, 1] (Highway has no atan2).
HWY_INLINE V atan2NonNegative(D d, V y, V x) {
  const V ax = hn::Abs(x);
  const M shallow = hn::Le(y, ax);
  const V num = hn::IfThenElse(shallow, y, ax), den = hn::IfThenElse(shallow, ax, y);
  // 0 / 0 (both zero) reads as 0.
  const V t = hn::IfThenElseZero(hn::Gt(den, hn::Zero(d)), hn::Div(num, den));
  const V a = hn::Atan(d, t);
  const V angle = hn::IfThenElse(shallow, a, hn::Sub(hn::Set(d, 0.5f * kPi), a));
  return hn::IfThenElse(hn::Lt(x, hn::Zero(d)), hn::Sub(hn::Set(d, kPi), angle), angle);
}
HWY_INLINE V length(const V3& a) {
  return hn::Sqrt(dot(a, a));
}
// The interior angle between two great circles with unit normals a and b, as
// atan2(|a x b|, -a.b): accurate where the normals are nearly parallel (accel/spherical_rectangle.cpp).
HWY_INLINE V interiorAngle(D d, const V3& a, const V3& b) {
  return atan2NonNegative(d, length(cross(a, b)), hn::Neg(dot(a, b)));
}

struct LaneSample {
  V3 p;
  V pdf;  // 0: no sample
};

// Area sampling: the half (v0, v1, v2) or (v0, v2, v3) picked by area with u.x, whose remainder
// then picks the point (PBRT4 eq. A.5.4); density converted to solid angle at ref.
HWY_INLINE LaneSample sampleByArea(D d, const QuadSampling& q, const V3& ref, V ux, V uy) {
  const V area0 = hn::Set(d, q.area0), area1 = hn::Set(d, q.area1);
  const V pick = hn::Mul(ux, hn::Add(area0, area1));
  const M first = hn::Lt(pick, area0);
  V u0 = hn::IfThenElse(first, hn::Div(pick, area0), hn::Div(hn::Sub(pick, area0), area1));
  u0 = hn::Min(u0, hn::Set(d, 0.99999994f));
  const V su = hn::Sqrt(u0);
  const V b0 = hn::Sub(hn::Set(d, 1.0f), su), b1 = hn::Mul(uy, su);
  const V b2 = hn::Sub(hn::Sub(hn::Set(d, 1.0f), b0), b1);
  const V3 a = splat(d, q.v[0]);
  const V3 p1 = select(first, splat(d, q.v[1]), splat(d, q.v[2]));
  const V3 p2 = select(first, splat(d, q.v[2]), splat(d, q.v[3]));
  auto blend = [&](V av, V pv1, V pv2) {
    return hn::Add(hn::Add(hn::Mul(b0, av), hn::Mul(b1, pv1)), hn::Mul(b2, pv2));
  };
  LaneSample s;
  s.p = {blend(a.x, p1.x, p2.x), blend(a.y, p1.y, p2.y), blend(a.z, p1.z, p2.z)};
  // p_w = p_A d^2 / |cos theta_light|, with p_A = 1 / area.
  const V3 toP = s.p - ref;
  const V dist2 = dot(toP, toP);
  const V cosLight = hn::Div(hn::Abs(dot(splat(d, q.normal), toP)), hn::Sqrt(dist2));
  const V zero = hn::Zero(d);
  const V pdf = hn::Div(hn::Mul(hn::Set(d, 1.0f / (q.area0 + q.area1)), dist2), cosLight);
  const M ok = hn::And(hn::And(hn::Ne(dist2, zero), hn::Ne(cosLight, zero)),
                       hn::And(hn::Gt(pdf, zero), hn::Lt(pdf, hn::Set(d, kInfinity))));
  s.pdf = hn::IfThenElseZero(ok, pdf);
  return s;
}

// Urena, Fajardo and King 2013, sections 3 and 4: the rectangle seen from ref as a spherical
// quadrilateral, its solid angle from the excess of its interior angles, then the sample inverted
// in x (eq. 8 ff.) and in y along that column. pdf is 0 where ref lies in the plane or the solid
// angle is too small for float.
HWY_INLINE LaneSample sampleSphericalRectangle(D d, const QuadSampling& q, const V3& o, V ux, V uy) {
  const V zero = hn::Zero(d), one = hn::Set(d, 1.0f);
  const V3 x = splat(d, q.x), y = splat(d, q.y);
  V3 z = splat(d, q.z);
  const V3 toCorner = splat(d, q.v[0]) - o;
  V z0 = dot(toCorner, z);
  // Work on the side where the rectangle lies at negative z.
  const M flip = hn::Gt(z0, zero);
  z = select(flip, V3{hn::Neg(z.x), hn::Neg(z.y), hn::Neg(z.z)}, z);
  z0 = hn::IfThenElse(flip, hn::Neg(z0), z0);
  const V x0 = dot(toCorner, x), y0 = dot(toCorner, y);
  const V x1 = hn::Add(x0, hn::Set(d, q.xLength)), y1 = hn::Add(y0, hn::Set(d, q.yLength));
  const V3 v00{x0, y0, z0}, v01{x0, y1, z0}, v10{x1, y0, z0}, v11{x1, y1, z0};
  const V3 n0 = normalize(d, cross(v00, v10));
  const V3 n1 = normalize(d, cross(v10, v11));
  const V3 n2 = normalize(d, cross(v11, v01));
  const V3 n3 = normalize(d, cross(v01, v00));
  const V g0 = interiorAngle(d, n0, n1), g1 = interiorAngle(d, n1, n2);
  const V g2 = interiorAngle(d, n2, n3), g3 = interiorAngle(d, n3, n0);
  const V b0 = n0.z, b1 = n2.z;
  const V k = hn::Sub(hn::Sub(hn::Set(d, 2.0f * kPi), g2), g3);
  const V solidAngle = hn::Max(zero, hn::Sub(hn::Add(g0, g1), k));

  const V au = hn::Add(hn::Mul(ux, solidAngle), k);
  const V fu = hn::Div(hn::Sub(hn::Mul(hn::Cos(d, au), b0), b1), hn::Sin(d, au));
  V cu = hn::Div(hn::CopySign(one, fu), hn::Sqrt(hn::Add(hn::Mul(fu, fu), hn::Mul(b0, b0))));
  cu = clamp(cu, hn::Set(d, -1.0f), one);
  V xu =
      hn::Div(hn::Neg(hn::Mul(cu, z0)), hn::Sqrt(hn::Max(hn::Set(d, 1e-12f), hn::Sub(one, hn::Mul(cu, cu)))));
  xu = clamp(xu, x0, x1);
  const V dd = hn::Sqrt(hn::Add(hn::Mul(xu, xu), hn::Mul(z0, z0)));
  const V dd2 = hn::Mul(dd, dd);
  const V h0 = hn::Div(y0, hn::Sqrt(hn::Add(dd2, hn::Mul(y0, y0))));
  const V h1 = hn::Div(y1, hn::Sqrt(hn::Add(dd2, hn::Mul(y1, y1))));
  const V hv = hn::Add(h0, hn::Mul(uy, hn::Sub(h1, h0)));
  const V hv2 = hn::Mul(hv, hv);
  const M inside = hn::Lt(hv2, hn::Set(d, 1.0f - 1e-6f));
  const V yv =
      clamp(hn::IfThenElse(inside, hn::Div(hn::Mul(hv, dd), hn::Sqrt(hn::Sub(one, hv2))), y1), y0, y1);

  LaneSample s;
  auto point = [&](V ov, V xv, V yvv, V zv) {
    return hn::Add(hn::Add(hn::Add(ov, hn::Mul(xu, xv)), hn::Mul(yv, yvv)), hn::Mul(z0, zv));
  };
  s.p = {point(o.x, x.x, y.x, z.x), point(o.y, x.y, y.y, z.y), point(o.z, x.z, y.z, z.z)};
  const M ok =
      hn::And(hn::Lt(z0, zero), hn::Gt(solidAngle, hn::Set(d, QuadSampling::kMinSphericalRectangle)));
  s.pdf = hn::IfThenElseZero(ok, hn::Div(one, solidAngle));
  return s;
}

void SampleQuadLanes(const QuadSampling& q, SolidAngleLanes& lanes) {
  const D d;
  for (unsigned i = 0; i < SolidAngleLanes::kMaxLanes; i += unsigned(hn::Lanes(d))) {
    const V3 ref{hn::Load(d, lanes.ref[0] + i), hn::Load(d, lanes.ref[1] + i), hn::Load(d, lanes.ref[2] + i)};
    const V ux = hn::Load(d, lanes.u[0] + i), uy = hn::Load(d, lanes.u[1] + i);
    LaneSample s = sampleByArea(d, q, ref, ux, uy);
    if (q.rectangle) {
      // From within twice its size: there the 1 / d^2 and cosine factors vary across the light.
      const V3 fromCenter = ref - splat(d, q.center);
      const M close = hn::Lt(dot(fromCenter, fromCenter), hn::Set(d, 4.0f * (q.area0 + q.area1)));
      if (!hn::AllFalse(d, close)) {
        const LaneSample sr = sampleSphericalRectangle(d, q, ref, ux, uy);
        const M use = hn::And(close, hn::Gt(sr.pdf, hn::Zero(d)));
        s.p = select(use, sr.p, s.p);
        s.pdf = hn::IfThenElse(use, sr.pdf, s.pdf);
      }
    }
    hn::Store(s.p.x, d, lanes.p[0] + i);
    hn::Store(s.p.y, d, lanes.p[1] + i);
    hn::Store(s.p.z, d, lanes.p[2] + i);
    hn::Store(hn::Set(d, q.normal.x), d, lanes.normal[0] + i);
    hn::Store(hn::Set(d, q.normal.y), d, lanes.normal[1] + i);
    hn::Store(hn::Set(d, q.normal.z), d, lanes.normal[2] + i);
    hn::Store(s.pdf, d, lanes.pdf + i);
  }
}

}  // namespace ember::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace ember {

HWY_EXPORT(SampleQuadLanes);

void sampleQuadLanes(const QuadSampling& quad, SolidAngleLanes& lanes) {
  HWY_DYNAMIC_DISPATCH(SampleQuadLanes)(quad, lanes);
}

QuadSampling QuadSampling::of(const Vec3 (&v)[4], bool rectangle, const Vec3& normal, float area0,
                              float area1) {
  QuadSampling q;
  q.rectangle = rectangle;
  for (int i = 0; i < 4; ++i) q.v[i] = v[i];
  q.normal = normal;
  q.area0 = area0;
  q.area1 = area1;
  q.center = 0.5f * (v[0] + v[2]);
  const Vec3 ex = v[1] - v[0], ey = v[3] - v[0];
  q.xLength = glm::length(ex);
  q.yLength = glm::length(ey);
  if (q.xLength > 0.0f && q.yLength > 0.0f) {
    q.x = ex / q.xLength;
    q.y = ey / q.yLength;
    q.z = glm::cross(q.x, q.y);
  } else {
    q.rectangle = false;
  }
  return q;
}

}  // namespace ember
#endif
