// One placement of a shared triangle mesh: a glTF mesh that several nodes use is loaded once, in
// its own object space, and each node places it with its transform. Embree traces it as an
// instance (RTC_GEOMETRY_TYPE_INSTANCE) of one BVH built over the mesh, so memory and build time
// follow the unique triangles, not the placed ones.
//
// Hits are reported in world space, with the values a copy of the mesh transformed into the world
// would give (the geometric normal of the transformed triangle, normals by the inverse transpose,
// tangents by the linear part with the bitangent sign flipped by a mirroring transform), so that
// materials and lights never see object space. The instance is also what a hit's
// SurfaceHit::attributes points to, so that the normal and tangent materials read are world ones.
#pragma once

#include "accel/triangle_mesh.h"

namespace ember {

class MeshInstance final : public VertexAttributes {
 public:
  // toWorld must be invertible with finite entries (the loader bakes any other placement).
  MeshInstance(const TriangleMesh* mesh, const Mat4& toWorld);
  // Whether a transform can place an instance: finite and invertible.
  static bool placeable(const Mat4& toWorld);

  const TriangleMesh& mesh() const { return *mesh_; }
  const Mat4& toWorld() const { return toWorld_; }

  // TriangleMesh's point, error bound and surface at (b1, b2) of `prim`, in world space.
  Vec3 pointAt(uint32_t prim, float b1, float b2) const;
  float pointError(uint32_t prim) const;
  TriangleMesh::Surface surfaceAt(uint32_t prim, float b1, float b2) const;
  Bounds bounds() const;  // of the transformed vertices' box corners
  // A copy of the mesh in world space, as the loader would have made it: for an instance that
  // needs one light per world triangle (an emissive mesh).
  std::unique_ptr<TriangleMesh> baked() const;

  Vec2 texCoordAt(int set, uint32_t prim, Vec2 b) const override { return mesh_->texCoordAt(set, prim, b); }
  glm::vec4 colorAt(uint32_t prim, Vec2 b) const override { return mesh_->colorAt(prim, b); }
  Vec3 normalAt(uint32_t prim, Vec2 b) const override { return surfaceAt(prim, b.x, b.y).ns; }
  glm::vec4 tangentAt(uint32_t prim, Vec2 b) const override { return surfaceAt(prim, b.x, b.y).tangent; }
  float uvDensity(uint32_t prim) const override;

 private:
  Vec3 toWorldPoint(const Vec3& p) const { return Vec3(toWorld_ * glm::vec4(p, 1.0f)); }
  Vec3 toWorldNormal(const Vec3& n) const;

  const TriangleMesh* mesh_;
  Mat4 toWorld_;
  glm::mat3 linear_;        // the transform's linear part: edges and tangents
  glm::mat3 normalMatrix_;  // its inverse transpose: normals
  float handedness_;        // -1 where the transform mirrors (negative determinant)
  float rowNorm_;           // max row sum of |linear_|: how far object-space errors grow
};

}  // namespace ember
