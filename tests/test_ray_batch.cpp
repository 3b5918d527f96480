// Ray batches: the vector check that takes untraceable rays out of Embree's packets
// (packet/traceable_lanes.h) against accel/embree_accel.h's traceable(), ray by ray, on every
// SIMD target built.
#include "accel/embree_accel.h"
#include "core/rng.h"
#include "packet/traceable_lanes.h"

#include <gtest/gtest.h>

#include "simd_targets.h"

#include <bit>
#include <cstdint>
#include <limits>
#include <vector>

namespace ember {
namespace {

constexpr unsigned kFloatsPerRay = 12;  // RTCRayN: org xyz, tnear, dir xyz, time, tfar, mask, id, flags

float coordinate(Rng& rng) {
  const float special[] = {std::numeric_limits<float>::quiet_NaN(),
                           -std::numeric_limits<float>::quiet_NaN(),
                           std::numeric_limits<float>::infinity(),
                           -std::numeric_limits<float>::infinity(),
                           kEmbreeLarge,  // still traceable
                           std::nextafter(kEmbreeLarge, 1e30f),
                           -kEmbreeLarge,
                           2e18f,
                           -0.0f,
                           0.0f,
                           1e-40f};
  if (rng.uniform() < 0.08f) return special[rng.nextU32() % std::size(special)];
  return (rng.uniform() - 0.5f) * 20.0f;
}

TEST(RayBatch, UntraceableLanesEqualTheScalarCheckOnEveryTarget) {
  forEachSimdTarget([] {
    for (const unsigned width : {8u, 16u}) {
      SCOPED_TRACE(width);
      Rng rng(width, 7);
      constexpr size_t kPackets = 40;
      const size_t stride = size_t(width) * kFloatsPerRay + 8;  // padding between packets, untouched
      std::vector<float> data(kPackets * stride + 8);
      for (float& x : data) x = float(rng.nextU32() % 1000);  // every field and the padding
      std::vector<Ray> rays(kPackets * width);
      for (size_t k = 0; k < kPackets; ++k)
        for (unsigned i = 0; i < width; ++i) {
          Ray& r = rays[k * width + i];
          r.origin = Vec3(coordinate(rng), coordinate(rng), coordinate(rng));
          r.dir = Vec3(coordinate(rng), coordinate(rng), coordinate(rng));
          r.tMax = rng.uniform() < 0.05f ? std::numeric_limits<float>::quiet_NaN() : coordinate(rng);
          float* p = data.data() + k * stride;
          const float fields[] = {r.origin.x, r.origin.y, r.origin.z, 0.0f, r.dir.x, r.dir.y, r.dir.z};
          for (unsigned f = 0; f < 7; ++f) p[f * width + i] = fields[f];
          p[8 * width + i] = r.tMax;
        }
      const std::vector<float> before = data;
      disableUntraceableRays(data.data(), kPackets, stride, width);
      int untraceable = 0;
      for (size_t k = 0; k < kPackets; ++k)
        for (unsigned i = 0; i < width; ++i) {
          const Ray& r = rays[k * width + i];
          const float* p = data.data() + k * stride;
          const float* q = before.data() + k * stride;
          const bool ok = traceable(r);
          untraceable += !ok;
          const float inactive[] = {0.0f, 0.0f, 0.0f, 1.0f, 0.0f, 0.0f, 1.0f};
          for (unsigned f = 0; f < 7; ++f)
            EXPECT_EQ(std::bit_cast<uint32_t>(p[f * width + i]),
                      std::bit_cast<uint32_t>(ok ? q[f * width + i] : inactive[f]))
                << "packet " << k << " lane " << i << " field " << f;
          EXPECT_EQ(std::bit_cast<uint32_t>(p[8 * width + i]),
                    std::bit_cast<uint32_t>(ok ? q[8 * width + i] : 0.0f))
              << "packet " << k << " lane " << i << " tfar";
          for (const unsigned f : {7u, 9u, 10u, 11u})  // time, mask, id, flags: never written
            EXPECT_EQ(std::bit_cast<uint32_t>(p[f * width + i]), std::bit_cast<uint32_t>(q[f * width + i]));
        }
      for (size_t k = 0; k < kPackets; ++k)  // the padding after each packet
        for (size_t j = size_t(width) * kFloatsPerRay; j < stride; ++j)
          EXPECT_EQ(data[k * stride + j], before[k * stride + j]);
      EXPECT_GT(untraceable, 50);
      EXPECT_LT(untraceable, int(kPackets * width) - 50);
    }
  });
}

}  // namespace
}  // namespace ember
