#include "packet/caustic_wave.h"

#include "materials/material.h"
#include "packet/bsdf_batch.h"
#include "packet/geometry_groups.h"
#include "packet/hit_prefetch.h"
#include "packet/thread_wave.h"
#include "packet/timed_trace.h"
#include "renderer/sampler_lanes.h"
#include "renderer/scene.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>

#include <pmmintrin.h>
#include <xmmintrin.h>

#include <array>
#include <cstdint>
#include <memory>
#include <mutex>

namespace ember {

namespace {

// One thread's light paths in flight and their ray batches, allocated on the thread's first
// task and reused: the bounce loop allocates nothing.
struct LightWave {
  static constexpr size_t kSize = 1024;
  struct Lane {
    Sampler sampler{SamplerType::Independent, 0, 0, 0};
    CausticTracer::PathState path;
  };
  std::array<Lane, kSize> lanes;
  std::array<uint16_t, kSize> active, next;
  std::array<CausticTracer::Splat, kSize> splats;  // the bounce's camera connections
  std::array<int, kSize> splatImage;
  // The bounce's scattering vertices, grouped by geometry and hence by material, so that each
  // material samples its run at once.
  GeometryGroups groups;
  std::array<SurfaceHit, kSize> hits;
  std::array<uint16_t, kSize> vertexLane;
  BsdfBatch bsdfs;
  static_assert(kSize <= BsdfBatch::kMaxVertices && kSize <= GeometryGroups::kMaxLanes);
  // Samplers whose next requests are drawn together (renderer/sampler_lanes.h), and the numbers.
  std::array<Sampler*, kSize> samplerOf;
  std::array<float, kSize> drawn1D;
  std::array<Vec2, kSize> drawn2D;
  std::array<CausticTracer::EmissionNumbers, kSize> emission;
  ClosestHitBatch closest{kSize};
  ShadowBatch shadows{kSize};
};

}  // namespace

void traceCausticsInWaves(const Scene& scene, int maxDepth, int rrDepth, uint64_t seed, SamplerType type,
                          uint64_t firstIndex, int count, CausticSplats& splats, PathStats& stats) {
  const CausticTracer& tracer = scene.causticTracer();
  if (!tracer.enabled() || count <= 0 || !CausticTracer::reachesCaustics(maxDepth)) return;
  // Plain variables, not a structured binding: Clang 14 cannot capture those in the lambda.
  const CausticTracer::Batch batch = tracer.batchFor(scene.camera(), splats.pathFraction());
  const uint64_t paths = batch.paths;
  const float pathsPerPixel = batch.pathsPerPixel;
  std::mutex statsMutex;
  tbb::parallel_for(
      tbb::blocked_range<uint64_t>(0, paths * uint64_t(count), LightWave::kSize),
      [&](const tbb::blocked_range<uint64_t>& range) {
        _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
        _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
        LightWave& wave = threadWave<LightWave>();
        wave.closest.setWidth(scene.accel().packetWidth());
        wave.shadows.setWidth(scene.accel().packetWidth());
        PathStats local;
        size_t active = 0;
        // The emissions: every path's four requests drawn together, in start's order.
        const size_t lanes = size_t(range.size());
        for (size_t i = 0; i < lanes; ++i) {
          const uint64_t k = range.begin() + i;
          wave.lanes[i].sampler = CausticTracer::samplerFor(type, seed, k % paths, firstIndex + k / paths);
          wave.samplerOf[i] = &wave.lanes[i].sampler;
        }
        draw1DThen2DLanes(wave.samplerOf.data(), lanes, wave.drawn1D.data(), wave.drawn2D.data());
        for (size_t i = 0; i < lanes; ++i) {
          wave.emission[i].light = wave.drawn1D[i];
          wave.emission[i].area = wave.drawn2D[i];
        }
        draw1DThen2DLanes(wave.samplerOf.data(), lanes, wave.drawn1D.data(), wave.drawn2D.data());
        for (size_t i = 0; i < lanes; ++i) {
          wave.emission[i].pick = wave.drawn1D[i];
          wave.emission[i].direction = wave.drawn2D[i];
          LightWave::Lane& lane = wave.lanes[i];
          if (tracer.startWith(wave.emission[i], int((range.begin() + i) / paths), pathsPerPixel, maxDepth,
                               lane.path)) {
            wave.active[active++] = uint16_t(i);
            wave.closest.push(lane.path.ray, lane.path.rayMask);
          }
        }
        while (active > 0) {
          local.rays += active;
          traceTimed(wave.closest, scene.accel(), local);
          // CausticTracer::onHit in its steps, each for the whole bounce: arrival and the camera
          // connections, then the BSDFs' numbers and samples, then the next rays.
          wave.shadows.clear();
          wave.groups.group(wave.closest, active, scene.geometryCount());
          size_t vertices = 0;
          const bool prefetch = scene.prefetchesMeshHits();
          for (size_t o = 0; o < active; ++o) {
            if (prefetch) prefetchGroupedHits(scene, wave.closest, wave.groups, o, active);
            const size_t a = wave.groups.order()[o];
            LightWave::Lane& lane = wave.lanes[wave.active[a]];
            RawHit raw;
            if (!wave.closest.hit(a, raw)) continue;
            SurfaceHit& hit = wave.hits[vertices];
            scene.surfaceHit(lane.path.ray, raw, hit);
            CausticTracer::Splat& splat = wave.splats[wave.shadows.size()];
            bool scatters;
            if (tracer.connect(scene, maxDepth, lane.path, hit, splat, scatters)) {
              wave.splatImage[wave.shadows.size()] = lane.path.index;
              wave.shadows.push(splat.ray, splat.mask);
            }
            if (!scatters) continue;
            wave.vertexLane[vertices] = wave.active[a];
            wave.bsdfs.hit[vertices] = &hit;
            wave.bsdfs.wo[vertices] = -lane.path.ray.dir;
            wave.samplerOf[vertices] = &lane.sampler;
            ++vertices;
          }
          draw2DThen1DLanes(wave.samplerOf.data(), vertices, wave.bsdfs.u.data(), wave.bsdfs.uLobe.data());
          wave.bsdfs.sampleAll(vertices);
          wave.closest.clear();  // its hits are all read
          size_t next = 0;
          for (size_t v = 0; v < vertices; ++v) {
            LightWave::Lane& lane = wave.lanes[wave.vertexLane[v]];
            if (tracer.follow(rrDepth, lane.path, wave.hits[v], wave.bsdfs.wo[v], wave.bsdfs.sample[v],
                              wave.bsdfs.sampled[v], lane.sampler)) {
              wave.next[next++] = wave.vertexLane[v];
              wave.closest.push(lane.path.ray, lane.path.rayMask);
            }
          }
          local.shadowRays += wave.shadows.size();
          traceTimed(wave.shadows, scene.accel(), local);
          for (size_t j = 0; j < wave.shadows.size(); ++j)
            if (!wave.shadows.occluded(j) &&
                !splats.add(wave.splatImage[j], wave.splats[j].x, wave.splats[j].y, wave.splats[j].value))
              ++local.nonFinite;
          std::swap(wave.active, wave.next);
          active = next;
        }
        std::lock_guard<std::mutex> lock(statsMutex);
        stats += local;
      },
      tbb::simple_partitioner());
}

}  // namespace ember
