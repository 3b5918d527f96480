#include "renderer/integrator.h"

namespace ember {

Ray cameraRay(const Scene& scene, int x, int y, Sampler& sampler) {
  return cameraRay(scene, x, y, sampler.get2D());
}

Ray cameraRay(const Scene& scene, int x, int y, Vec2 jitter) {
  return scene.camera().generateRay(float(x) + jitter.x, float(y) + jitter.y);
}

void addToFilm(Film& film, int x, int y, const Color& L, PathStats& stats) {
  if (isFinite(L)) {
    film.addSample(x, y, L);
  } else {
    ++stats.nonFinite;
  }
}

namespace {

// The one place a finished sample (with the light tracer's splat for it) reaches the film.
void addSampleToFilm(Film& film, const TileWork& work, int x, int y, int s, const Color& L,
                     const AovSample* aov, PathStats& stats) {
  const Color total = work.caustics ? L + work.caustics->at(s, x, y) : L;
  if (!isFinite(total)) {
    ++stats.nonFinite;
  } else if (aov) {
    film.addSample(x, y, total, *aov);
  } else {
    film.addSample(x, y, total);
  }
}

}  // namespace

void addToFilm(Film& film, const TileWork& work, int x, int y, int s, const Color& L, PathStats& stats) {
  addSampleToFilm(film, work, x, y, s, L, nullptr, stats);
}

void addToFilm(Film& film, const TileWork& work, int x, int y, int s, const Color& L, const AovSample& aov,
               PathStats& stats) {
  addSampleToFilm(film, work, x, y, s, L, &aov, stats);
}

void Integrator::traceCaustics(const Scene& scene, uint64_t seed, SamplerType sampler, uint64_t firstIndex,
                               int count, CausticSplats& splats, PathStats& stats) const {
  scene.causticTracer().traceAlone(scene, maxDepth(), rrDepth(), seed, sampler, firstIndex, count, splats,
                                   stats);
}

void Integrator::renderTile(const Scene& scene, const TileWork& work, Film& film, PathStats& stats) const {
  const uint64_t width = uint64_t(film.width());
  for (int y = work.y0; y < work.y1; ++y)
    for (int x = work.x0; x < work.x1; ++x) {
      const uint64_t pixel = uint64_t(y) * width + uint64_t(x);
      for (int s = 0; s < work.spp; ++s) {
        if (!work.wants(x, y, s)) break;  // a pixel's budget ends its samples
        Sampler sampler(work.sampler, work.seed, pixel, work.firstSample + uint64_t(s));
        const Ray ray = cameraRay(scene, x, y, sampler);
        if (film.aovs().perSample()) {
          AovSample aov;
          const Color L = LiWithAovs(scene, ray, sampler, stats, aov);
          addToFilm(film, work, x, y, s, L, aov, stats);
        } else {
          addToFilm(film, work, x, y, s, Li(scene, ray, sampler, stats), stats);
        }
      }
    }
}

}  // namespace ember
