// Raw Embree throughput in the cornell-area geometry: the "limit" Ember's path vertices/s are
// compared with (docs/performance.md). Casts a synthetic form of a path tracer's ray mix —
// incoherent closest-hit rays starting on surfaces inside the box, and shadow rays from those
// points to the area light — as single rays (rtcIntersect1/rtcOccluded1) and as 8- and 16-wide
// packets, on 1 and on all threads. It is harder than Ember's own mix: every vertex casts a shadow
// ray (Ember's cast 0.65 per vertex there: none where the light is behind the surface or the
// material is a Dirac one), no ray is a coherent camera ray, and consecutive rays start at random
// points of the box. `ember bench`'s trace_share measures Ember's own rays
// (benchmarks/limit_fraction.py reports both). The scene is Ember's own (analytic user geometry), so
// the numbers include the cost of our intersection callbacks, exactly as Ember pays it, and the rays
// carry the Embree masks Ember's own carry (Shape::flat, Shape::convexSide).
//   embree_raw_throughput [scene.json] [--rays N] [--mix-only]
// --mix-only measures the two vertex-mix rows alone (the limit), for benchmarks/limit_fraction.py.
#include "core/sampling.h"
#include "io/scene_loader.h"
#include "packet/ray_batch.h"

#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

namespace ember {
namespace {

struct RayBatch {
  std::vector<Ray> closest;
  std::vector<Ray> shadow;
  std::vector<float> shadowDist;
  // The Embree masks Ember's own rays carry (Shape::flat, Shape::convexSide): a closest-hit ray
  // skips the shape it leaves, a shadow ray that one and the flat light it is aimed at.
  std::vector<uint32_t> closestMask, shadowMask;
};

// Path-tracer-like rays: start at the first hit of a random camera ray, continue in a cosine
// direction (closest-hit), and aim a shadow ray at a random point of the light.
RayBatch makeRays(const Scene& scene, size_t n) {
  RayBatch b;
  Rng rng(11, 1);
  const Vec3 lightCenter(0.0f, 1.98f, 0.0f);
  // The light's Light::shadowMask; all bits unless the scene has exactly one light (the rays aim
  // at cornell-area's).
  const uint32_t lightMask = scene.lights.size() == 1 ? scene.lights[0]->shadowMask : kAllRayMask;
  while (b.closest.size() < n) {
    const Ray cam = scene.camera().generateRay(rng.uniform() * 256.0f, rng.uniform() * 256.0f);
    SurfaceHit hit;
    if (!scene.intersect(cam, hit)) continue;
    const Vec3 n0 = glm::dot(hit.ng, cam.dir) < 0.0f ? hit.ng : -hit.ng;
    const Vec3 dir = Frame(n0).toWorld(sampleCosineHemisphere(Vec2(rng.uniform(), rng.uniform())));
    const bool front = frontSide(hit.ng, dir);
    b.closest.push_back(Ray{hit.offsetOrigin(front), dir});
    b.closestMask.push_back(hit.maskFor(front));
    const Vec3 target = lightCenter + Vec3(rng.uniform() - 0.5f, 0.0f, rng.uniform() - 0.5f) * 0.5f;
    const float targetError = roundingErrorBound(maxAbsComponent(target));
    const bool toLight = frontSide(hit.ng, target - hit.p);
    b.shadow.push_back(
        spawnRayTo(hit.p, hit.ng, hit.pError, target, Vec3(0.0f, -1.0f, 0.0f), targetError, toLight));
    b.shadowDist.push_back(b.shadow.back().tMax);
    b.shadowMask.push_back(hit.maskToward(target, targetError, toLight) & lightMask);
  }
  return b;
}

template <int N, typename Packet>
void fillPacket(Packet& p, const Ray* rays, const float* tfar, const uint32_t* masks) {
  for (int i = 0; i < N; ++i) {
    p.org_x[i] = rays[i].origin.x;
    p.org_y[i] = rays[i].origin.y;
    p.org_z[i] = rays[i].origin.z;
    p.dir_x[i] = rays[i].dir.x;
    p.dir_y[i] = rays[i].dir.y;
    p.dir_z[i] = rays[i].dir.z;
    p.tnear[i] = 0.0f;
    p.tfar[i] = tfar ? tfar[i] : kInfinity;
    p.time[i] = 0.0f;
    p.mask[i] = masks[i];
    p.id[i] = unsigned(i);
    p.flags[i] = 0;
  }
}

// Mrays/s of `work(begin, end)` over n rays on `threads` threads.
template <typename Work>
double measure(size_t n, int threads, Work work) {
  tbb::task_arena arena(threads);
  const auto t0 = std::chrono::steady_clock::now();
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 4096),
                      [&](const tbb::blocked_range<size_t>& r) { work(r.begin(), r.end()); });
  });
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return double(n) / s * 1e-6;
}

