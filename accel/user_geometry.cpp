#include "accel/user_geometry.h"

#include "accel/packet_tfar.h"
#include "accel/shape.h"

#include <algorithm>
#include <bit>
#include <cstdint>

namespace ember {

void shapeBoundsCallback(const RTCBoundsFunctionArguments* args) {
  const auto* shape = static_cast<const ShapeGeometry*>(args->geometryUserPtr)->shape;
  const Bounds b = shape->bounds();
  // Pad by a relative epsilon so float rounding of the exact bounds never culls a true hit.
  const Vec3 pad = 1e-5f * (absolute(b.lower) + absolute(b.upper)) + Vec3(1e-7f);
  RTCBounds* out = args->bounds_o;
  out->lower_x = b.lower.x - pad.x;
  out->lower_y = b.lower.y - pad.y;
  out->lower_z = b.lower.z - pad.z;
  out->upper_x = b.upper.x + pad.x;
  out->upper_y = b.upper.y + pad.y;
  out->upper_z = b.upper.z + pad.z;
}

// A ray packet in Embree's RTCRayN layout (each field an array of N floats, in RTCRay's order),
// in blocks of up to RayLanes::kMaxLanes lanes for the shapes' lane filters. A block the filters
// can read in place (16 lanes, or a width their vectors divide: 8-ray packets on AVX2) points into
// Embree's arrays; any other (a single ray, or 8 rays for 16-float vectors) is copied into a
// padded block, so a filter never reads past an array. The padded block is the thread's own,
// zeroed once: a block copies only its live rays' fields, and the lanes past them keep earlier
// rays' finite values, never live.
class PacketLanes {
 public:
  PacketLanes(RTCRayN* rays, unsigned n, const int* valid, bool needsUv)
      : f_(reinterpret_cast<float*>(rays)), n_(n), valid_(valid), needsUv_(needsUv) {}

  unsigned blocks() const { return (n_ + RayLanes::kMaxLanes - 1) / RayLanes::kMaxLanes; }
  RayLanes block(unsigned k) {
    const unsigned first = k * RayLanes::kMaxLanes;
    const unsigned count = std::min(RayLanes::kMaxLanes, n_ - first);
    if (count == RayLanes::kMaxLanes || count % rayLanesStep() == 0) {
      auto field = [&](unsigned i) { return f_ + i * n_ + first; };
      return RayLanes{{field(0), field(1), field(2)},
                      {field(4), field(5), field(6)},
                      field(3),
                      field(8),
                      valid_ + first,
                      count,
                      needsUv_};
    }
    Padded& pad = padded();
    for (unsigned i = 0; i < count; ++i) {
      for (unsigned c = 0; c < 3; ++c) {
        pad.org[c][i] = f_[c * n_ + first + i];
        pad.dir[c][i] = f_[(4 + c) * n_ + first + i];
      }
      pad.tnear[i] = f_[3 * n_ + first + i];
      pad.tfar[i] = f_[8 * n_ + first + i];
    }
    for (unsigned i = 0; i < RayLanes::kMaxLanes; ++i) pad.valid[i] = i < count ? valid_[first + i] : 0;
    return RayLanes{{pad.org[0], pad.org[1], pad.org[2]},
                    {pad.dir[0], pad.dir[1], pad.dir[2]},
                    pad.tnear,
                    pad.tfar,
                    pad.valid,
                    count,
                    needsUv_};
  }

 private:
  struct Padded {
    alignas(64) float org[3][RayLanes::kMaxLanes];
    alignas(64) float dir[3][RayLanes::kMaxLanes];
    alignas(64) float tnear[RayLanes::kMaxLanes];
    alignas(64) float tfar[RayLanes::kMaxLanes];
    alignas(64) int valid[RayLanes::kMaxLanes];
  };
  static Padded& padded() {
    thread_local Padded pad{};
    return pad;
  }
  float* f_;
  unsigned n_;
  const int* valid_;
  bool needsUv_;
};

// Calls report(lane, hit) for each live lane of the packet that hits the shape, as the shape's
// intersectLanes decides it. Single rays take the same route (a padded block of one live lane),
// so a packet finds exactly the hits single rays find.
template <typename Report>
void intersectPacket(const Shape& shape, bool needsUv, RTCRayN* rays, unsigned n, const int* valid,
                     Report report) {
  PacketLanes packet(rays, n, valid, needsUv);
  thread_local LaneHits hits;  // the thread's own: 16 hit records not rebuilt per call
  for (unsigned k = 0; k < packet.blocks(); ++k) {
    shape.intersectLanes(packet.block(k), hits);
    for (uint32_t bits = hits.mask; bits != 0; bits &= bits - 1) {
      const unsigned lane = unsigned(__builtin_ctz(bits));
      report(k * RayLanes::kMaxLanes + lane, hits.hit[lane]);
    }
  }
}

static_assert(kPacketTfarLanes == RayLanes::kMaxLanes);

void shapeIntersectCallback(const RTCIntersectFunctionNArguments* args) {
  const auto* geometry = static_cast<const ShapeGeometry*>(args->geometryUserPtr);
  RTCRayN* rays = RTCRayHitN_RayN(args->rayhit, args->N);
  RTCHitN* hits = RTCRayHitN_HitN(args->rayhit, args->N);
  const unsigned n = args->N;
  // Shapes report hits with t strictly inside (tnear, tfar), but compute t in double: a hit whose
  // t rounds onto the current tfar would be kept by the shape Embree happens to visit first, and
  // Embree visits them in another order for single rays than for packets. So the shapes see tfar
  // one float step further, and every hit that rounds onto tfar reaches the rule below.
  float tfar[kPacketTfarLanes];
  float* rayTfar = &RTCRayN_tfar(rays, n, 0);
  widenLiveTfar(rayTfar, args->valid, tfar, n);
  intersectPacket(*geometry->shape, geometry->needsUv, rays, n, args->valid,
                  [&](unsigned i, const LocalHit& h) {
                    if (!(h.t <= tfar[i])) return;
                    // A hit at exactly the current tfar ties with the hit found there: the smaller
                    // geomID keeps it, so that the result does not depend on the order Embree visits
                    // the shapes in. With no hit yet, tfar is the ray's own end, which is open.
                    if (h.t == tfar[i]) {
                      const unsigned current = RTCHitN_geomID(hits, n, i);
                      if (current == RTC_INVALID_GEOMETRY_ID || current <= args->geomID) return;
                    }
                    tfar[i] = h.t;
                    RTCHitN_Ng_x(hits, n, i) = h.ng.x;
                    RTCHitN_Ng_y(hits, n, i) = h.ng.y;
                    RTCHitN_Ng_z(hits, n, i) = h.ng.z;
                    RTCHitN_u(hits, n, i) = h.uv.x;
                    RTCHitN_v(hits, n, i) = h.uv.y;
                    RTCHitN_primID(hits, n, i) = args->primID;
                    RTCHitN_geomID(hits, n, i) = args->geomID;
                    RTCHitN_instID(hits, n, i, 0) = args->context->instID[0];
                  });
  storeLiveTfar(rayTfar, args->valid, tfar, n);
}

void shapeOccludedCallback(const RTCOccludedFunctionNArguments* args) {
  const auto* shape = static_cast<const ShapeGeometry*>(args->geometryUserPtr)->shape;
  // Embree 3 reports an occluded ray by setting tfar to -infinity.
  intersectPacket(*shape, false, args->ray, args->N, args->valid,
                  [&](unsigned i, const LocalHit&) { RTCRayN_tfar(args->ray, args->N, i) = -kInfinity; });
}

}  // namespace ember
