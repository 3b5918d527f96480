// Small helpers several test files share: a flat shading point and a whole-scene render.
#pragma once

#include "packet/wave_integrator.h"
#include "renderer/render.h"
#include "renderer/scene.h"

namespace ember::test {

// A hit at the origin on the plane z = 0, facing +z, uv (0.5, 0.5): the frame materials are
// sampled in by the chi-square and furnace tests.
inline SurfaceHit flatHit() {
  SurfaceHit hit;
  hit.p = Vec3(0.0f);
  hit.ng = hit.ns = Vec3(0.0f, 0.0f, 1.0f);
  hit.uv = Vec2(0.5f);
  return hit;
}

// An integrator that hands every call to another, for tests that wrap one to watch or change a
// single step: they override only that.
class ForwardingIntegrator : public Integrator {
 public:
  explicit ForwardingIntegrator(const Integrator& inner) : inner_(inner) {}
  Color Li(const Scene& s, Ray r, Sampler& smp, PathStats& st) const override {
    return inner_.Li(s, r, smp, st);
  }
  void renderTile(const Scene& s, const TileWork& w, Film& f, PathStats& st) const override {
    inner_.renderTile(s, w, f, st);
  }
  bool tracesCaustics() const override { return inner_.tracesCaustics(); }
  void traceCaustics(const Scene& s, uint64_t seed, SamplerType sampler, uint64_t first, int count,
                     CausticSplats& splats, PathStats& st) const override {
    inner_.traceCaustics(s, seed, sampler, first, count, splats, st);
  }
  int maxDepth() const override { return inner_.maxDepth(); }
  int rrDepth() const override { return inner_.rrDepth(); }

 private:
  const Integrator& inner_;
};

// Renders a built scene at its own image size and depth settings, with the kernel `ember render`
// uses by default (tests/test_wavefront.cpp holds it equal to the scalar reference).
inline Film renderFilm(const Scene& scene, int spp, uint64_t seed, RenderStats* stats = nullptr,
                       SamplerType sampler = SamplerType::Independent) {
  const std::unique_ptr<Integrator> integrator = makeIntegrator(scene.settings, Kernel::Wave);
  Film film(scene.settings.width, scene.settings.height);
  RenderOptions options;
  options.spp = spp;
  options.seed = seed;
  options.sampler = sampler;
  const RenderStats s = render(scene, *integrator, options, film);
  if (stats) *stats = s;
  return film;
}

}  // namespace ember::test
