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
  ProgressReporter progress(uint64_t(width) * uint64_t(height), uint64_t(options.spp), options.progress);

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
          for (int t = range.begin(); t != range.end(); ++t) {
            TileWork work;
            work.x0 = (t % tilesX) * tile;
            work.y0 = (t / tilesX) * tile;
            work.x1 = std::min(work.x0 + tile, width);
            work.y1 = std::min(work.y0 + tile, height);
            work.firstSample = options.firstSample;
            work.spp = options.spp;
            work.seed = options.seed;
            work.sampler = options.sampler;
            integrator.renderTile(scene, work, film, local);
            progress.advance(uint64_t(work.x1 - work.x0) * uint64_t(work.y1 - work.y0));
          }
          std::lock_guard<std::mutex> lock(statsMutex);
          stats.paths += local;
        },
        tbb::simple_partitioner());
  });
  progress.finish();
  stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  stats.samples = uint64_t(width) * uint64_t(height) * uint64_t(options.spp);
  stats.nonFinite = stats.paths.nonFinite;
  return stats;
}

}  // namespace ember
