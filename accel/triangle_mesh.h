// An indexed triangle mesh in world space (from glTF), traced by Embree's own triangle kernels.
// Normals, UVs and tangents are optional per-vertex attributes; without normals the mesh is shaded
// flat. An optional opacity makes parts of it transparent to rays (glTF alpha modes).
#pragma once

#include "accel/shape.h"
#include "core/vertex_attributes.h"

#include <memory>
#include <string>
#include <vector>

namespace ember {

struct TriangleMesh;

// Decides, inside Embree's traversal, whether a ray passes through the mesh at a hit, at
// barycentrics b of triangle `prim`.
class MeshOpacity {
 public:
  virtual ~MeshOpacity() = default;
  // `u` is uniform in [0, 1), a hash of the ray and the triangle, for stochastic transparency.
  virtual bool passesThrough(const TriangleMesh& mesh, uint32_t prim, Vec2 b, float u) const = 0;
  // The probability that a ray stops there: what light sampling weights an emitter's radiance by,
  // so that it agrees with the emission rays find through passesThrough.
  virtual float coverage(const TriangleMesh& mesh, uint32_t prim, Vec2 b) const = 0;
};

// The point at barycentrics (b1, b2) of vertices p1 and p2 of triangle (p0, p1, p2): the one
// expression every interpolated point uses (TriangleMesh::pointAt, TriangleLight's samples), so
// that they agree bit for bit.
inline Vec3 pointOnTriangle(const Vec3& p0, const Vec3& p1, const Vec3& p2, float b1, float b2) {
  return (1.0f - b1 - b2) * p0 + b1 * p1 + b2 * p2;
}

struct TriangleMesh final : VertexAttributes {
  std::string name;
  std::vector<Vec3> positions;
  std::vector<Vec3> normals;        // empty, or one per position
  std::vector<Vec2> uvs;            // empty, or one per position: TEXCOORD_0
  std::vector<glm::vec4> tangents;  // empty, or one per position: xyz and the bitangent sign w
  // TEXCOORD_1, TEXCOORD_2, ...: texCoordSets[k] is set k + 1, each empty or one per position.
  std::vector<std::vector<Vec2>> texCoordSets;
  std::vector<glm::vec4> colors;  // empty, or one RGBA per position: COLOR_0
  std::vector<glm::uvec3> indices;
  std::shared_ptr<const MeshOpacity> opacity;  // null: opaque

  struct Surface {
    Vec3 ng;  // front normal: normalize(cross(p1 - p0, p2 - p0))
    Vec3 ns;  // interpolated vertex normal, or ng
    Vec2 uv;
    glm::vec4 tangent{0.0f};  // interpolated tangent and sign; zero when the mesh has none
  };
  // Surface attributes at barycentrics (b1, b2) of triangle `prim`.
  Surface surfaceAt(uint32_t prim, float b1, float b2) const;
  Vec2 uvAt(uint32_t prim, float b1, float b2) const;
  Vec3 geometricNormal(uint32_t prim) const;  // unit, (0, 0, 1) for a degenerate triangle
  glm::vec4 interpolatedTangent(uint32_t prim, float b1, float b2) const;  // 0 without tangents
  // Texture coordinate sets beyond uvs count from 1; a set the mesh lacks reads as set 0 (the
  // loader refuses materials that name one).
  int texCoordSetCount() const { return 1 + int(texCoordSets.size()); }
  Vec2 texCoordAt(int set, uint32_t prim, Vec2 b) const override;
  glm::vec4 colorAt(uint32_t prim, Vec2 b) const override;
  Vec3 normalAt(uint32_t prim, Vec2 b) const override { return surfaceAt(prim, b.x, b.y).ns; }
  glm::vec4 tangentAt(uint32_t prim, Vec2 b) const override { return surfaceAt(prim, b.x, b.y).tangent; }
  float uvDensity(uint32_t prim) const override;
  // The point at barycentrics (b1, b2) of triangle `prim`, interpolated from its vertices, with the
  // rounding-error bound of points computed from them (core/ray_spawn.h).
  Vec3 pointAt(uint32_t prim, float b1, float b2) const;
  float pointError(uint32_t prim) const;

  float triangleArea(uint32_t prim) const;
  Bounds bounds() const;

  // Per-vertex tangents for normal mapping when the file has none: the UV-gradient tangent of
  // every triangle (Lengyel 2001) summed over the triangles sharing a vertex, made orthogonal to
  // the vertex normal. The bitangent sign follows glTF's convention that a normal map's +Y points
  // up in the image, i.e. towards decreasing v: w = sign(dot(cross(n, t), -dp/dv)). This agrees
  // with MikkTSpace on meshes whose UV charts are not mirrored within a vertex's fan. Needs
  // normals and UVs; does nothing without them.
  void generateTangents();
};

}  // namespace ember
