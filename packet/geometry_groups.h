// A bounce's hits ordered by the geometry they hit (misses first), so that consecutive lanes run
// the same shape, material and light code: the virtual calls of shading then predict well, and
// each material's run of vertices samples its BSDF at once (Material::sampleLanes). Each lane's
// result does not depend on the order lanes are shaded in, so any order gives the same image.
#pragma once

#include "packet/ray_batch.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace ember {

class GeometryGroups {
 public:
  static constexpr size_t kMaxLanes = 1024;
  // Above this many geometries the buckets of a counting sort would cost more to clear than the
  // keys to sort.
  static constexpr size_t kMaxCountingSortBuckets = 1024;

  // A group: order()[begin, end) are the batch indices whose rays hit `geometry`
  // (RTC_INVALID_GEOMETRY_ID: the misses).
  struct Run {
    uint32_t geometry;
    uint16_t begin, end;
  };

  // order()[0, active) lists the batch indices [0, active) of `batch`, grouped by geomID, and
  // runs()[0, runCount()) the groups in that order, none empty.
  void group(const ClosestHitBatch& batch, size_t active, size_t geometries);
  const uint16_t* order() const { return order_.data(); }
  const Run* runs() const { return runs_.data(); }
  size_t runCount() const { return runCount_; }

 private:
  // Padded so that kernels may load order() in whole vectors of up to 16 past its end
  // (packet/arrival_lanes.h).
  static constexpr size_t kOrderPadding = 16;
  std::array<uint16_t, kMaxLanes + kOrderPadding> order_{};
  std::array<uint32_t, kMaxLanes> key_;      // geomID + 1 of each batch index's hit, 0 for a miss
  std::array<uint64_t, kMaxLanes> sortKey_;  // (geomID + 1) << 16 | batch index, for many geometries
  std::array<Run, kMaxLanes> runs_;
  size_t runCount_ = 0;
  static constexpr size_t kWays = 4;  // counters per bucket (geometry_groups.cpp)
  std::vector<uint16_t> start_;       // counting-sort buckets, kWays per geometry, sized once per scene
};

}  // namespace ember
