// Compiled once per SIMD target by Highway's foreach_target.h; see packet/arrival_lanes.h.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "packet/arrival_lanes.cpp"
#include <hwy/foreach_target.h>  // must come before highway.h
#include <hwy/highway.h>

#include "core/ray_spawn-inl.h"
#include "packet/arrival_lanes.h"

#include <stdexcept>

HWY_BEFORE_NAMESPACE();
namespace ember::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

using D = hn::CappedTag<float, NextEventArrays::kBlock>;
using V = hn::Vec<D>;

size_t ArriveLambertianKernel(const HitFields& hits, const PathArrays& paths, const LambertianRun& run,
                              NextEventArrays& nee, ContinuationArrays& cont, int32_t* project) {
  const D d;
  const hn::RebindToSigned<D> di;
  const hn::RebindToUnsigned<D> du;
  const hn::Rebind<uint16_t, D> d16;
  using VI = hn::Vec<decltype(di)>;
  const V albedo[3] = {hn::Set(d, run.albedo.x), hn::Set(d, run.albedo.y), hn::Set(d, run.albedo.z)};
  const VI laneMask = hn::Set(di, int32_t(hits.laneMask)), stride = hn::Set(di, int32_t(hits.stride));
  const VI firstVertex = hn::Set(di, int32_t(run.firstVertex));
  size_t projected = 0;
  for (size_t i = 0; i < run.count; i += hn::Lanes(d)) {
    // Lanes past the run repeat the run's first slot, whose ray hit this shape (so their values
    // are finite, as the rows' padding lanes must be), and write past the run's vertices.
    const VI slot =
        hn::IfThenElse(hn::FirstN(di, run.count - i), hn::PromoteTo(di, hn::LoadU(d16, run.slots + i)),
                       hn::Set(di, int32_t(run.slots[0])));
    const VI inPacket =
        hn::Add(hn::Mul(hn::ShiftRightSame(slot, int(hits.shift)), stride), hn::And(slot, laneMask));
    const auto hit = [&](uint32_t field) { return hn::GatherIndex(d, hits.base + field, inPacket); };
    const auto path = [&](const float* row) { return hn::GatherIndex(d, row, slot); };
    const auto pathI = [&](const int32_t* row) { return hn::GatherIndex(di, row, slot); };
    const size_t v = run.firstVertex + i;
    const auto store = [&](V value, float* row) { hn::StoreU(value, d, row + v); };
    const auto storeI = [&](VI value, int32_t* row) { hn::StoreU(value, di, row + v); };

    // p = origin + t dir, and roundingErrorBound(maxAbsComponent(p) + t) where t <= that
    // magnitude (the scalar arrival's branch; the others are projected afterwards).
    const V t = hit(hits.tfar);
    V p[3], magnitude = hn::Zero(d);
    for (int k = 0; k < 3; ++k) {
      const V dir = path(paths.dir[k]);
      p[k] = hn::Add(path(paths.origin[k]), hn::Mul(t, dir));
      // maxAbsComponent: the largest magnitude's bits as an unsigned integer (NaN propagates).
      magnitude = hn::BitCast(d, hn::Max(hn::BitCast(du, magnitude), hn::BitCast(du, hn::Abs(p[k]))));
      store(p[k], nee.p[k]);
      store(hn::Neg(dir), nee.wo[k]);
      store(hit(k == 0 ? hits.ngX : k == 1 ? hits.ngY : hits.ngZ), nee.ng[k]);
      store(albedo[k], nee.albedo[k]);
      store(path(paths.throughput[k]), nee.throughput[k]);
    }
    store(roundingErrorBound(d, hn::Add(magnitude, t)), nee.pError);
    const auto far = hn::RebindMask(di, hn::And(hn::Gt(t, magnitude), hn::FirstN(d, run.count - i)));
    hn::CompressStore(hn::Add(firstVertex, hn::Iota(di, int32_t(i))), far, di, project + projected);
    projected += hn::CountTrue(di, far);

    // No light sample yet; a Lambertian vertex is in the kernels' own form; the path's state.
    store(hn::Set(d, -1.0f), nee.lightPdf);
    storeI(hn::Zero(di), nee.pointLight);
    storeI(hn::Zero(di), nee.infinite);
    storeI(hn::Zero(di), cont.general);
    storeI(hn::Zero(di), cont.sampledDelta);
    store(path(paths.etaProduct), cont.etaProduct);
    storeI(pathI(paths.owner), cont.owner);
    storeI(pathI(paths.depth), cont.depth);
    storeI(pathI(paths.firstBounceNonDelta), cont.firstBounceNonDelta);
    hn::StoreU(hn::Set(du, run.maskFront), du, cont.maskFront + v);
    hn::StoreU(hn::Set(du, run.maskBack), du, cont.maskBack + v);
  }
  return projected;
}

}  // namespace ember::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace ember {

HWY_EXPORT(ArriveLambertianKernel);

size_t arriveLambertianLanes(const HitFields& hits, const PathArrays& paths, const LambertianRun& run,
                             NextEventArrays& nee, ContinuationArrays& cont, int32_t* project) {
  if (run.firstVertex + run.count > NextEventArrays::kCapacity)
    throw std::logic_error("arriveLambertianLanes: more vertices than the rows hold");
  return HWY_DYNAMIC_DISPATCH(ArriveLambertianKernel)(hits, paths, run, nee, cont, project);
}

}  // namespace ember
#endif
