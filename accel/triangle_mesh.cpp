#include "accel/triangle_mesh.h"

namespace ember {

TriangleMesh::Surface TriangleMesh::surfaceAt(uint32_t prim, float b1, float b2) const {
  const glm::uvec3& idx = indices[prim];
  const Vec3& p0 = positions[idx.x];
  const Vec3 cross = glm::cross(positions[idx.y] - p0, positions[idx.z] - p0);
  const float len = glm::length(cross);
  Surface s;
  s.ng = len > 0.0f ? cross / len : Vec3(0.0f, 0.0f, 1.0f);
  const float b0 = 1.0f - b1 - b2;
  s.ns = s.ng;
  if (!normals.empty()) {
    const Vec3 n = b0 * normals[idx.x] + b1 * normals[idx.y] + b2 * normals[idx.z];
    const float nl = glm::length(n);
    // A degenerate interpolated normal (opposite vertex normals) falls back to flat shading.
    if (nl > 1e-6f && std::isfinite(nl)) s.ns = n / nl;
  }
  s.uv = uvs.empty() ? Vec2(b1, b2) : b0 * uvs[idx.x] + b1 * uvs[idx.y] + b2 * uvs[idx.z];
  return s;
}

float TriangleMesh::triangleArea(uint32_t prim) const {
  const glm::uvec3& idx = indices[prim];
  const Vec3& p0 = positions[idx.x];
  return 0.5f * glm::length(glm::cross(positions[idx.y] - p0, positions[idx.z] - p0));
}

Bounds TriangleMesh::bounds() const {
  Bounds b;
  for (const Vec3& p : positions) b.extend(p);
  return b;
}

}  // namespace ember
