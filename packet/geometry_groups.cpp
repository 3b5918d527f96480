#include "packet/geometry_groups.h"

#include <algorithm>
#include <stdexcept>

namespace ember {

void GeometryGroups::group(const ClosestHitBatch& batch, size_t active, size_t geometries) {
  if (active > kMaxLanes) throw std::logic_error("GeometryGroups: more lanes than it holds");
  const size_t buckets = geometries + 1;
  runCount_ = 0;
  if (buckets > kMaxCountingSortBuckets) {
    for (size_t a = 0; a < active; ++a)
      sortKey_[a] = uint64_t(batch.geometryOf(a) + 1u) << 16 | a;  // misses (0) first
    std::sort(sortKey_.begin(), sortKey_.begin() + ptrdiff_t(active));
    for (size_t o = 0; o < active; ++o) {
      order_[o] = uint16_t(sortKey_[o] & 0xffffu);
      if (o == 0 || (sortKey_[o] >> 16) != (sortKey_[o - 1] >> 16))
        runs_[runCount_++] = Run{uint32_t(sortKey_[o] >> 16) - 1u, uint16_t(o), uint16_t(o)};
      ++runs_[runCount_ - 1].end;
    }
    return;
  }
  // kWays counting sorts' counters, one per consecutive range of the batch, visited in turn: most
  // of a bounce's hits fall in a few buckets, and the increments of one counter in consecutive
  // steps would each wait for the last through memory (store to load). Bucket by bucket, the
  // ranges' slots follow one another in range order, so the order is the one counter's (stable).
  const size_t range = (active + kWays - 1) / kWays;
  if (start_.size() < kWays * buckets) start_.assign(kWays * buckets, 0);
  std::fill(start_.begin(), start_.begin() + ptrdiff_t(kWays * buckets), uint16_t(0));
  for (size_t i = 0; i < range; ++i)
    for (size_t w = 0; w < kWays; ++w) {
      const size_t a = w * range + i;
      if (a >= active) break;
      const uint32_t key = batch.geometryOf(a) + 1u;  // RTC_INVALID_GEOMETRY_ID + 1 == 0
      key_[a] = key;
      ++start_[w * buckets + key];
    }
  uint16_t next = 0;
  for (size_t b = 0; b < buckets; ++b) {
    const uint16_t begin = next;
    for (size_t w = 0; w < kWays; ++w) {
      const uint16_t count = start_[w * buckets + b];
      start_[w * buckets + b] = next;
      next = uint16_t(next + count);
    }
    if (next != begin) runs_[runCount_++] = Run{uint32_t(b) - 1u, begin, next};  // bucket 0: ~0u
  }
  for (size_t i = 0; i < range; ++i)
    for (size_t w = 0; w < kWays; ++w) {
      const size_t a = w * range + i;
      if (a >= active) break;
      order_[start_[w * buckets + key_[a]]++] = uint16_t(a);
    }
}

}  // namespace ember
