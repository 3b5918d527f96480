// Compiled once per SIMD target by Highway's foreach_target.h; see packet/next_event_lanes.h.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "packet/next_event_lanes.cpp"
#include <hwy/foreach_target.h>  // must come before highway.h
#include <hwy/highway.h>

#include "core/math.h"
#include "core/ray_spawn-inl.h"
#include "core/ray_spawn.h"
#include "packet/next_event_lanes.h"

HWY_BEFORE_NAMESPACE();
namespace ember::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

using D = hn::CappedTag<float, NextEventArrays::kBlock>;
using V = hn::Vec<D>;
using M = hn::Mask<D>;

// glm's dot of two vec3: (x + y) + z of the products.
HWY_INLINE V dot3(const V (&a)[3], const V (&b)[3]) {
  return hn::Add(hn::Add(hn::Mul(a[0], b[0]), hn::Mul(a[1], b[1])), hn::Mul(a[2], b[2]));
}

// powerHeuristic (core/sampling.h) of densities a and b.
HWY_INLINE V powerHeuristic(D d, V a, V b) {
  const V zero = hn::Zero(d), one = hn::Set(d, 1.0f);
  const V r = hn::Div(b, a);
  V w = hn::Div(one, hn::Add(one, hn::Mul(r, r)));
  w = hn::IfThenElse(hn::IsInf(a), hn::IfThenElse(hn::IsInf(b), hn::Set(d, 0.5f), one), w);
  return hn::IfThenElseZero(hn::Gt(a, zero), w);
}

