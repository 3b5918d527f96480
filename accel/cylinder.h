// Cylinder from p0 to p1 with a radius: the exact lateral quadric, optionally closed by two disc
// caps (at p0 facing away from p1, at p1 facing away from p0). Normals point outwards.
// UV on the side: u = angle / (2 pi) around the axis in the axis' tangent frame, v = 0 at p0 and
// 1 at p1 (u computed in surfaceUv from the normal); on the caps, the disc's planar mapping (accel/disc.h).
#pragma once

#include "accel/disc.h"

namespace ember {

class Cylinder final : public Shape {
 public:
  Cylinder(const Vec3& p0, const Vec3& p1, float radius, bool caps);

  std::string_view typeName() const override { return "cylinder"; }
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
  Vec3 p0_;
  Frame axis_;  // axis_.n points from p0 to p1
  float height_;
  float radius_;
  bool caps_;
  DiscGeometry cap0_, cap1_;
  LateralQuadric lateral_;

  LocalHit lateralHit(const LateralRoot& root) const;
};

}  // namespace ember
