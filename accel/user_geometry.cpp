#include "accel/user_geometry.h"

#include "accel/packet_commit.h"
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
  // The shapes see `tfar` (n floats) as the rays' tfar.
  PacketLanes(RTCRayN* rays, const float* tfar, unsigned n, const int* valid, bool needsUv)
      : f_(reinterpret_cast<float*>(rays)), tfar_(tfar), n_(n), valid_(valid), needsUv_(needsUv) {}

  unsigned blocks() const { return (n_ + RayLanes::kMaxLanes - 1) / RayLanes::kMaxLanes; }
  RayLanes block(unsigned k) {
    const unsigned first = k * RayLanes::kMaxLanes;
    const unsigned count = std::min(RayLanes::kMaxLanes, n_ - first);
    if (count == RayLanes::kMaxLanes || count % rayLanesStep() == 0) {
      const float* base = f_ + first;  // field i of the block: base + i * n_
      return RayLanes{{base, base + n_, base + 2 * n_},
                      {base + 4 * n_, base + 5 * n_, base + 6 * n_},
                      base + 3 * n_,
                      tfar_ + first,
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
      pad.tfar[i] = tfar_[first + i];
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
  const float* tfar_;
  unsigned n_;
  const int* valid_;
  bool needsUv_;
};

// Calls report(first, count, hits) for each block of the packet's lanes [first, first + count)
// with the block's hits, as the shape's intersectLanes decides them. Single rays take the same
// route (a padded block of one live lane), so a packet finds exactly the hits single rays find.
template <typename Report>
void intersectPacket(const Shape& shape, bool needsUv, RTCRayN* rays, const float* tfar, unsigned n,
                     const int* valid, Report report) {
  PacketLanes packet(rays, tfar, n, valid, needsUv);
  thread_local LaneHits hits;  // the thread's own: a block's hit arrays, not rebuilt per call
  for (unsigned k = 0; k < packet.blocks(); ++k) {
    const RayLanes block = packet.block(k);
    shape.intersectLanes(block, hits);
    if (hits.mask != 0) report(k * RayLanes::kMaxLanes, block.n, hits);
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
  float widened[kPacketTfarLanes];
  float* rayTfar = &RTCRayN_tfar(rays, n, 0);
  widenedTfar(rayTfar, args->valid, widened, n);
  // A hit at exactly the current tfar ties with the hit found there: the smaller geomID keeps it
  // (commitLaneHits), so that the result does not depend on the order Embree visits the shapes in.
  intersectPacket(*geometry->shape, geometry->needsUv, rays, widened, n, args->valid,
                  [&](unsigned first, unsigned count, const LaneHits& found) {
                    commitLaneHits(found, count, rayTfar + first, hits, n, first, args->primID, args->geomID,
                                   args->context->instID[0]);
                  });
}

void shapeOccludedCallback(const RTCOccludedFunctionNArguments* args) {
  const auto* shape = static_cast<const ShapeGeometry*>(args->geometryUserPtr)->shape;
  // Embree 3 reports an occluded ray by setting tfar to -infinity.
  intersectPacket(*shape, false, args->ray, &RTCRayN_tfar(args->ray, args->N, 0), args->N, args->valid,
                  [&](unsigned first, unsigned, const LaneHits& found) {
                    for (uint32_t bits = found.mask; bits != 0; bits &= bits - 1)
                      RTCRayN_tfar(args->ray, args->N, first + unsigned(__builtin_ctz(bits))) = -kInfinity;
                  });
}

}  // namespace ember
