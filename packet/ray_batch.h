// Rays cast together: up to `capacity` rays stored as Embree packets of `width` rays (8 or 16:
// structure of arrays, lane i % width of packet i / width), traced by one call per packet
// (rtcIntersect8/16, rtcOccluded8/16). Embree then tests each BVH node against a whole packet, and our
// user-geometry callbacks get the packet's rays in one call (accel/user_geometry.cpp), which they intersect
// together (accel/shape_lanes.h). The width should be the one Embree traverses natively
// (EmbreeAccel::packetWidth): a packet of any other width Embree splits and copies into its own,
// and calls the callbacks with those.
// Storage is allocated once, at construction; push, trace and the queries allocate nothing.
#pragma once

#include "accel/embree_accel.h"
#include "core/ray_spawn.h"

#include <embree3/rtcore.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>

namespace ember {

namespace detail {

// Packets of 8 or 16 rays in one aligned allocation; `floatsPerRay` is the size of one ray's
// record (RTCRayHitN or RTCRayN) in floats.
class PacketStorage {
 public:
  PacketStorage(size_t capacity, size_t floatsPerRay, unsigned width);
  // Lays the storage out as packets of `width` rays (8 or 16) with their fixed fields set, unless
  // it is laid out so already.
  void setWidth(unsigned width);
  size_t capacity() const { return capacity_; }
  unsigned width() const { return width_; }
  size_t packets(size_t rays) const { return (rays + width_ - 1) >> shift_; }
  float* packet(size_t k) const { return data_.get() + k * stride_; }
  float* packetOf(size_t i) const { return packet(i >> shift_); }
  unsigned laneOf(size_t i) const { return unsigned(i & (width_ - 1)); }

 private:
  struct Free {
    void operator()(float* p) const;
  };
  size_t capacity_;
  size_t floatsPerRay_;
  std::unique_ptr<float[], Free> data_;
  unsigned width_ = 0;
  unsigned shift_ = 0;
  size_t stride_ = 0;  // floats per packet
};

}  // namespace detail

// Where a ClosestHitBatch keeps its rays' hits, for kernels that gather them by index: field f of
// ray i lies at base[(i >> shift) * stride + f + (i & laneMask)], f being one of the offsets below
// (lane 0's field, in floats from the start of its packet).
struct HitFields {
  const float* base;
  uint32_t shift, laneMask, stride;
  uint32_t tfar, ngX, ngY, ngZ;
};

class ClosestHitBatch {
 public:
  static constexpr unsigned kDefaultWidth = 16;
  explicit ClosestHitBatch(size_t capacity, unsigned width = kDefaultWidth);

  // Rays per packet, 8 or 16; empties the batch.
  void setWidth(unsigned width) {
    size_ = 0;
    storage_.setWidth(width);
  }
  unsigned width() const { return storage_.width(); }
  void clear() { size_ = 0; }
  size_t size() const { return size_; }
  size_t capacity() const { return storage_.capacity(); }
  // Appends a ray (tnear 0, tfar ray.tMax); its index is the size before the call.
  // `mask`: the ray's Embree mask (all bits, or SurfaceHit::maskFor of the surface it leaves).
  void push(const Ray& ray, uint32_t mask = kAllRayMask);
  // Replaces the batch with `count` rays kept in rows (structure of arrays): ray i from
  // (origin[0][i], origin[1][i], origin[2][i]) along dir's, with Embree mask mask[i], as push
  // makes it. Each field of a packet is copied from its row whole: the rows are read up to the
  // next multiple of the width past count (packet/packet_fields.h).
  void assign(const std::array<const float*, 3>& origin, const std::array<const float*, 3>& dir,
              const uint32_t* mask, size_t count);
  void trace(const EmbreeAccel& accel);
  // The closest hit of ray i, as EmbreeAccel::intersect reports it; false if it hit nothing.
  bool hit(size_t i, RawHit& out) const;
  // The layout hit() reads, valid until the next setWidth.
  HitFields hitFields() const;
  // The geomID ray i hit, RTC_INVALID_GEOMETRY_ID for a miss.
  uint32_t geometryOf(size_t i) const {
    return RTCHitN_geomID(hitsOf(i), storage_.width(), storage_.laneOf(i));
  }
  // The primID of ray i's hit, RTC_INVALID_GEOMETRY_ID for a miss.
  uint32_t primitiveOf(size_t i) const {
    return RTCHitN_primID(hitsOf(i), storage_.width(), storage_.laneOf(i));
  }

 private:
  RTCRayHitN* packetOf(size_t i) const { return reinterpret_cast<RTCRayHitN*>(storage_.packetOf(i)); }
  RTCHitN* hitsOf(size_t i) const { return RTCRayHitN_HitN(packetOf(i), storage_.width()); }

  size_t size_ = 0;
  detail::PacketStorage storage_;
};

class ShadowBatch {
 public:
  static constexpr unsigned kDefaultWidth = 16;
  explicit ShadowBatch(size_t capacity, unsigned width = kDefaultWidth);

  // Rays per packet, 8 or 16; empties the batch.
  void setWidth(unsigned width) {
    size_ = 0;
    storage_.setWidth(width);
  }
  unsigned width() const { return storage_.width(); }
  void clear() { size_ = 0; }
  size_t size() const { return size_; }
  // Appends a ray blocked by anything on its open segment (0, ray.tMax) whose Embree mask shares
  // a bit with `mask` (all bits, or the surface's and the light's: ShadowRequest::mask).
  void push(const Ray& ray, uint32_t mask = kAllRayMask);
  // Replaces the batch with `count` rays kept in rows, as ClosestHitBatch::assign: ray i from
  // origin's, along dir's, over (0, tMax[i]), with Embree mask mask[i], as push makes it.
  void assign(const std::array<const float*, 3>& origin, const std::array<const float*, 3>& dir,
              const float* tMax, const uint32_t* mask, size_t count);
  void trace(const EmbreeAccel& accel);
  bool occluded(size_t i) const {
    return RTCRayN_tfar(reinterpret_cast<RTCRayN*>(storage_.packetOf(i)), storage_.width(),
                        storage_.laneOf(i)) < 0.0f;
  }

 private:
  size_t size_ = 0;
  detail::PacketStorage storage_;
};

}  // namespace ember
