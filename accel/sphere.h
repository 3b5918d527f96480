// Sphere: exact quadric. UV: u = 0.5 + atan2(n.x, n.z) / (2 pi) (u = 0.5 on +z, growing towards +x),
// v = polar angle / pi from the +y pole (v = 0 at the top). Lights sample the cone of directions
// the sphere subtends (PBRT4 section 6.2.4), which has far less variance than area sampling.
#pragma once

#include "accel/shape.h"

namespace ember {

class Sphere final : public Shape {
 public:
  Sphere(const Vec3& center, float radius) : center_(center), radius_(radius) {}

  std::string_view typeName() const override { return "sphere"; }
  Bounds bounds() const override;
  bool intersect(const Ray& ray, float tMin, float tMax, LocalHit& hit) const override;
  uint32_t candidateLanes(const RayLanes& rays) const override {
    return sphereCandidates(rays, center_, radius_);
  }
  // The candidates' exact tests in one double-precision kernel (sphereHits), equal to intersect().
  void intersectLanes(const RayLanes& rays, LaneHits& out) const override;
  // Longitude from +z towards +x, latitude from +y (../shared/refs/CONVENTIONS.md).
  Vec2 surfaceUv(const LocalHit& hit) const override;
  SurfacePoint projectToSurface(const Vec3& p, const LocalHit& hit) const override;
  float area() const override { return 4.0f * kPi * radius_ * radius_; }
  int convexSide() const override { return 1; }
  ShapeSample sampleArea(Vec2 u) const override;
  bool sampleSolidAngle(const Vec3& ref, Vec2 u, ShapeSample& s, float& pdf) const override;
  float pdfSolidAngle(const Vec3& ref, const Vec3& p, const Vec3& n) const override;

  const Vec3& center() const { return center_; }
  float radius() const { return radius_; }

 private:
  Vec3 center_;
  float radius_;
};

}  // namespace ember
