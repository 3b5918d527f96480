#include "renderer/render.h"

#include "renderer/adaptive.h"
#include "renderer/progress.h"

#include <tbb/blocked_range.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>
#include <tbb/task_arena.h>

#include <pmmintrin.h>
#include <xmmintrin.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <mutex>
#include <stdexcept>
#include <string>

namespace ember {

RenderStats render(const Scene& scene, const Integrator& integrator, const RenderOptions& options,
                   Film& film) {
  using Clock = std::chrono::steady_clock;
  const int width = film.width(), height = film.height();
  const int baseTile = std::max(1, options.tileSize);
  const int threads = options.threads > 0 ? options.threads : tbb::info::default_concurrency();
  const int passSpp = std::max(1, options.passSpp);
  const int passes = passCount(options.spp, passSpp);
  const uint64_t pixels = uint64_t(width) * uint64_t(height);
  const auto passSamples = [&](int p) { return std::min(passSpp, options.spp - p * passSpp); };

  RenderStats stats;
  stats.threads = threads;
  stats.passes = std::min(options.passesDone, passes);
  uint64_t remaining = 0;
  for (int p = stats.passes; p < passes; ++p) remaining += pixels * uint64_t(passSamples(p));
  std::mutex statsMutex;
  ProgressReporter progress(remaining, 1, options.progress);
  // Backups of each tile's pixels before it adds a pass, to take an interrupted pass back.
  std::vector<Film::TileBackup> backups;
  std::vector<uint8_t> rendered;
  const auto stopRequested = [&] { return options.stop && options.stop->load(std::memory_order_relaxed); };

  const auto start = Clock::now();
  double lastPass = 0.0;
  const int firstPass = stats.passes;
  tbb::task_arena arena(threads);
  const bool traceCaustics = integrator.tracesCaustics() && scene.causticTracer().enabled();
  // The light tracer splats where the camera projects, and the path tracer has left it the
  // caustics: a film of another size would lose them (a caller's error, never the CLI's).
  if (traceCaustics && (scene.camera().width() != width || scene.camera().height() != height))
    throw std::invalid_argument("render: the film is " + std::to_string(width) + "x" +
                                std::to_string(height) + " but the scene was built for " +
                                std::to_string(scene.camera().width()) + "x" +
                                std::to_string(scene.camera().height()));
  CausticSplats splats;
  // Adaptive sampling: the most samples any pixel's budget asks for, once the budgets are set,
  // and the samples pass p takes.
  const auto largestBudget = [&] {
    return film.budgets().empty() ? uint32_t(options.spp)
                                  : *std::max_element(film.budgets().begin(), film.budgets().end());
  };
  const auto budgetEnd = [&] { return std::min(uint32_t(options.spp), largestBudget()); };
  const auto samplesOfPass = [&](int p) {
    if (film.budgets().empty()) return pixels * uint64_t(passSamples(p));
    const uint32_t offset = uint32_t(p) * uint32_t(passSpp);
    uint64_t taken = 0;
    for (uint32_t b : film.budgets())
      taken += b > offset ? std::min<uint64_t>(b - offset, uint64_t(passSamples(p))) : 0;
    return taken;
  };
  for (int p = firstPass; p < passes; ++p) {
    // The budget admits a pass if the previous one, run again, would end within it; the first
    // pass of a call always runs, so every render adds at least one.
    const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
    if (p > firstPass && options.timeBudgetSeconds > 0.0 && elapsed + lastPass > options.timeBudgetSeconds) {
      stats.outOfTime = true;
      break;
    }
    if (stopRequested()) {
      stats.interrupted = true;
      break;
    }
    const uint32_t passOffset = uint32_t(p) * uint32_t(passSpp);
    if (options.adaptive) {
      // The budgets depend on the pilot passes alone (the film when the pilot ends), so a resumed
      // render sets the same ones, or has them from its checkpoint.
      if (film.budgets().empty() && passOffset >= uint32_t(options.adaptivePilotSpp))
        film.budgets() = adaptiveBudgets(film, options.targetRelativeError, passOffset, kMaxAdaptiveBudget);
      if (passOffset >= budgetEnd()) {
        stats.converged = true;
        break;
      }
    } else if (options.targetRelativeError > 0.0 && film.relativeError() <= options.targetRelativeError) {
      stats.converged = true;
      break;
    }
    const auto passStart = Clock::now();
    // Tiles of the usual size; under adaptive sampling, as much larger as the pass samples fewer
    // pixels, so that a tile still fills the wave driver's waves (the image is the same for any
    // tile size).
    int tile = baseTile;
    if (!film.budgets().empty()) {
      const double share = double(samplesOfPass(p)) / double(pixels * uint64_t(passSamples(p)));
      tile = int(std::min(256.0, double(baseTile) / std::sqrt(std::max(share, 1e-4))));
      tile = std::max(tile, baseTile);
    }
    const int tilesX = (width + tile - 1) / tile, tilesY = (height + tile - 1) / tile;
    const int tiles = tilesX * tilesY;
    rendered.assign(size_t(tiles), 0);
    if (options.stop) backups.resize(size_t(tiles));
    const uint64_t passFirstSample = options.firstSample + uint64_t(p) * uint64_t(passSpp);
    if (traceCaustics) {
      // Under adaptive sampling, light paths in proportion to the samples the pass takes: a light
      // path's splats land anywhere, and most pixels are done.
      splats.reset(passSamples(p), width, height,
                   double(samplesOfPass(p)) / double(pixels * uint64_t(passSamples(p))));
      PathStats traced;
      arena.execute([&] {
        integrator.traceCaustics(scene, options.seed, options.sampler, passFirstSample, passSamples(p),
                                 splats, traced);
      });
      stats.paths += traced;
    }
    arena.execute([&] {
      tbb::parallel_for(
          tbb::blocked_range<int>(0, tiles, 1),
          [&](const tbb::blocked_range<int>& range) {
            // Embree's recommendation: flush denormals to zero in every rendering thread.
            _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
            _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
            PathStats local;
            for (int t = range.begin(); t != range.end(); ++t) {
              if (stopRequested()) continue;
              TileWork work;
              work.x0 = (t % tilesX) * tile;
              work.y0 = (t / tilesX) * tile;
              work.x1 = std::min(work.x0 + tile, width);
              work.y1 = std::min(work.y0 + tile, height);
              work.firstSample = passFirstSample;
              work.spp = passSamples(p);
              work.seed = options.seed;
              work.sampler = options.sampler;
              work.caustics = traceCaustics ? &splats : nullptr;
              work.timePhases = options.timePhases;
              if (!film.budgets().empty()) {
                work.budgets = film.budgets().data();
                work.passOffset = passOffset;
                work.filmWidth = width;
              }
              if (options.stop) film.save(work.x0, work.y0, work.x1, work.y1, backups[size_t(t)]);
              integrator.renderTile(scene, work, film, local);
              rendered[size_t(t)] = 1;
              progress.advance(uint64_t(work.x1 - work.x0) * uint64_t(work.y1 - work.y0) *
                               uint64_t(work.spp));
            }
            std::lock_guard<std::mutex> lock(statsMutex);
            stats.paths += local;
          },
          tbb::simple_partitioner());
    });
    if (std::find(rendered.begin(), rendered.end(), 0) != rendered.end()) {
      // Interrupted: the film goes back to the passes before this one.
      for (int t = 0; t < tiles; ++t)
        if (rendered[size_t(t)]) {
          const int x0 = (t % tilesX) * tile, y0 = (t / tilesX) * tile;
          film.restore(x0, y0, std::min(x0 + tile, width), std::min(y0 + tile, height), backups[size_t(t)]);
        }
      stats.interrupted = true;
      break;
    }
    lastPass = std::chrono::duration<double>(Clock::now() - passStart).count();
    stats.samples += samplesOfPass(p);
    stats.passes = p + 1;
    if (options.onPass) options.onPass(film, stats.passes);
  }
  progress.finish();
  if (options.targetRelativeError > 0.0) {
    stats.relativeError = film.relativeError();
    // Adaptive: converged when every budget is spent, not when --spp cut the budgets short.
    stats.converged = options.adaptive
                          ? !film.budgets().empty() && uint32_t(stats.passes * passSpp) >= largestBudget()
                          : stats.relativeError <= options.targetRelativeError;
  }
  stats.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  stats.sppDone =
      int(std::min<uint32_t>(budgetEnd(), uint32_t(std::min(options.spp, stats.passes * passSpp))));
  stats.nonFinite = stats.paths.nonFinite;
  return stats;
}

}  // namespace ember
