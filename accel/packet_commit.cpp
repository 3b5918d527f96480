// Compiled once per SIMD target by Highway's foreach_target.h; see accel/packet_commit.h.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "accel/packet_commit.cpp"
#include <hwy/foreach_target.h>  // must come before highway.h
#include <hwy/highway.h>

#include "accel/packet_commit.h"

HWY_BEFORE_NAMESPACE();
namespace ember::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// Lane i of each array is the hit field of the block's lane i.
struct HitFields {
  float* ng[3];
  float* u;
  float* v;
  uint32_t* primID;
  uint32_t* geomID;
  uint32_t* instID;
};

// A field of the block's hits, lanes [i, i + Lanes(d)). The double-precision kernels (the
// sphere's, the rectangles') store each block of doubles as floats, half a float vector at a
// time; a load of the whole vector would span two stores and wait for both to retire instead of
// taking its data from them, so a 16-lane vector is loaded as the two halves it was stored as.
template <class D, class T>
hn::Vec<D> loadHitField(D d, const T* p) {
#if HWY_TARGET != HWY_SCALAR
  if constexpr (hn::MaxLanes(D()) == 16) {
    const hn::Half<D> half;
    return hn::Combine(d, hn::LoadU(half, p + hn::Lanes(half)), hn::LoadU(half, p));
  }
#endif
  return hn::LoadU(d, p);
}

// p[k] = v[k] where keep[k]: a masked store where the CPU has one (AVX-512); elsewhere Highway
// emulates it (vmaskmov on AVX2, lane by lane before), so the blend with the old values is stored.
template <class D, class V, class M, typename T>
HWY_INLINE void storeKept(V v, M keep, D d, T* p) {
#if HWY_TARGET <= HWY_AVX3
  hn::BlendedStore(v, keep, d, p);
#else
  hn::StoreU(hn::IfThenElse(keep, v, hn::LoadU(d, p)), d, p);
#endif
}

// Commits lanes [i, i + Lanes(d)) of the block, as the scalar rule below decides each. tfar and
// geomID are read back as whole vectors (by Embree, and by the next shape's commit), so they are
// stored whole; the other fields, read one lane at a time after the trace, with masked stores
// (storeKept).
template <class D>
void commitVector(D d, unsigned i, const LaneHits& hits, float* tfar, const HitFields& out, uint32_t primID,
                  uint32_t geomID, uint32_t instID) {
  const hn::RebindToUnsigned<D> du;
  const uint8_t bits[8] = {uint8_t(hits.mask >> i), uint8_t(hits.mask >> (i + 8))};  // may read 8 bytes
  const auto has = hn::LoadMaskBits(d, bits);
  if (hn::AllFalse(d, has)) return;
  const auto t = loadHitField(d, hits.t + i), current = hn::LoadU(d, tfar + i);
  const auto currentGeometry = hn::LoadU(du, out.geomID + i);
  const auto ours = hn::Set(du, geomID);
  const auto beatsTie =
      hn::RebindMask(d, hn::And(hn::Ne(currentGeometry, hn::Set(du, uint32_t(RTC_INVALID_GEOMETRY_ID))),
                                hn::Gt(currentGeometry, ours)));
  const auto keep = hn::And(has, hn::And(hn::Le(t, current), hn::Or(hn::Ne(t, current), beatsTie)));
  if (hn::AllFalse(d, keep)) return;
  const auto keepU = hn::RebindMask(du, keep);
  hn::StoreU(hn::IfThenElse(keep, t, current), d, tfar + i);
  hn::StoreU(hn::IfThenElse(keepU, ours, currentGeometry), du, out.geomID + i);
  for (int c = 0; c < 3; ++c) storeKept(loadHitField(d, hits.ng[c] + i), keep, d, out.ng[c] + i);
  storeKept(loadHitField(d, hits.uv[0] + i), keep, d, out.u + i);
  storeKept(loadHitField(d, hits.uv[1] + i), keep, d, out.v + i);
  storeKept(hn::Set(du, primID), keepU, du, out.primID + i);
  storeKept(hn::Set(du, instID), keepU, du, out.instID + i);
}

void CommitLaneHits(const LaneHits& hits, unsigned n, float* tfar, RTCHitN* packet, unsigned width,
                    unsigned first, uint32_t primID, uint32_t geomID, uint32_t instID) {
  const HitFields out{{&RTCHitN_Ng_x(packet, width, first), &RTCHitN_Ng_y(packet, width, first),
                       &RTCHitN_Ng_z(packet, width, first)},
                      &RTCHitN_u(packet, width, first),
                      &RTCHitN_v(packet, width, first),
                      &RTCHitN_primID(packet, width, first),
                      &RTCHitN_geomID(packet, width, first),
                      &RTCHitN_instID(packet, width, first, 0)};
  // The widest vectors first: a 16-ray packet in one step where the CPU has 16 float lanes.
  // Embree and the next shape's callback read tfar (and the hit fields) back as whole vectors,
  // and a load spanning two narrower stores cannot take its data from them (store-to-load
  // forwarding): with two 8-lane steps, the next callback's first load of tfar waited for both
  // stores to retire (`perf annotate`: 83% of the tfar pass's samples on a 16-lane packet).
  const hn::CappedTag<float, 16> wide;
  const hn::CappedTag<float, 8> narrow;
  unsigned i = 0;
  for (; i + hn::Lanes(wide) <= n; i += unsigned(hn::Lanes(wide)))
    commitVector(wide, i, hits, tfar, out, primID, geomID, instID);
  for (; i + hn::Lanes(narrow) <= n; i += unsigned(hn::Lanes(narrow)))
    commitVector(narrow, i, hits, tfar, out, primID, geomID, instID);
  // The lanes past the last whole vector (a single ray, or a padded block), one by one.
  for (uint32_t bits = hits.mask & ~((1u << i) - 1u); bits != 0; bits &= bits - 1) {
    const unsigned lane = unsigned(__builtin_ctz(bits));
    if (lane >= n) break;
    const float t = hits.t[lane];
    if (!(t <= tfar[lane])) continue;
    if (t == tfar[lane] && (out.geomID[lane] == RTC_INVALID_GEOMETRY_ID || out.geomID[lane] <= geomID))
      continue;
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
