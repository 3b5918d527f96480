// Renders a scene into a Film, in progressive passes: each pass adds `passSpp` samples to every
// pixel, so at any moment the image is uniformly sampled. A pass cuts the image into square tiles;
// oneTBB's scheduler hands them out from per-thread task deques with work stealing
// (docs/architecture.md explains the choice). Each pixel belongs to one tile, each (pixel, sample
// index) has its own random stream, and a pixel's samples are added in index order whatever the
// passes, so the result is bit-identical for any thread count and any pass size, and a render
// resumed from its film after some passes ends bit-identical to one that never stopped.
#pragma once

#include "renderer/film.h"
#include "renderer/integrator.h"

#include <atomic>
#include <cstdint>
#include <functional>

namespace ember {

struct RenderOptions {
  int spp = 16;
  uint64_t seed = 0;
  int threads = 0;           // 0 = all cores
  uint64_t firstSample = 0;  // render sample indices [firstSample, firstSample + spp)
  int tileSize = 16;
  SamplerType sampler = SamplerType::Independent;
  bool progress = false;
  bool timePhases = false;  // PathStats::phaseNanoseconds (the batched kernels; `ember bench --phases`)

  int passSpp = 4;     // samples per pixel per pass (the last pass may take fewer)
  int passesDone = 0;  // passes the film already holds (a resumed render): pass p renders sample
                       // indices firstSample + [p passSpp, (p + 1) passSpp)
  // Set from outside (a signal handler): no new tile starts, and the interrupted pass is taken
  // back, so the film holds whole passes only. Null: nothing can interrupt.
  const std::atomic<bool>* stop = nullptr;
  double timeBudgetSeconds = 0.0;  // > 0: no pass starts that the last one's time says won't fit
  // > 0: no pass starts once the film's Film::relativeError() is at most this. The check depends
  // on the film alone, before every pass (the first of a resumed render's too), so a render
  // stopped and resumed ends at the same pass as one run through.
  double targetRelativeError = 0.0;
  // Adaptive sampling (renderer/adaptive.h): every pixel first takes the first whole passes holding
  // at least `adaptivePilotSpp` samples; the film then gets each pixel's budget (Film::budgets,
  // kept by checkpoints), sized so that the image's relative error reaches targetRelativeError,
  // and later passes sample a pixel only within it. The render ends when every budget is spent,
  // or at `spp`.
  bool adaptive = false;
  int adaptivePilotSpp = 16;
  // Called after each completed pass with the number of passes the film now holds.
  std::function<void(const Film&, int passes)> onPass;
};

// How many passes of passSpp make spp.
inline int passCount(int spp, int passSpp) {
  return passSpp > 0 ? (spp + passSpp - 1) / passSpp : 0;
}

struct RenderStats {
  double seconds = 0.0;
  int threads = 0;
  uint64_t samples = 0;        // samples per pixel added by this call, times the pixel count
  int passes = 0;              // passes the film holds at the end (earlier ones included)
  int sppDone = 0;             // samples per pixel the film holds at the end (the most, if adaptive)
  bool interrupted = false;    // options.stop was set
  bool outOfTime = false;      // the time budget ended the render before options.spp
  bool converged = false;      // the film reached options.targetRelativeError
  double relativeError = 0.0;  // Film::relativeError() at the end, when a target was set
  uint64_t nonFinite = 0;      // samples dropped because they were NaN or infinite
  PathStats paths;
};

RenderStats render(const Scene& scene, const Integrator& integrator, const RenderOptions& options,
                   Film& film);

}  // namespace ember