size_t NextEventKernel(NextEventArrays& a, const uint32_t* maskFront, const uint32_t* maskBack, size_t n,
                       bool misWeights) {
  const D d;
  const V zero = hn::Zero(d);
  size_t shadows = 0;
  for (size_t i = 0; i < n; i += hn::Lanes(d)) {
    const auto load = [&](const float* row) { return hn::Load(d, row + i); };
    const auto load3 = [&](const float(&rows)[3][NextEventArrays::kStride], V(&out)[3]) {
      for (int c = 0; c < 3; ++c) out[c] = load(rows[c]);
    };
    V p[3], ng[3], wo[3], albedo[3], tp[3], lp[3], ln[3], wi[3], li[3];
    load3(a.p, p), load3(a.ng, ng), load3(a.wo, wo), load3(a.albedo, albedo), load3(a.throughput, tp);
    load3(a.lightP, lp), load3(a.lightN, ln), load3(a.lightWi, wi), load3(a.lightLi, li);
    const V pError = load(a.pError), lightPError = load(a.lightPError);
    V lightPdf = load(a.lightPdf);
    const hn::RebindToSigned<D> di;
    M delta = hn::RebindMask(d, hn::Lt(hn::Load(di, a.delta + i), hn::Zero(di)));

    // A point light's sample (samplePosition): the direction and distance to its position, its
    // intensity over the squared distance; none where the two points coincide.
    const M point = hn::RebindMask(d, hn::Lt(hn::Load(di, a.pointLight + i), hn::Zero(di)));
    if (!hn::AllFalse(d, point)) {
      const V toLight[3] = {hn::Sub(lp[0], p[0]), hn::Sub(lp[1], p[1]), hn::Sub(lp[2], p[2])};
      const V dist2 = dot3(toLight, toLight);
      const V dist = hn::Sqrt(dist2);
      for (int c = 0; c < 3; ++c) {
        wi[c] = hn::IfThenElse(point, hn::Div(toLight[c], dist), wi[c]);
        li[c] = hn::IfThenElse(point, hn::Div(li[c], dist2), li[c]);
      }
      lightPdf = hn::IfThenElse(
          point, hn::IfThenElse(hn::Eq(dist2, zero), hn::Set(d, -1.0f), hn::Set(d, 1.0f)), lightPdf);
      delta = hn::Or(delta, point);
    }

    // PathIntegrator::shadowFor: a sample with a density and some radiance.
    M ok = hn::And(hn::Not(hn::Le(lightPdf, zero)),
                   hn::Not(hn::And(hn::And(hn::Eq(li[0], zero), hn::Eq(li[1], zero)), hn::Eq(li[2], zero))));
    // Lambertian::evalPdf with ns = ng: wo and wi on one side, the cosine about the normal turned
    // towards wo, f = R cos / pi and pdf = max(cos, 0) / pi.
    const V cosWo = dot3(wo, ng);
    ok = hn::And(ok, hn::Gt(hn::Mul(cosWo, dot3(wi, ng)), zero));
    const M woFront = hn::Ge(cosWo, zero);
    const V facing[3] = {hn::IfThenElse(woFront, ng[0], hn::Neg(ng[0])),
                         hn::IfThenElse(woFront, ng[1], hn::Neg(ng[1])),
                         hn::IfThenElse(woFront, ng[2], hn::Neg(ng[2]))};
    const V cosI = dot3(wi, facing);
    const V bsdfPdf = hn::Mul(hn::IfThenElse(hn::Lt(cosI, zero), zero, cosI), hn::Set(d, kInvPi));
    ok = hn::And(ok, hn::Not(hn::Le(cosI, zero)));
    const V scale = hn::Mul(cosI, hn::Set(d, kInvPi));
    const V f[3] = {hn::Mul(albedo[0], scale), hn::Mul(albedo[1], scale), hn::Mul(albedo[2], scale)};
    ok = hn::And(ok, hn::Not(hn::And(hn::And(hn::Eq(f[0], zero), hn::Eq(f[1], zero)), hn::Eq(f[2], zero))));

    // spawnRayTo(p, ng, pError, lightP, lightN, lightPError, front); towards an infinitely far
    // light, a ray from the offset origin along wi (front: the side of wi).
    const M infinite = hn::RebindMask(d, hn::Lt(hn::Load(di, a.infinite + i), hn::Zero(di)));
    const V dv[3] = {hn::Sub(lp[0], p[0]), hn::Sub(lp[1], p[1]), hn::Sub(lp[2], p[2])};
    const V dDotNg = dot3(dv, ng);
    const M front =
        hn::Or(hn::And(infinite, hn::Ge(dot3(wi, ng), zero)), hn::AndNot(infinite, hn::Ge(dDotNg, zero)));
    const V offset = hn::IfThenElse(front, pError, hn::Neg(pError));
    V origin[3];
    for (int c = 0; c < 3; ++c) origin[c] = hn::Add(p[c], hn::Mul(offset, ng[c]));
    const V negD[3] = {hn::Neg(dv[0]), hn::Neg(dv[1]), hn::Neg(dv[2])};
    const V targetOffset = hn::IfThenElse(hn::Ge(dot3(negD, ln), zero), lightPError, hn::Neg(lightPError));
    V segment[3];
    for (int c = 0; c < 3; ++c) segment[c] = hn::Sub(hn::Add(lp[c], hn::Mul(targetOffset, ln[c])), origin[c]);
    const V length = hn::Sqrt(dot3(segment, segment));
    const M apart = hn::Gt(length, zero);
    const V shortened = hn::Sub(length, hn::Add(lightPError, roundingErrorBound(d, length)));
    const V tMax = hn::IfThenElse(infinite, hn::Set(d, kInfinity),
                                  hn::IfThenElseZero(hn::And(apart, hn::Lt(zero, shortened)), shortened));
    const V dir[3] = {hn::IfThenElse(infinite, wi[0], hn::IfThenElseZero(apart, hn::Div(segment[0], length))),
                      hn::IfThenElse(infinite, wi[1], hn::IfThenElseZero(apart, hn::Div(segment[1], length))),
                      hn::IfThenElse(infinite, wi[2],
                                     hn::IfThenElse(apart, hn::Div(segment[2], length), hn::Set(d, 1.0f)))};

    // The contribution, throughput * (f * Li * (weight / lightPdf)).
    const V pdf = hn::Mul(load(a.pmf), lightPdf);
    const V weight = misWeights ? hn::IfThenElse(delta, hn::Set(d, 1.0f), powerHeuristic(d, pdf, bsdfPdf))
                                : hn::Set(d, 1.0f);
    const V k = hn::Div(weight, pdf);
    for (int c = 0; c < 3; ++c)
      hn::Store(hn::Mul(tp[c], hn::Mul(hn::Mul(f[c], li[c]), k)), d, a.contribution[c] + i);

    // SurfaceHit::maskToward: whether the target is off the tangent plane by more than both
    // points' errors and the dot product's rounding.
    const V sum = hn::Add(hn::Add(hn::Abs(dv[0]), hn::Abs(dv[1])), hn::Abs(dv[2]));
    // Towards an infinitely far light, the surface's own mask for the side (SurfaceHit::maskFor).
    const M clear = hn::Or(
        infinite, hn::Gt(hn::Abs(dDotNg), hn::Add(hn::Add(pError, lightPError), roundingErrorBound(d, sum))));
    const hn::RebindToUnsigned<D> du;
    const auto surface = hn::IfThenElse(
        hn::RebindMask(du, clear),
        hn::IfThenElse(hn::RebindMask(du, front), hn::Load(du, maskFront + i), hn::Load(du, maskBack + i)),
        hn::Set(du, kAllRayMask));

    // The shadow rays of the vertices whose sample contributes, compacted.
    const M shadow = hn::And(ok, hn::FirstN(d, n - i));
    const auto put = [&](V value, float* row) { hn::StoreU(hn::Compress(value, shadow), d, row + shadows); };
    for (int c = 0; c < 3; ++c) {
      put(origin[c], a.shadowOrigin[c]);
      put(dir[c], a.shadowDir[c]);
    }
    put(tMax, a.shadowTMax);
    hn::StoreU(hn::Compress(hn::And(surface, hn::Load(du, a.lightMask + i)), hn::RebindMask(du, shadow)), du,
               a.shadowMask + shadows);
    hn::StoreU(hn::Compress(hn::Iota(di, int32_t(i)), hn::RebindMask(di, shadow)), di,
               a.shadowVertex + shadows);
    shadows += hn::CountTrue(d, shadow);
  }
  return shadows;
}

}  // namespace ember::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace ember {

HWY_EXPORT(NextEventKernel);

size_t nextEventLanes(NextEventArrays& a, const uint32_t* maskFront, const uint32_t* maskBack, size_t n,
                      bool misWeights) {
  return HWY_DYNAMIC_DISPATCH(NextEventKernel)(a, maskFront, maskBack, n, misWeights);
}

}  // namespace ember
#endif
