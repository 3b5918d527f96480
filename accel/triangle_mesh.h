// An indexed triangle mesh in world space (from glTF), traced by Embree's own triangle kernels.
// Normals and UVs are optional per-vertex attributes; without normals the mesh is shaded flat.
#pragma once

#include "accel/shape.h"

#include <string>
#include <vector>

namespace ember {

struct TriangleMesh {
  std::string name;
  std::vector<Vec3> positions;
  std::vector<Vec3> normals;  // empty, or one per position
  std::vector<Vec2> uvs;      // empty, or one per position
  std::vector<glm::uvec3> indices;

  struct Surface {
    Vec3 ng;  // front normal: normalize(cross(p1 - p0, p2 - p0))
    Vec3 ns;  // interpolated vertex normal, or ng
    Vec2 uv;
  };
  // Surface attributes at barycentrics (b1, b2) of triangle `prim`.
  Surface surfaceAt(uint32_t prim, float b1, float b2) const;

  float triangleArea(uint32_t prim) const;
  Bounds bounds() const;
};

}  // namespace ember
