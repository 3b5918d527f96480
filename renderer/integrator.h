// The integrator interface: radiance arriving along a camera ray, estimated with one path, and
// the unit of work the tile scheduler hands out: all samples of a rectangle of pixels.
#pragma once

#include "renderer/film.h"
#include "renderer/path_phases.h"
#include "renderer/sampler.h"
#include "renderer/scene.h"

#include <cstdint>

namespace ember {

// Per-thread counters; merged once per tile, never shared inside the hot loop.
struct PathStats {
  uint64_t rays = 0;        // closest-hit queries
  uint64_t shadowRays = 0;  // occlusion queries
  uint64_t vertices = 0;    // surface hits
  uint64_t nonFinite = 0;   // samples dropped because they were NaN or infinite
  // Wall time the batched kernels spent in their batches' trace calls (Embree and the shapes'
  // callbacks), summed over threads: how much of a render is traversal (`ember bench`'s
  // trace_seconds). The scalar kernel, one ray per call, does not time its rays.
  uint64_t traceNanoseconds = 0;
  // The batched path tracer's time by step of the bounce (renderer/path_phases.h), summed over
  // threads, where the render asked for it (TileWork::timePhases); zeros otherwise.
  std::array<uint64_t, kPathPhases> phaseNanoseconds{};

  PathStats& operator+=(const PathStats& o) {
    rays += o.rays;
    shadowRays += o.shadowRays;
    vertices += o.vertices;
    nonFinite += o.nonFinite;
    traceNanoseconds += o.traceNanoseconds;
    for (size_t i = 0; i < kPathPhases; ++i) phaseNanoseconds[i] += o.phaseNanoseconds[i];
    return *this;
  }
};

// Pixels [x0, x1) x [y0, y1) and sample indices [firstSample, firstSample + spp) of each.
struct TileWork {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  uint64_t firstSample = 0;
  int spp = 1;
  uint64_t seed = 0;
  SamplerType sampler = SamplerType::Independent;
  // The light tracer's splats for the pass (image s for sample index firstSample + s), added to
  // each sample; null when the render traces no caustics.
  const CausticSplats* caustics = nullptr;
  bool timePhases = false;  // charge the batched kernels' time to PathStats::phaseNanoseconds
  // Adaptive sampling: each pixel's budget (Film::budgets, row by row), counted from the render's
  // first sample, of which this pass's sample 0 is number `passOffset`; a pixel renders only the
  // samples within its budget. Null: every sample of the pass.
  const uint32_t* budgets = nullptr;
  uint32_t passOffset = 0;
  int filmWidth = 0;
  bool wants(int x, int y, int s) const {
    return !budgets || passOffset + uint32_t(s) < budgets[size_t(y) * size_t(filmWidth) + size_t(x)];
  }
};

class Integrator {
 public:
  virtual ~Integrator() = default;
  virtual Color Li(const Scene& scene, Ray ray, Sampler& sampler, PathStats& stats) const = 0;
  // The same, recording the sample's AOVs (renderer/aov.h) into `aov`; an estimator that has none
  // leaves it as it was.
  virtual Color LiWithAovs(const Scene& scene, Ray ray, Sampler& sampler, PathStats& stats,
                           AovSample& /*aov*/) const {
    return Li(scene, ray, sampler, stats);
  }

  // Adds every sample of the tile to the film. Each (pixel, sample index) has its own sampler,
  // and a pixel's samples reach the film in the order of their indices, so any implementation
  // that estimates the same paths produces the same film. This one traces each path alone, one
  // ray at a time, pixel by pixel.
  virtual void renderTile(const Scene& scene, const TileWork& work, Film& film, PathStats& stats) const;

  // Whether this estimator leaves caustic paths to the scene's light tracer
  // (renderer/caustic_tracer.h), which render() then runs before each pass, and the path-length
  // settings the tracer must share with it.
  virtual bool tracesCaustics() const { return false; }
  // The light paths of sample indices firstIndex + [0, count) into splats' images 0 .. count - 1,
  // in parallel on the calling thread's task arena (CausticTracer::traceAlone by default).
  virtual void traceCaustics(const Scene& scene, uint64_t seed, SamplerType sampler, uint64_t firstIndex,
                             int count, CausticSplats& splats, PathStats& stats) const;
  virtual int maxDepth() const { return -1; }
  virtual int rrDepth() const { return 5; }
};

// The camera sample (pixel, index) of a tile: its sampler, and the ray through its jittered
// raster position (the sampler's first 2D request).
Ray cameraRay(const Scene& scene, int x, int y, Sampler& sampler);
// The same ray for the pixel jitter the sampler's first request gave.
Ray cameraRay(const Scene& scene, int x, int y, Vec2 jitter);

// Adds a finished sample to the film, or counts it in stats.nonFinite if it is NaN or infinite.
void addToFilm(Film& film, int x, int y, const Color& L, PathStats& stats);
// The same for sample s of the tile's pass, with the light tracer's splat for it added.
void addToFilm(Film& film, const TileWork& work, int x, int y, int s, const Color& L, PathStats& stats);
// The same with the sample's AOVs, for a film that has them (dropped with a non-finite colour).
void addToFilm(Film& film, const TileWork& work, int x, int y, int s, const Color& L, const AovSample& aov,
               PathStats& stats);

}  // namespace ember
