#include "materials/hit_memo.h"

#include <atomic>

namespace ember {

uint64_t newHitMemoOwner() {
  static std::atomic<uint64_t> next{1};
  return next.fetch_add(1, std::memory_order_relaxed);
}

}  // namespace ember
