#include "packet/geometry_groups.h"

#include <algorithm>
#include <stdexcept>

namespace ember {

void GeometryGroups::group(const ClosestHitBatch& batch, size_t active, size_t geometries) {
  if (active > kMaxLanes) throw std::logic_error("GeometryGroups: more lanes than it holds");
  const size_t buckets = geometries + 1;
  if (buckets > kMaxCountingSortBuckets) {
    for (size_t a = 0; a < active; ++a)
      sortKey_[a] = uint64_t(batch.geometryOf(a) + 1u) << 16 | a;  // misses (0) first
    std::sort(sortKey_.begin(), sortKey_.begin() + ptrdiff_t(active));
    for (size_t o = 0; o < active; ++o) order_[o] = uint16_t(sortKey_[o] & 0xffffu);
    return;
  }
  if (start_.size() < buckets + 1) start_.assign(buckets + 1, 0);
  std::fill(start_.begin(), start_.begin() + ptrdiff_t(buckets + 1), uint16_t(0));
  for (size_t a = 0; a < active; ++a) {
    const uint32_t key = batch.geometryOf(a) + 1u;  // RTC_INVALID_GEOMETRY_ID + 1 == 0
    key_[a] = key;
    ++start_[key + 1];
  }
  for (size_t b = 1; b <= buckets; ++b) start_[b] += start_[b - 1];
  for (size_t a = 0; a < active; ++a) order_[start_[key_[a]]++] = uint16_t(a);
}

}  // namespace ember