int run(int argc, char** argv) {
  std::string path = std::string(EMBER_SOURCE_DIR) + "/scenes/cornell-area.json";
  size_t n = 2'000'000;
  bool mixOnly = false;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--rays") && i + 1 < argc)
      n = std::stoul(argv[++i]);
    else if (!std::strcmp(argv[i], "--mix-only"))
      mixOnly = true;
    else
      path = argv[i];
  }
  n -= n % 16;
  Scene scene = loadScene(path);
  scene.build();
  const RayBatch b = makeRays(scene, n);
  RTCScene rtc = scene.accel().rtcScene();
  const int all = tbb::info::default_concurrency();

  std::printf("batches: packets of %u rays (Embree's native width here)\n", scene.accel().packetWidth());
  std::printf("%-34s %10s %10s\n", "ray kind (Mrays/s)", "1 thread",
              std::to_string(all).append(" threads").c_str());
  auto row = [&](const char* name, auto work) {
    if (mixOnly && std::strncmp(name, "vertex mix", 10) != 0) return;
    const double one = measure(n, 1, work);
    const double many = measure(n, all, work);
    std::printf("%-34s %10.2f %10.2f\n", name, one, many);
  };
  row("incoherent closest-hit, single", [&](size_t lo, size_t hi) {
    for (size_t i = lo; i < hi; ++i) {
      SurfaceHit h;
      scene.intersect(b.closest[i], h, b.closestMask[i]);
    }
  });
  row("shadow to light, single", [&](size_t lo, size_t hi) {
    for (size_t i = lo; i < hi; ++i) scene.occluded(b.shadow[i], b.shadowMask[i]);
  });
  row("incoherent closest-hit, 8-wide", [&](size_t lo, size_t hi) {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    alignas(32) int valid[8];
    std::fill(valid, valid + 8, -1);
    for (size_t i = lo; i + 8 <= hi; i += 8) {
      alignas(32) RTCRayHit8 rh;
      fillPacket<8>(rh.ray, &b.closest[i], nullptr, &b.closestMask[i]);
      std::fill(rh.hit.geomID, rh.hit.geomID + 8, RTC_INVALID_GEOMETRY_ID);
      rtcIntersect8(valid, rtc, &ctx, &rh);
    }
  });
  row("incoherent closest-hit, 16-wide", [&](size_t lo, size_t hi) {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    alignas(64) int valid[16];
    std::fill(valid, valid + 16, -1);
    for (size_t i = lo; i + 16 <= hi; i += 16) {
      alignas(64) RTCRayHit16 rh;
      fillPacket<16>(rh.ray, &b.closest[i], nullptr, &b.closestMask[i]);
      std::fill(rh.hit.geomID, rh.hit.geomID + 16, RTC_INVALID_GEOMETRY_ID);
      rtcIntersect16(valid, rtc, &ctx, &rh);
    }
  });
  row("shadow to light, 16-wide", [&](size_t lo, size_t hi) {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    alignas(64) int valid[16];
    std::fill(valid, valid + 16, -1);
    for (size_t i = lo; i + 16 <= hi; i += 16) {
      alignas(64) RTCRay16 r;
      fillPacket<16>(r, &b.shadow[i], &b.shadowDist[i], &b.shadowMask[i]);
      rtcOccluded16(valid, rtc, &ctx, &r);
    }
  });
  // What the wave driver does (packet/ray_batch.h): batches of rays (256 here; the driver's waves
  // are 1,024, which changes nothing for packets, traced one by one), copied in, traced as
  // packets, hits read back.
  auto batchRow = [&](const char* name, bool shadow) {
    row(name, [&, shadow](size_t lo, size_t hi) {
      ClosestHitBatch closest(256, scene.accel().packetWidth());
      ShadowBatch shadows(256, scene.accel().packetWidth());
      RawHit raw;
      for (size_t i = lo; i < hi; i += 256) {
        const size_t end = std::min(hi, i + 256);
        if (shadow) {
          shadows.clear();
          for (size_t k = i; k < end; ++k) shadows.push(b.shadow[k], b.shadowMask[k]);
          shadows.trace(scene.accel());
        } else {
          closest.clear();
          for (size_t k = i; k < end; ++k) closest.push(b.closest[k], b.closestMask[k]);
          closest.trace(scene.accel());
          for (size_t k = 0; k < closest.size(); ++k) closest.hit(k, raw);
        }
      }
    });
  };
  batchRow("closest-hit, batch of packets", false);
  batchRow("shadow, batch of packets", true);
  // The mix a path tracer casts: one closest-hit and one shadow ray per path vertex.
  row("vertex mix (1 closest + 1 shadow)", [&](size_t lo, size_t hi) {
    for (size_t i = lo; i < hi; ++i) {
      SurfaceHit h;
      scene.intersect(b.closest[i], h, b.closestMask[i]);
      scene.occluded(b.shadow[i], b.shadowMask[i]);
    }
  });
  row("vertex mix, batches of packets", [&](size_t lo, size_t hi) {
    ClosestHitBatch closest(256, scene.accel().packetWidth());
    ShadowBatch shadows(256, scene.accel().packetWidth());
    RawHit raw;
    for (size_t i = lo; i < hi; i += 256) {
      const size_t end = std::min(hi, i + 256);
      closest.clear();
      shadows.clear();
      for (size_t k = i; k < end; ++k) {
        closest.push(b.closest[k], b.closestMask[k]);
        shadows.push(b.shadow[k], b.shadowMask[k]);
      }
      closest.trace(scene.accel());
      for (size_t k = 0; k < closest.size(); ++k) closest.hit(k, raw);
      shadows.trace(scene.accel());
    }
  });
  std::printf("(vertex mix rows: M path vertices/s at the traversal limit; the faster is the limit)\n");
  return 0;
}

}  // namespace
}  // namespace ember

int main(int argc, char** argv) {
  return ember::run(argc, argv);
}
