// Box: an oriented rectangular cuboid with full side lengths `size`, centred at `center`, turned by
// an orthonormal rotation. Intersected exactly by the slab method in its own frame (Kay & Kajiya
// 1986). UV on each face: the face's two in-plane local coordinates mapped to [0, 1].
#pragma once

#include "accel/quadric_lanes.h"
#include "accel/shape.h"

namespace ember {

class Box final : public Shape {
 public:
  // `rotation` maps box-local axes to world axes and must be orthonormal.
  Box(const Vec3& center, const Vec3& size, const glm::mat3& rotation);

  std::string_view typeName() const override { return "box"; }
  Bounds bounds() const override;
  bool intersect(const Ray& ray, float tMin, float tMax, LocalHit& hit) const override;
  void intersectLanes(const RayLanes& rays, LaneHits& out) const override;
  SurfacePoint projectToSurface(const Vec3& p, const LocalHit& hit) const override;
  float area() const override;
  int convexSide() const override { return 1; }
  ShapeSample sampleArea(Vec2 u) const override;

 private:
  Vec3 center_;
  Vec3 half_;
  glm::mat3 rotation_;  // local -> world
  ExactBox slab_;

  LocalHit faceHit(const BoxCrossing& crossing) const;
};

}  // namespace ember
