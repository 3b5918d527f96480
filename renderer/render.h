// Renders a scene into a Film. The image is cut into square tiles; oneTBB's scheduler hands them
// out from per-thread task deques with work stealing (docs/architecture.md explains the choice).
// Each pixel belongs to one tile and each (pixel, sample index) has its own random stream, so the
// result is bit-identical for any thread count.
#pragma once

#include "renderer/film.h"
#include "renderer/integrator.h"

#include <cstdint>

namespace ember {

struct RenderOptions {
  int spp = 16;
  uint64_t seed = 0;
  int threads = 0;           // 0 = all cores
  uint64_t firstSample = 0;  // render sample indices [firstSample, firstSample + spp)
  int tileSize = 16;
  SamplerType sampler = SamplerType::Independent;
  bool progress = false;
};

struct RenderStats {
  double seconds = 0.0;
  int threads = 0;
  uint64_t samples = 0;
  uint64_t nonFinite = 0;  // samples dropped because they were NaN or infinite
  PathStats paths;
};

RenderStats render(const Scene& scene, const Integrator& integrator, const RenderOptions& options,
                   Film& film);

}  // namespace ember
