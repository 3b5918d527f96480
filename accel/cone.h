// Right circular cone from a base centre to an apex: the exact lateral quadric, optionally closed by
// a base disc facing away from the apex. The normal is the exact, smooth cone normal (outwards).
// UV on the side: u = angle / (2 pi) around the axis, v = 0 at the base and 1 at the apex (u computed in
// surfaceUv from the normal); on the base, the disc's planar mapping (accel/disc.h).
#pragma once

#include "accel/disc.h"

namespace ember {

class Cone final : public Shape {
 public:
  Cone(const Vec3& baseCenter, const Vec3& apex, float radius, bool capBase);

  std::string_view typeName() const override { return "cone"; }
  Bounds bounds() const override;
  bool intersect(const Ray& ray, float tMin, float tMax, LocalHit& hit) const override;
  void intersectLanes(const RayLanes& rays, LaneHits& out) const override;
  // u from the lateral hit's normal, here rather than for every root the packets find.
  Vec2 surfaceUv(const LocalHit& hit) const override;
  SurfacePoint projectToSurface(const Vec3& p, const LocalHit& hit) const override;
  float area() const override;
  int convexSide() const override { return 1; }
  ShapeSample sampleArea(Vec2 u) const override;

 private:
  Vec3 lateralNormal(float cosPhi, float sinPhi) const;
  LocalHit lateralHit(const LateralRoot& root) const;

  Vec3 base_;
  Vec3 apex_;
  Frame axis_;  // axis_.n points from the base to the apex
  float height_;
  float radius_;
  bool capBase_;
  DiscGeometry cap_;
  LateralQuadric lateral_;
};

}  // namespace ember
