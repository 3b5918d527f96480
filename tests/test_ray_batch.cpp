// Ray batches: the vector check that takes untraceable rays out of Embree's packets
// (packet/traceable_lanes.h) against accel/embree_accel.h's traceable(), ray by ray, and batches
// filled from rows (assign, packet/packet_fields.h) against batches filled ray by ray (push), on
// every SIMD target built.
#include "accel/embree_accel.h"
#include "core/rng.h"
#include "core/sampling.h"
#include "io/scene_loader.h"
#include "packet/ray_batch.h"
#include "packet/traceable_lanes.h"

#include <gtest/gtest.h>

#include "simd_targets.h"
#include "test_paths.h"

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

// Rays in rows (structure of arrays, padded to whole packets) give the same hits and occlusions
// as the same rays pushed one at a time: batch sizes that end mid-packet, both widths, rays with
// masks that skip some geometry, a few untraceable rays, shadow rays of every length.
TEST(RayBatch, BatchesAssignedFromRowsTraceAsPushedOnEveryTarget) {
  Scene scene = loadScene(test::sourcePath("scenes/cornell-point.json"));
  scene.build();
  forEachSimdTarget([&] {
    for (const unsigned width : {8u, 16u}) {
      scene.setPacketWidth(width);
      // The batches are reused, as the renderer reuses them: a trace leaves its marks in the
      // packets (untraceable lanes made inactive, hit distances, occluded rays' tfar), and each
      // assign must write over all of them.
      ClosestHitBatch pushed(1024, width), assigned(1024, width);
      ShadowBatch pushedShadows(1024, width), assignedShadows(1024, width);
      for (const size_t count : {size_t(1024), size_t(17), size_t(300), size_t(1), size_t(1024)}) {
        SCOPED_TRACE(testing::Message() << "width " << width << ", " << count << " rays");
        Rng rng(uint64_t(width), count * 7 + pushed.size());
        const size_t padded = (count + 15) / 16 * 16;
        std::vector<float> origin[3], dir[3], tMax(padded, 0.0f);
        for (int k = 0; k < 3; ++k) origin[k].assign(padded, 0.0f), dir[k].assign(padded, 0.0f);
        std::vector<uint32_t> mask(padded, kAllRayMask);
        pushed.clear();
        pushedShadows.clear();
        for (size_t i = 0; i < count; ++i) {
          Ray ray{Vec3(rng.uniform() * 1.6f - 0.8f, rng.uniform() * 1.8f + 0.1f, rng.uniform() * 2.0f),
                  sampleUniformSphere(Vec2(rng.uniform(), rng.uniform())), rng.uniform() * 3.0f};
          if (i % 97 == count % 97) ray.origin.x = std::numeric_limits<float>::quiet_NaN();  // untraceable
          mask[i] = i % 3 == 0 ? rng.nextU32() | 1u : kAllRayMask;
          for (int k = 0; k < 3; ++k) origin[k][i] = ray.origin[k], dir[k][i] = ray.dir[k];
          tMax[i] = ray.tMax;
          pushedShadows.push(ray, mask[i]);
          ray.tMax = kInfinity;
          pushed.push(ray, mask[i]);
        }
        assigned.assign({origin[0].data(), origin[1].data(), origin[2].data()},
                        {dir[0].data(), dir[1].data(), dir[2].data()}, mask.data(), count);
        assignedShadows.assign({origin[0].data(), origin[1].data(), origin[2].data()},
                               {dir[0].data(), dir[1].data(), dir[2].data()}, tMax.data(), mask.data(),
                               count);
        ASSERT_EQ(assigned.size(), count);
        ASSERT_EQ(assignedShadows.size(), count);
        for (ClosestHitBatch* batch : {&pushed, &assigned}) batch->trace(scene.accel());
        for (ShadowBatch* batch : {&pushedShadows, &assignedShadows}) batch->trace(scene.accel());
        size_t hits = 0, occluded = 0;
        for (size_t i = 0; i < count; ++i) {
          RawHit a, b;
          const bool hitA = pushed.hit(i, a), hitB = assigned.hit(i, b);
          ASSERT_EQ(hitA, hitB) << "ray " << i;
          if (hitA) {
            ++hits;
            EXPECT_EQ(a.geomID, b.geomID) << "ray " << i;
            EXPECT_EQ(a.primID, b.primID) << "ray " << i;
            EXPECT_EQ(std::bit_cast<uint32_t>(a.t), std::bit_cast<uint32_t>(b.t)) << "ray " << i;
          }
          EXPECT_EQ(pushedShadows.occluded(i), assignedShadows.occluded(i)) << "shadow ray " << i;
          occluded += pushedShadows.occluded(i);
        }
        if (count >= 300) {  // the rays must both hit and miss, and be both blocked and not
          EXPECT_GT(hits, count / 4);
          EXPECT_LT(hits, count);
          EXPECT_GT(occluded, count / 10);
          EXPECT_LT(occluded, count - count / 10);
        }
      }
    }
  });
}

}  // namespace
}  // namespace ember
