// Rays cast together: up to `capacity` rays stored as Embree 16-wide packets (structure of arrays,
// lane i of packet i / 16), traced by one call per packet (rtcIntersect16 / rtcOccluded16) or by
// one stream call over all packets (rtcIntersectNM / rtcOccludedNM). Embree then tests each BVH
// node against 16 rays at once, and our user-geometry callbacks get up to 16 rays per call
// (accel/user_geometry.cpp), which they intersect together (accel/shape_lanes.h).
// Storage is allocated once, at construction; push, trace and the queries allocate nothing.
#pragma once

#include "accel/embree_accel.h"

#include <embree3/rtcore.h>

#include <cstddef>
#include <memory>

namespace ember {

// How a batch is handed to Embree; measured in docs/performance.md.
enum class BatchTraversal { Packets, Stream };

class ClosestHitBatch {
 public:
  explicit ClosestHitBatch(size_t capacity);

  void clear() { size_ = 0; }
  size_t size() const { return size_; }
  size_t capacity() const { return capacity_; }
  // Appends a ray (tnear 0, tfar ray.tMax); its index is the size before the call.
  void push(const Ray& ray);
  void trace(const EmbreeAccel& accel, BatchTraversal traversal = BatchTraversal::Packets);
  // The closest hit of ray i, as EmbreeAccel::intersect reports it; false if it hit nothing.
  bool hit(size_t i, RawHit& out) const;
  // The geomID ray i hit, RTC_INVALID_GEOMETRY_ID for a miss.
  uint32_t geometryOf(size_t i) const { return packets_[i / 16].hit.geomID[i % 16]; }

 private:
  size_t capacity_;
  size_t size_ = 0;
  std::unique_ptr<RTCRayHit16[]> packets_;
};

class ShadowBatch {
 public:
  explicit ShadowBatch(size_t capacity);

  void clear() { size_ = 0; }
  size_t size() const { return size_; }
  // Appends a ray blocked by anything on its open segment (0, ray.tMax).
  void push(const Ray& ray);
  void trace(const EmbreeAccel& accel, BatchTraversal traversal = BatchTraversal::Packets);
  bool occluded(size_t i) const { return packets_[i / 16].tfar[i % 16] < 0.0f; }

 private:
  size_t capacity_;
  size_t size_ = 0;
  std::unique_ptr<RTCRay16[]> packets_;
};

}  // namespace ember
