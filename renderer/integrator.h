// The integrator interface: radiance arriving along a camera ray, estimated with one path.
#pragma once

#include "renderer/sampler.h"
#include "renderer/scene.h"

#include <cstdint>

namespace ember {

// Per-thread counters; merged once per tile, never shared inside the hot loop.
struct PathStats {
  uint64_t rays = 0;        // closest-hit queries
  uint64_t shadowRays = 0;  // occlusion queries
  uint64_t vertices = 0;    // surface hits

  PathStats& operator+=(const PathStats& o) {
    rays += o.rays;
    shadowRays += o.shadowRays;
    vertices += o.vertices;
    return *this;
  }
};

class Integrator {
 public:
  virtual ~Integrator() = default;
  virtual Color Li(const Scene& scene, Ray ray, Sampler& sampler, PathStats& stats) const = 0;
};

}  // namespace ember
