// Everything shading needs about a ray's hit point, in world space.
#pragma once

#include "core/math.h"
#include "core/ray_spawn.h"
#include "core/vertex_attributes.h"

#include <cstdint>

namespace ember {

class Material;
class Light;

struct SurfaceHit {
  Vec3 p;
  Vec3 ng;  // unit geometric normal: outward for closed shapes, the front side otherwise
  Vec3 ns;  // unit shading normal, in the same hemisphere as ng
  Vec2 uv;  // texture coordinates; (0, 0) on an analytic shape whose material reads none
  float t = 0.0f;
  float pError = roundingErrorBound(0.0f);  // rounding-error bound of p (core/ray_spawn.h)
  const Material* material = nullptr;
  const Light* light = nullptr;  // the area light this surface belongs to, if it emits
  Color emission{0.0f};          // radiance emitted on the side of ng
  // The Embree ray masks of rays leaving the surface to the side of ng and to the other side:
  // every bit but the surface's own shape's where such a ray cannot meet the shape again (either
  // side of a flat shape, the outer side of a convex solid's boundary: Shape::flat,
  // Shape::convexSide); every bit otherwise.
  uint32_t maskFront = kAllRayMask, maskBack = kAllRayMask;
  bool twoSidedEmission = false;  // emits on both sides (glTF doubleSided)
  // The mesh triangle the hit lies on, for the attributes few materials read (core/
  // vertex_attributes.h); null on analytic shapes.
  const VertexAttributes* attributes = nullptr;
  uint32_t prim = 0;
  Vec2 bary{0.0f};  // barycentrics (b1, b2) within triangle `prim`
  // The width of one pixel's footprint here, in texture coordinates (set 0), for filtered textures;
  // 0 where the scene has none (Scene::surfaceHit, Camera::footprintAt).
  float uvFootprint = 0.0f;

  // Texture coordinates of set `set`: uv for set 0, and on shapes without further sets.
  Vec2 texCoord(int set) const {
    return set == 0 || !attributes ? uv : attributes->texCoordAt(set, prim, bary);
  }
  // The vertex colour, white without one.
  glm::vec4 vertexColor() const { return attributes ? attributes->colorAt(prim, bary) : glm::vec4(1.0f); }

  // Radiance the surface emits towards direction w: only on the side of ng unless two-sided.
  Color emitted(const Vec3& w) const {
    return twoSidedEmission || glm::dot(w, ng) > 0.0f ? emission : Color(0.0f);
  }
  // Origin for a ray leaving the surface in direction dir: p pushed off it by its error bound.
  Vec3 offsetOrigin(const Vec3& dir) const { return offsetAlongNormal(p, ng, pError, dir); }
  // The same for a side already decided (frontSide(ng, dir)), and the Embree mask of a ray that
  // leaves to it: callers decide the side once for both.
  Vec3 offsetOrigin(bool front) const { return offsetAlongNormal(p, ng, pError, front); }
  uint32_t maskFor(bool front) const { return front ? maskFront : maskBack; }
  // The mask of a segment spawnRayTo made from p (origin pushed to side `front`) to `to`, a point
  // within errorTo of the one it aims at: the surface's own bit is left out only where `to` lies
  // clearly off the surface's tangent plane, so that the segment's far end is on the origin's
  // side too (a light sampled on the very surface it lights is not).
  uint32_t maskToward(const Vec3& to, float errorTo, bool front) const {
    // The dot product's own rounding is within a few ulps of sum |d_i| (|ng_i| <= 1); a sum rather
    // than maxAbsComponent, whose std::max GCC's profile-guided build turns into branches that the
    // data-dependent comparison mispredicts.
    const Vec3 d = to - p;
    const float sum = std::fabs(d.x) + std::fabs(d.y) + std::fabs(d.z);
    const bool clear = std::fabs(glm::dot(d, ng)) > pError + errorTo + roundingErrorBound(sum);
    return clear ? maskFor(front) : kAllRayMask;
  }
};

}  // namespace ember
