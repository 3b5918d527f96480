#include "accel/triangle_mesh.h"

namespace ember {

TriangleMesh::Surface TriangleMesh::surfaceAt(uint32_t prim, float b1, float b2) const {
  Surface s;
  s.ng = geometricNormal(prim);
  s.ns = s.ng;
  if (!normals.empty()) {
    const glm::uvec3& idx = indices[prim];
    const Vec3 n = (1.0f - b1 - b2) * normals[idx.x] + b1 * normals[idx.y] + b2 * normals[idx.z];
    const float nl = glm::length(n);
    // A degenerate interpolated normal (opposite vertex normals) falls back to flat shading.
    if (nl > 1e-6f && std::isfinite(nl)) s.ns = n / nl;
  }
  s.uv = uvAt(prim, b1, b2);
  s.tangent = interpolatedTangent(prim, b1, b2);
  return s;
}

Vec3 TriangleMesh::geometricNormal(uint32_t prim) const {
  const glm::uvec3& idx = indices[prim];
  const Vec3& p0 = positions[idx.x];
  const Vec3 cross = glm::cross(positions[idx.y] - p0, positions[idx.z] - p0);
  const float len = glm::length(cross);
  return len > 0.0f ? cross / len : Vec3(0.0f, 0.0f, 1.0f);
}

glm::vec4 TriangleMesh::interpolatedTangent(uint32_t prim, float b1, float b2) const {
  if (tangents.empty()) return glm::vec4(0.0f);
  const glm::uvec3& idx = indices[prim];
  return (1.0f - b1 - b2) * tangents[idx.x] + b1 * tangents[idx.y] + b2 * tangents[idx.z];
}

float TriangleMesh::uvDensity(uint32_t prim) const {
  if (uvs.empty()) return 0.0f;
  const glm::uvec3& idx = indices[prim];
  const Vec2 du = uvs[idx.y] - uvs[idx.x], dv = uvs[idx.z] - uvs[idx.x];
  const float uvArea = std::abs(du.x * dv.y - du.y * dv.x);
  const float area =
      glm::length(glm::cross(positions[idx.y] - positions[idx.x], positions[idx.z] - positions[idx.x]));
  return area > 0.0f && std::isfinite(uvArea) ? std::sqrt(uvArea / area) : 0.0f;
}

Vec2 TriangleMesh::uvAt(uint32_t prim, float b1, float b2) const {
  if (uvs.empty()) return Vec2(b1, b2);
  const glm::uvec3& idx = indices[prim];
  return (1.0f - b1 - b2) * uvs[idx.x] + b1 * uvs[idx.y] + b2 * uvs[idx.z];
}

Vec2 TriangleMesh::texCoordAt(int set, uint32_t prim, Vec2 b) const {
  if (set <= 0 || size_t(set) > texCoordSets.size() || texCoordSets[size_t(set) - 1].empty())
    return uvAt(prim, b.x, b.y);
  const std::vector<Vec2>& t = texCoordSets[size_t(set) - 1];
  const glm::uvec3& idx = indices[prim];
  return (1.0f - b.x - b.y) * t[idx.x] + b.x * t[idx.y] + b.y * t[idx.z];
}

glm::vec4 TriangleMesh::colorAt(uint32_t prim, Vec2 b) const {
  if (colors.empty()) return glm::vec4(1.0f);
  const glm::uvec3& idx = indices[prim];
  return (1.0f - b.x - b.y) * colors[idx.x] + b.x * colors[idx.y] + b.y * colors[idx.z];
}

Vec3 TriangleMesh::pointAt(uint32_t prim, float b1, float b2) const {
  const glm::uvec3& idx = indices[prim];
  return pointOnTriangle(positions[idx.x], positions[idx.y], positions[idx.z], b1, b2);
}

float TriangleMesh::pointError(uint32_t prim) const {
  const glm::uvec3& idx = indices[prim];
  float m = 0.0f;
  for (uint32_t v : {idx.x, idx.y, idx.z}) m = std::max(m, maxAbsComponent(positions[v]));
  return roundingErrorBound(m);
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

void TriangleMesh::generateTangents() {
  if (normals.empty() || uvs.empty()) return;
  std::vector<Vec3> sumT(positions.size(), Vec3(0.0f)), sumB(positions.size(), Vec3(0.0f));
  for (const glm::uvec3& idx : indices) {
    const Vec3 dp1 = positions[idx.y] - positions[idx.x], dp2 = positions[idx.z] - positions[idx.x];
    const Vec2 duv1 = uvs[idx.y] - uvs[idx.x], duv2 = uvs[idx.z] - uvs[idx.x];
    const float det = duv1.x * duv2.y - duv2.x * duv1.y;
    const float weight = 0.5f * glm::length(glm::cross(dp1, dp2));
    if (!(std::abs(det) > 1e-20f) || !(weight > 0.0f)) continue;  // degenerate: no gradient
    // Solving dp = dp/du du + dp/dv dv over both edges; weighting by |det| (UV area) is implicit
    // in leaving the sums unnormalised, so large triangles count more, as in Lengyel's method.
    const Vec3 dpdu = (dp1 * duv2.y - dp2 * duv1.y) / det;
    const Vec3 dpdv = (dp2 * duv1.x - dp1 * duv2.x) / det;
    for (uint32_t v : {idx.x, idx.y, idx.z}) {
      sumT[v] += weight * glm::normalize(dpdu);
      sumB[v] += weight * glm::normalize(dpdv);
    }
  }
  tangents.assign(positions.size(), glm::vec4(0.0f));
  for (size_t v = 0; v < positions.size(); ++v) {
    const Vec3& n = normals[v];
    Vec3 t = sumT[v] - n * glm::dot(n, sumT[v]);
    if (!(glm::length(t) > 1e-12f)) {
      const Frame frame(n);  // no usable UV gradient: any tangent keeps the frame valid
      t = frame.s;
    }
    t = glm::normalize(t);
    const float w = glm::dot(glm::cross(n, t), -sumB[v]) < 0.0f ? -1.0f : 1.0f;
    tangents[v] = glm::vec4(t, w);
  }
}

}  // namespace ember
