// A bounce's BSDF samples, for the camera and the light waves alike: each scattering vertex's
// inputs (its hit, the direction it was reached from, its random numbers), sampled one
// Material::sampleLanes call per run of vertices of the same material, then what each returned.
#pragma once

#include "materials/material.h"

#include <array>
#include <cstddef>

namespace ember {

struct BsdfBatch {
  static constexpr size_t kMaxVertices = 1024;
  std::array<const SurfaceHit*, kMaxVertices> hit;
  std::array<Vec3, kMaxVertices> wo;
  std::array<Vec2, kMaxVertices> u;
  std::array<float, kMaxVertices> uLobe;
  std::array<BsdfSample, kMaxVertices> sample;
  std::array<bool, kMaxVertices> sampled;

  // Samples vertices [0, n). Vertices of one material should be consecutive (grouped by
  // geometry): each run is one call. A vertex's sample does not depend on the runs.
  void sampleAll(size_t n) {
    for (size_t first = 0; first < n;) {
      const Material* material = hit[first]->material;
      size_t end = first + 1;
      while (end < n && hit[end]->material == material) ++end;
      material->sampleLanes(&hit[first], &wo[first], &u[first], &uLobe[first], end - first, &sample[first],
                            &sampled[first]);
      first = end;
    }
  }
};

}  // namespace ember
