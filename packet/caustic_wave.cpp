#include "packet/caustic_wave.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>

#include <pmmintrin.h>
#include <xmmintrin.h>

#include <array>
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
  ClosestHitBatch closest{kSize};
  ShadowBatch shadows{kSize};
};

LightWave& threadLightWave() {
  thread_local std::unique_ptr<LightWave> wave;
  if (!wave) wave = std::make_unique<LightWave>();
  return *wave;
}

}  // namespace

void traceCausticsInWaves(const Scene& scene, int maxDepth, int rrDepth, uint64_t seed, SamplerType type,
                          uint64_t firstIndex, int count, CausticSplats& splats, PathStats& stats,
                          BatchTraversal traversal) {
  const CausticTracer& tracer = scene.causticTracer();
  if (!tracer.enabled() || count <= 0) return;
  // Plain variables, not a structured binding: Clang 14 cannot capture those in the lambda.
  const CausticTracer::Batch batch = tracer.batchFor(scene.camera());
  const uint64_t paths = batch.paths;
  const float pathsPerPixel = batch.pathsPerPixel;
  std::mutex statsMutex;
  tbb::parallel_for(
      tbb::blocked_range<uint64_t>(0, paths * uint64_t(count), LightWave::kSize),
      [&](const tbb::blocked_range<uint64_t>& range) {
        _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
        _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
        LightWave& wave = threadLightWave();
        PathStats local;
        size_t active = 0;
        wave.closest.clear();
        for (uint64_t k = range.begin(); k != range.end(); ++k) {
          const size_t i = size_t(k - range.begin());
          const uint64_t index = k / paths;
          LightWave::Lane& lane = wave.lanes[i];
          lane.sampler = CausticTracer::samplerFor(type, seed, k % paths, firstIndex + index);
          if (tracer.start(lane.sampler, int(index), pathsPerPixel, maxDepth, lane.path)) {
            wave.active[active++] = uint16_t(i);
            wave.closest.push(lane.path.ray);
          }
        }
        while (active > 0) {
          local.rays += active;
          wave.closest.trace(scene.accel(), traversal);
          wave.shadows.clear();
          size_t next = 0;
          for (size_t a = 0; a < active; ++a) {
            LightWave::Lane& lane = wave.lanes[wave.active[a]];
            RawHit raw;
            if (!wave.closest.hit(a, raw)) continue;
            SurfaceHit hit;
            scene.surfaceHit(lane.path.ray, raw, hit);
            CausticTracer::Splat& splat = wave.splats[wave.shadows.size()];
            bool continues;
            if (tracer.onHit(scene, maxDepth, rrDepth, lane.path, hit, lane.sampler, splat, continues)) {
              wave.splatImage[wave.shadows.size()] = lane.path.index;
              wave.shadows.push(splat.ray);
            }
            if (continues) wave.next[next++] = wave.active[a];
          }
          wave.closest.clear();  // its hits are all read
          for (size_t a = 0; a < next; ++a) wave.closest.push(wave.lanes[wave.next[a]].path.ray);
          local.shadowRays += wave.shadows.size();
          wave.shadows.trace(scene.accel(), traversal);
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
