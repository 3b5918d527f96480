// Core math helpers whose form is chosen for speed and must not change a result.
#include "core/math.h"
#include "core/rng.h"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>

namespace ember {
namespace {

// maxAbsComponent compares bit patterns (core/math.h); it must equal the float comparison for
// every non-NaN input: signed zeros, denormals, infinities, and random magnitudes.
TEST(MaxAbsComponent, EqualsTheFloatMaximumOfTheMagnitudes) {
  const float special[] = {0.0f, -0.0f, 1e-45f, -1e-45f, 1e-38f, 1.0f, -1.0f, 3e38f, -kInfinity, kInfinity};
  for (const float x : special)
    for (const float y : special)
      for (const float z : special) {
        const Vec3 v(x, y, z);
        EXPECT_EQ(std::bit_cast<uint32_t>(maxAbsComponent(v)),
                  std::bit_cast<uint32_t>(maxComponent(absolute(v))))
            << x << " " << y << " " << z;
      }
  Rng rng(3, 4);
  for (int i = 0; i < 10000; ++i) {
    const Vec3 v((rng.uniform() - 0.5f) * std::ldexp(1.0f, int(rng.uniform() * 60.0f) - 30),
                 (rng.uniform() - 0.5f) * std::ldexp(1.0f, int(rng.uniform() * 60.0f) - 30),
                 (rng.uniform() - 0.5f) * std::ldexp(1.0f, int(rng.uniform() * 60.0f) - 30));
    ASSERT_EQ(maxAbsComponent(v), maxComponent(absolute(v))) << i;
  }
}

}  // namespace
}  // namespace ember
