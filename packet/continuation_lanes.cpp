// Compiled once per SIMD target by Highway's foreach_target.h; see packet/continuation_lanes.h.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "packet/continuation_lanes.cpp"
#include <hwy/foreach_target.h>  // must come before highway.h
#include <hwy/highway.h>

#include "packet/continuation_lanes.h"

#include <stdexcept>

HWY_BEFORE_NAMESPACE();
namespace ember::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

using D = hn::CappedTag<float, NextEventArrays::kBlock>;
using V = hn::Vec<D>;
using M = hn::Mask<D>;

// std::max(a, b) and std::min(a, b) as written, a < b ? b : a and b < a ? b : a, which keep
// their first argument where a comparison with NaN is false.
HWY_INLINE V stdMax(V a, V b) {
  return hn::IfThenElse(hn::Lt(a, b), b, a);
}
HWY_INLINE V stdMin(V a, V b) {
  return hn::IfThenElse(hn::Lt(b, a), b, a);
}

size_t ContinuationKernel(const NextEventArrays& v, const ContinuationArrays& c, size_t n, int rrDepth,
                          PathArrays& next) {
  const D d;
  const hn::RebindToSigned<D> di;
  const hn::RebindToUnsigned<D> du;
  const V zero = hn::Zero(d);
  const auto isSet = [&](const int32_t* row, size_t i) {
    return hn::RebindMask(d, hn::Lt(hn::Load(di, row + i), hn::Zero(di)));
  };
  size_t count = 0;
  for (size_t i = 0; i < n; i += hn::Lanes(d)) {
    const auto load = [&](const float* row) { return hn::Load(d, row + i); };
    const M general = isSet(c.general, i);
    const V wi[3] = {load(c.wi[0]), load(c.wi[1]), load(c.wi[2])};
    const V ng[3] = {load(v.ng[0]), load(v.ng[1]), load(v.ng[2])};
    const V wo[3] = {load(v.wo[0]), load(v.wo[1]), load(v.wo[2])};
    // Lambertian::sample's test: a density, and wi on wo's side of the surface.
    const V cosine = hn::Add(hn::Add(hn::Mul(wi[0], ng[0]), hn::Mul(wi[1], ng[1])), hn::Mul(wi[2], ng[2]));
    const V cosWo = hn::Add(hn::Add(hn::Mul(wo[0], ng[0]), hn::Mul(wo[1], ng[1])), hn::Mul(wo[2], ng[2]));
    const V pdf = load(c.pdf);
    const M lambertianSampled = hn::AndNot(hn::Le(pdf, zero), hn::Gt(hn::Mul(cosWo, cosine), zero));
    const M sampled =
        hn::Or(hn::And(general, isSet(c.generalSampled, i)), hn::AndNot(general, lambertianSampled));
    // The throughput times the sample's weight; the path ends without a sample or where it is black.
    V tp[3];
    for (int k = 0; k < 3; ++k)
      tp[k] = hn::Mul(load(v.throughput[k]), hn::IfThenElse(general, load(c.weight[k]), load(v.albedo[k])));
    const M black = hn::And(hn::And(hn::Eq(tp[0], zero), hn::Eq(tp[1], zero)), hn::Eq(tp[2], zero));
    M alive = hn::And(hn::FirstN(d, n - i), hn::AndNot(black, sampled));
    // The eta product, then Russian roulette from rrDepth: the path goes on with probability
    // q = min(maxComponent(throughput) * eta * eta, 0.95), its throughput divided by q.
    const V eta = hn::Mul(load(c.etaProduct), hn::IfThenElse(general, load(c.eta), hn::Set(d, 1.0f)));
    const auto depth = hn::Load(di, c.depth + i);
    const M plays = hn::RebindMask(d, hn::Not(hn::Lt(depth, hn::Set(di, rrDepth))));  // depth >= rrDepth
    const V q = stdMin(hn::Mul(hn::Mul(stdMax(tp[0], stdMax(tp[1], tp[2])), eta), eta), hn::Set(d, 0.95f));
    alive = hn::AndNot(hn::And(plays, hn::Ge(load(c.roulette), q)), alive);
    for (int k = 0; k < 3; ++k) tp[k] = hn::IfThenElse(plays, hn::Div(tp[k], q), tp[k]);
    // frontSide(ng, wi), and the next ray from offsetAlongNormal(p, ng, pError, front).
    const M front = hn::Ge(cosine, zero);
    const V pError = load(v.pError);
    const V offset = hn::IfThenElse(front, pError, hn::Neg(pError));
    const auto delta = hn::Load(di, c.sampledDelta + i);
    const auto firstBounce = hn::Eq(depth, hn::Set(di, 1));

    // The survivors, compacted: each row's lanes that go on, stored as one vector at `count`.
    const auto put = [&](float* row, V value) { hn::StoreU(hn::Compress(value, alive), d, row + count); };
    const auto aliveI = hn::RebindMask(di, alive);
    const auto putI = [&](int32_t* row, hn::Vec<decltype(di)> value) {
      hn::StoreU(hn::Compress(value, aliveI), di, row + count);
    };
    for (int k = 0; k < 3; ++k) {
      const V p = load(v.p[k]);
      put(next.origin[k], hn::Add(p, hn::Mul(offset, ng[k])));
      put(next.dir[k], wi[k]);
      put(next.throughput[k], tp[k]);
      put(next.previousPoint[k], p);
    }
    put(next.previousPdf, pdf);
    put(next.etaProduct, eta);
    putI(next.owner, hn::Load(di, c.owner + i));
    putI(next.depth, hn::Add(depth, hn::Set(di, 1)));
    putI(next.previousDelta, delta);
    putI(next.firstBounceNonDelta,
         hn::IfThenElse(firstBounce, hn::Not(delta), hn::Load(di, c.firstBounceNonDelta + i)));
    const auto mask = hn::IfThenElse(hn::RebindMask(du, front), hn::Load(du, c.maskFront + i),
                                     hn::Load(du, c.maskBack + i));
    hn::StoreU(hn::Compress(mask, hn::RebindMask(du, alive)), du, next.mask + count);
    count += hn::CountTrue(d, alive);
  }
  return count;
}

}  // namespace ember::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace ember {

HWY_EXPORT(ContinuationKernel);

size_t continuationLanes(const NextEventArrays& vertices, const ContinuationArrays& c, size_t n, int rrDepth,
                         PathArrays& next) {
  if (n > NextEventArrays::kCapacity)
    throw std::logic_error("continuationLanes: more vertices than the rows hold");
  return HWY_DYNAMIC_DISPATCH(ContinuationKernel)(vertices, c, n, rrDepth, next);
}

}  // namespace ember
#endif
