// Per-vertex data of a mesh that only some materials read (glTF's TEXCOORD_n beyond the first set,
// COLOR_0, the interpolated normal and tangent before normal mapping), interpolated at a hit on
// demand: the hit record keeps where it lies (SurfaceHit::attributes, prim, bary) rather than the
// values, so that scenes that read none of them pay nothing for them.
#pragma once

#include "core/math.h"

#include <cstdint>

namespace ember {

class VertexAttributes {
 public:
  virtual ~VertexAttributes() = default;
  // Texture coordinates of set `set` at barycentrics b of triangle `prim` (set 0: TEXCOORD_0).
  virtual Vec2 texCoordAt(int set, uint32_t prim, Vec2 b) const = 0;
  // The vertex colour (RGBA), (1, 1, 1, 1) where the mesh has none (glTF 2.0 section 3.7.2.1).
  virtual glm::vec4 colorAt(uint32_t prim, Vec2 b) const = 0;
  // The unit interpolated vertex normal (the geometric one without normals) and the interpolated
  // tangent with its bitangent sign in w (zero without tangents), before any normal map.
  virtual Vec3 normalAt(uint32_t prim, Vec2 b) const = 0;
  virtual glm::vec4 tangentAt(uint32_t prim, Vec2 b) const = 0;
  // Texture coordinates (set 0) per unit of length on triangle `prim`: sqrt(UV area / area), the
  // scale a filtered texture turns a footprint's width into UV units with (Scene::surfaceHit); 0
  // (no filtering) where unknown.
  virtual float uvDensity(uint32_t) const { return 0.0f; }
};

}  // namespace ember
