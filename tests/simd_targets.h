// Runs a test's body once on each SIMD target that Highway compiled and this CPU has (AVX-512,
// AVX2, SSE4, ...), not only on the one dynamic dispatch picks, so that a kernel's narrower or
// wider code paths are checked too. Back on the CPU's best target afterwards, also when the body
// fails.
#pragma once

#include <gtest/gtest.h>
#include <hwy/targets.h>

#include <cstdint>
#include <vector>

namespace ember {

template <class Body>
void forEachSimdTarget(Body&& body) {
  struct RestoreTargets {
    ~RestoreTargets() {
      hwy::SetSupportedTargetsForTest(0);
      hwy::GetChosenTarget().Update(hwy::SupportedTargets());
    }
  } restore;
  const std::vector<int64_t> targets = hwy::SupportedAndGeneratedTargets();
  ASSERT_FALSE(targets.empty());
  for (const int64_t target : targets) {
    SCOPED_TRACE(hwy::TargetName(target));
    hwy::SetSupportedTargetsForTest(target);
    hwy::GetChosenTarget().Update(hwy::SupportedTargets());
    body();
    if (::testing::Test::HasFatalFailure()) return;
  }
}

}  // namespace ember
