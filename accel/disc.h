// Disc: a flat, zero-thickness circle with a front normal. UV is planar: u = 0.5 + x / (2R),
// v = 0.5 - y / (2R) over the disc's tangent frame (core/math.h Frame of the normal), so a
// square texture maps onto the disc's bounding square. Also the caps of cylinders and cones.
#pragma once

#include "accel/shape.h"

namespace ember {

// The disc as a value, so other shapes can use it as a cap.
struct DiscGeometry {
  Vec3 center;
  Frame frame;  // frame.n is the front normal
  float radius;

  DoublePlane plane;  // through the centre, with frame.n
  DiscGeometry(const Vec3& c, const Vec3& normal, float r)
      : center(c), frame(normal), radius(r), plane(DoublePlane::through(c, normal)) {}
  bool intersect(const Ray& ray, float tMin, float tMax, LocalHit& hit) const;
  ShapeSample sampleArea(Vec2 u) const;
  // Onto the disc's plane; as a cap, also at least `rimMargin` inside the rim (accel/shape.h).
  SurfacePoint projectToSurface(const Vec3& p, float rimMargin = 0.0f) const;
  float area() const { return kPi * radius * radius; }
  void extendBounds(Bounds& b) const;
};

class Disc final : public Shape {
 public:
  Disc(const Vec3& center, const Vec3& normal, float radius) : disc_(center, normal, radius) {}

  std::string_view typeName() const override { return "disc"; }
  Bounds bounds() const override;
  bool intersect(const Ray& ray, float tMin, float tMax, LocalHit& hit) const override {
    return disc_.intersect(ray, tMin, tMax, hit);
  }
  SurfacePoint projectToSurface(const Vec3& p, const LocalHit&) const override {
    return disc_.projectToSurface(p);
  }
  float area() const override { return disc_.area(); }
  ShapeSample sampleArea(Vec2 u) const override { return disc_.sampleArea(u); }

 private:
  DiscGeometry disc_;
};

}  // namespace ember
