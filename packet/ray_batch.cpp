#include "packet/ray_batch.h"

#include <algorithm>
#include <stdexcept>

namespace ember {

namespace {

constexpr size_t kLanes = 16;

size_t packetsFor(size_t capacity) {
  return (capacity + kLanes - 1) / kLanes;
}

// An untraceable ray (accel/embree_accel.h) becomes an inactive lane at the origin with the
// empty interval (1, 0): it misses, and as a shadow ray it is unblocked, as EmbreeAccel treats
// single rays.
template <typename Packet>
void writeRay(Packet& p, size_t lane, const Ray& given) {
  static const Ray inactive{Vec3(0.0f), Vec3(0.0f, 0.0f, 1.0f), 0.0f};
  const bool ok = traceable(given);
  const Ray& ray = ok ? given : inactive;
  p.org_x[lane] = ray.origin.x;
  p.org_y[lane] = ray.origin.y;
  p.org_z[lane] = ray.origin.z;
  p.tnear[lane] = ok ? 0.0f : 1.0f;
  p.dir_x[lane] = ray.dir.x;
  p.dir_y[lane] = ray.dir.y;
  p.dir_z[lane] = ray.dir.z;
  p.tfar[lane] = ray.tMax;
}

// The fields no ray changes, written once per packet at construction.
template <typename Packet>
void initFixedFields(Packet& p) {
  for (size_t lane = 0; lane < kLanes; ++lane) {
    p.time[lane] = 0.0f;
    p.mask[lane] = 0xFFFFFFFFu;  // Debian's Embree is built with ray masks: 0 would miss everything
    p.id[lane] = unsigned(lane);
    p.flags[lane] = 0;
  }
}

// Lanes [0, count) of a packet are valid. Packets after the last are never traced.
void validMask(int (&valid)[kLanes], size_t count) {
  for (size_t i = 0; i < kLanes; ++i) valid[i] = i < count ? -1 : 0;
}

// Stream calls have no valid mask: the unused lanes of the last packet get an empty interval,
// which Embree treats as an inactive ray.
template <typename Packet>
void disableLanes(Packet& p, size_t from) {
  for (size_t i = from; i < kLanes; ++i) {
    p.tnear[i] = 1.0f;
    p.tfar[i] = 0.0f;
  }
}

}  // namespace

ClosestHitBatch::ClosestHitBatch(size_t capacity)
    : capacity_(capacity), packets_(new RTCRayHit16[packetsFor(capacity)]) {
  for (size_t k = 0; k < packetsFor(capacity); ++k) initFixedFields(packets_[k].ray);
}

void ClosestHitBatch::push(const Ray& ray) {
  if (size_ == capacity_) throw std::logic_error("ClosestHitBatch overflow");
  RTCRayHit16& p = packets_[size_ / kLanes];
  const size_t lane = size_ % kLanes;
  writeRay(p.ray, lane, ray);
  p.hit.geomID[lane] = RTC_INVALID_GEOMETRY_ID;
  p.hit.primID[lane] = RTC_INVALID_GEOMETRY_ID;
  p.hit.instID[0][lane] = RTC_INVALID_GEOMETRY_ID;
  ++size_;
}

void ClosestHitBatch::trace(const EmbreeAccel& accel, BatchTraversal traversal) {
  if (size_ == 0) return;
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  const size_t packets = packetsFor(size_);
  if (traversal == BatchTraversal::Stream) {
    disableLanes(packets_[packets - 1].ray, size_ - (packets - 1) * kLanes);
    context.flags = RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
    rtcIntersectNM(accel.rtcScene(), &context, reinterpret_cast<RTCRayHitN*>(packets_.get()), kLanes, packets,
                   sizeof(RTCRayHit16));
    return;
  }
  alignas(64) int valid[kLanes];
  for (size_t k = 0; k < packets; ++k) {
    validMask(valid, std::min(kLanes, size_ - k * kLanes));
    rtcIntersect16(valid, accel.rtcScene(), &context, &packets_[k]);
  }
}

bool ClosestHitBatch::hit(size_t i, RawHit& out) const {
  const RTCRayHit16& p = packets_[i / kLanes];
  const size_t lane = i % kLanes;
  if (p.hit.geomID[lane] == RTC_INVALID_GEOMETRY_ID) return false;
  out.t = p.ray.tfar[lane];
  out.geomID = p.hit.geomID[lane];
  out.primID = p.hit.primID[lane];
  out.ng = Vec3(p.hit.Ng_x[lane], p.hit.Ng_y[lane], p.hit.Ng_z[lane]);
  out.uv = Vec2(p.hit.u[lane], p.hit.v[lane]);
  return true;
}

ShadowBatch::ShadowBatch(size_t capacity)
    : capacity_(capacity), packets_(new RTCRay16[packetsFor(capacity)]) {
  for (size_t k = 0; k < packetsFor(capacity); ++k) initFixedFields(packets_[k]);
}

void ShadowBatch::push(const Ray& ray) {
  if (size_ == capacity_) throw std::logic_error("ShadowBatch overflow");
  writeRay(packets_[size_ / kLanes], size_ % kLanes, ray);
  ++size_;
}

void ShadowBatch::trace(const EmbreeAccel& accel, BatchTraversal traversal) {
  if (size_ == 0) return;
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  const size_t packets = packetsFor(size_);
  if (traversal == BatchTraversal::Stream) {
    disableLanes(packets_[packets - 1], size_ - (packets - 1) * kLanes);
    context.flags = RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
    rtcOccludedNM(accel.rtcScene(), &context, reinterpret_cast<RTCRayN*>(packets_.get()), kLanes, packets,
                  sizeof(RTCRay16));
    return;
  }
  alignas(64) int valid[kLanes];
  for (size_t k = 0; k < packets; ++k) {
    validMask(valid, std::min(kLanes, size_ - k * kLanes));
    rtcOccluded16(valid, accel.rtcScene(), &context, &packets_[k]);
  }
}

}  // namespace ember
