// Compiled once per SIMD target by Highway's foreach_target.h; see accel/packet_commit.h.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "accel/packet_commit.cpp"
#include <hwy/foreach_target.h>  // must come before highway.h
#include <hwy/highway.h>

#include "accel/packet_commit.h"

HWY_BEFORE_NAMESPACE();
namespace ember::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// Eight lanes: Embree's packets on AVX2 are 8 rays, and a 16-ray packet takes two steps.
using D = hn::CappedTag<float, 8>;

// Lane i of each array is the hit field of the block's lane i.
struct HitFields {
  float* ng[3];
  float* u;
  float* v;
  uint32_t* primID;
  uint32_t* geomID;
  uint32_t* instID;
};

void CommitLaneHits(const LaneHits& hits, unsigned n, float* tfar, RTCHitN* packet, unsigned width,
                    unsigned first, uint32_t primID, uint32_t geomID, uint32_t instID) {
  const HitFields out{{&RTCHitN_Ng_x(packet, width, first), &RTCHitN_Ng_y(packet, width, first),
                       &RTCHitN_Ng_z(packet, width, first)},
                      &RTCHitN_u(packet, width, first),
                      &RTCHitN_v(packet, width, first),
                      &RTCHitN_primID(packet, width, first),
                      &RTCHitN_geomID(packet, width, first),
                      &RTCHitN_instID(packet, width, first, 0)};
  const uint32_t kNoGeometry = RTC_INVALID_GEOMETRY_ID;
  const D d;
  const hn::RebindToUnsigned<D> du;
  const unsigned step = unsigned(hn::Lanes(d));
  const auto none = hn::Set(du, kNoGeometry), ours = hn::Set(du, geomID);
  const auto prim = hn::Set(du, primID), inst = hn::Set(du, instID);
  unsigned i = 0;
  for (; i + step <= n; i += step) {
    const uint8_t bits[8] = {uint8_t(hits.mask >> i)};  // LoadMaskBits may read 8 bytes
    const auto has = hn::LoadMaskBits(d, bits);
    if (hn::AllFalse(d, has)) continue;
    const auto t = hn::LoadU(d, hits.t + i), current = hn::LoadU(d, tfar + i);
    const auto currentGeometry = hn::LoadU(du, out.geomID + i);
    const auto beatsTie =
        hn::RebindMask(d, hn::And(hn::Ne(currentGeometry, none), hn::Gt(currentGeometry, ours)));
    const auto keep = hn::And(has, hn::And(hn::Le(t, current), hn::Or(hn::Ne(t, current), beatsTie)));
    if (hn::AllFalse(d, keep)) continue;
    const auto keepU = hn::RebindMask(du, keep);
    hn::StoreU(hn::IfThenElse(keep, t, current), d, tfar + i);
    for (int c = 0; c < 3; ++c)
      hn::StoreU(hn::IfThenElse(keep, hn::LoadU(d, hits.ng[c] + i), hn::LoadU(d, out.ng[c] + i)), d,
                 out.ng[c] + i);
    hn::StoreU(hn::IfThenElse(keep, hn::LoadU(d, hits.uv[0] + i), hn::LoadU(d, out.u + i)), d, out.u + i);
    hn::StoreU(hn::IfThenElse(keep, hn::LoadU(d, hits.uv[1] + i), hn::LoadU(d, out.v + i)), d, out.v + i);
    hn::StoreU(hn::IfThenElse(keepU, prim, hn::LoadU(du, out.primID + i)), du, out.primID + i);
    hn::StoreU(hn::IfThenElse(keepU, ours, currentGeometry), du, out.geomID + i);
    hn::StoreU(hn::IfThenElse(keepU, inst, hn::LoadU(du, out.instID + i)), du, out.instID + i);
  }
  // The lanes past the last whole vector (a single ray, or a padded block), one by one.
  for (uint32_t bits = hits.mask & ~((1u << i) - 1u); bits != 0; bits &= bits - 1) {
    const unsigned lane = unsigned(__builtin_ctz(bits));
    if (lane >= n) break;
    const float t = hits.t[lane];
    if (!(t <= tfar[lane])) continue;
    if (t == tfar[lane] && (out.geomID[lane] == kNoGeometry || out.geomID[lane] <= geomID)) continue;
    tfar[lane] = t;
    for (int c = 0; c < 3; ++c) out.ng[c][lane] = hits.ng[c][lane];
    out.u[lane] = hits.uv[0][lane];
    out.v[lane] = hits.uv[1][lane];
    out.primID[lane] = primID;
    out.geomID[lane] = geomID;
    out.instID[lane] = instID;
  }
}

}  // namespace ember::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
#include <cassert>

namespace ember {

HWY_EXPORT(CommitLaneHits);

void commitLaneHits(const LaneHits& hits, unsigned n, float* tfar, RTCHitN* packet, unsigned width,
                    unsigned first, uint32_t primID, uint32_t geomID, uint32_t instID) {
  assert(n <= RayLanes::kMaxLanes && first + n <= width);
  HWY_DYNAMIC_DISPATCH(CommitLaneHits)(hits, n, tfar, packet, width, first, primID, geomID, instID);
}

}  // namespace ember
#endif
