#include "accel/mesh_instance.h"

#include "core/ray_spawn.h"

#include <cmath>

namespace ember {

bool MeshInstance::placeable(const Mat4& toWorld) {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (!std::isfinite(toWorld[c][r])) return false;
  const float det = glm::determinant(glm::mat3(toWorld));
  return std::isfinite(det) && std::abs(det) > 1e-30f;
}

MeshInstance::MeshInstance(const TriangleMesh* mesh, const Mat4& toWorld)
    : mesh_(mesh),
      toWorld_(toWorld),
      linear_(toWorld),
      normalMatrix_(glm::transpose(glm::inverse(glm::mat3(toWorld)))),
      handedness_(glm::determinant(glm::mat3(toWorld)) < 0.0f ? -1.0f : 1.0f) {
  rowNorm_ = 0.0f;
  for (int r = 0; r < 3; ++r)
    rowNorm_ =
        std::max(rowNorm_, std::abs(linear_[0][r]) + std::abs(linear_[1][r]) + std::abs(linear_[2][r]));
}

Vec3 MeshInstance::toWorldNormal(const Vec3& n) const {
  const Vec3 w = normalMatrix_ * n;
  const float len = glm::length(w);
  return len > 0.0f && std::isfinite(len) ? w / len : Vec3(0.0f, 0.0f, 1.0f);
}

Vec3 MeshInstance::pointAt(uint32_t prim, float b1, float b2) const {
  return toWorldPoint(mesh_->pointAt(prim, b1, b2));
}

// The object-space point's error grows by at most the linear part's row norm, and the transform
// adds its own rounding: a three-term dot product and a translation (core/ray_spawn.h's bound
// covers that many operations at the magnitude of their terms).
float MeshInstance::pointError(uint32_t prim) const {
  const glm::uvec3& idx = mesh_->indices[prim];
  float m = 0.0f;
  for (uint32_t v : {idx.x, idx.y, idx.z}) m = std::max(m, maxAbsComponent(mesh_->positions[v]));
  const Vec3 t(toWorld_[3]);
  return rowNorm_ * roundingErrorBound(m) + roundingErrorBound(rowNorm_ * m + maxAbsComponent(t));
}

TriangleMesh::Surface MeshInstance::surfaceAt(uint32_t prim, float b1, float b2) const {
  TriangleMesh::Surface s;
  // cross(M a, M b) = det(M) M^-T (a x b): the transformed triangle's normal.
  s.ng = handedness_ * toWorldNormal(mesh_->geometricNormal(prim));
  // Vertex normals transformed one by one, then interpolated, as in the copy: under a non-uniform
  // scale, transforming the interpolated normal instead tilts it by degrees on a coarse mesh.
  s.ns = s.ng;
  if (!mesh_->normals.empty()) {
    const glm::uvec3& idx = mesh_->indices[prim];
    const Vec3 n = (1.0f - b1 - b2) * toWorldNormal(mesh_->normals[idx.x]) +
                   b1 * toWorldNormal(mesh_->normals[idx.y]) + b2 * toWorldNormal(mesh_->normals[idx.z]);
    const float nl = glm::length(n);
    if (nl > 1e-6f && std::isfinite(nl)) s.ns = n / nl;  // TriangleMesh::surfaceAt's fallback
  }
  s.uv = mesh_->uvAt(prim, b1, b2);
  if (!mesh_->tangents.empty()) {
    const glm::vec4 t = mesh_->interpolatedTangent(prim, b1, b2);
    s.tangent = glm::vec4(linear_ * Vec3(t), t.w * handedness_);
  }
  return s;
}

float MeshInstance::uvDensity(uint32_t prim) const {
  // The object-space density, over the placement's scaling of this triangle's area.
  const glm::uvec3& idx = mesh_->indices[prim];
  const Vec3 p0 = toWorldPoint(mesh_->positions[idx.x]);
  const float world = glm::length(
      glm::cross(toWorldPoint(mesh_->positions[idx.y]) - p0, toWorldPoint(mesh_->positions[idx.z]) - p0));
  const Vec3& q0 = mesh_->positions[idx.x];
  const float local = glm::length(glm::cross(mesh_->positions[idx.y] - q0, mesh_->positions[idx.z] - q0));
  return world > 0.0f ? mesh_->uvDensity(prim) * std::sqrt(local / world) : 0.0f;
}

Bounds MeshInstance::bounds() const {
  const Bounds local = mesh_->bounds();
  Bounds out;
  if (local.empty()) return out;
  for (int corner = 0; corner < 8; ++corner)
    out.extend(toWorldPoint(Vec3(corner & 1 ? local.upper.x : local.lower.x,
                                 corner & 2 ? local.upper.y : local.lower.y,
                                 corner & 4 ? local.upper.z : local.lower.z)));
  return out;
}

std::unique_ptr<TriangleMesh> MeshInstance::baked() const {
  auto out = std::make_unique<TriangleMesh>(*mesh_);
  for (Vec3& p : out->positions) p = toWorldPoint(p);
  for (Vec3& n : out->normals) n = toWorldNormal(n);
  for (glm::vec4& t : out->tangents) t = glm::vec4(linear_ * Vec3(t), t.w * handedness_);
  return out;
}

}  // namespace ember
