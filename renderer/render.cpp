#include "renderer/render.h"

#include "renderer/progress.h"

#include <tbb/blocked_range.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>
#include <tbb/task_arena.h>

#include <pmmintrin.h>
#include <xmmintrin.h>

#include <atomic>
#include <chrono>
#include <mutex>

namespace ember {

RenderStats render(const Scene& scene, const Integrator& integrator, const RenderOptions& options,
                   Film& film) {
  const int width = film.width(), height = film.height();
  const int tile = std::max(1, options.tileSize);
  const int tilesX = (width + tile - 1) / tile, tilesY = (height + tile - 1) / tile;
  const int threads = options.threads > 0 ? options.threads : tbb::info::default_concurrency();

  RenderStats stats;
  stats.threads = threads;
  std::mutex statsMutex;
  std::atomic<uint64_t> nonFinite{0};
  ProgressReporter progress(uint64_t(width) * uint64_t(height), uint64_t(options.spp), options.progress);
  const Camera& camera = scene.camera();

  const auto start = std::chrono::steady_clock::now();
  tbb::task_arena arena(threads);
  arena.execute([&] {
    tbb::parallel_for(
        tbb::blocked_range<int>(0, tilesX * tilesY, 1),
        [&](const tbb::blocked_range<int>& range) {
          // Embree's recommendation: flush denormals to zero in every rendering thread.
          _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
          _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
          PathStats local;
          uint64_t localNonFinite = 0;
          for (int t = range.begin(); t != range.end(); ++t) {
            const int x0 = (t % tilesX) * tile, y0 = (t / tilesX) * tile;
            const int x1 = std::min(x0 + tile, width), y1 = std::min(y0 + tile, height);
            for (int y = y0; y < y1; ++y)
              for (int x = x0; x < x1; ++x) {
                const uint64_t pixel = uint64_t(y) * uint64_t(width) + uint64_t(x);
                for (int s = 0; s < options.spp; ++s) {
                  Sampler sampler(options.sampler, options.seed, pixel, options.firstSample + uint64_t(s));
                  const Vec2 jitter = sampler.get2D();
                  const Ray ray = camera.generateRay(float(x) + jitter.x, float(y) + jitter.y);
                  const Color L = integrator.Li(scene, ray, sampler, local);
                  if (isFinite(L)) {
                    film.addSample(x, y, L);
                  } else {
                    ++localNonFinite;
                  }
                }
              }
            progress.advance(uint64_t(x1 - x0) * uint64_t(y1 - y0));
          }
          nonFinite.fetch_add(localNonFinite, std::memory_order_relaxed);
          std::lock_guard<std::mutex> lock(statsMutex);
          stats.paths += local;
        },
        tbb::simple_partitioner());
  });
  progress.finish();
  stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  stats.samples = uint64_t(width) * uint64_t(height) * uint64_t(options.spp);
  stats.nonFinite = nonFinite.load();
  return stats;
}

}  // namespace ember
