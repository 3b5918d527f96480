// Disc: a flat, zero-thickness circle with a front normal. UV is planar: u = 0.5 + x / (2R),
// v = 0.5 - y / (2R) over the disc's tangent frame (core/math.h Frame of the normal), so a
// square texture maps onto the disc's bounding square. Also the caps of cylinders and cones.
#pragma once

#include "accel/quadric_lanes.h"
#include "accel/shape.h"

namespace ember {

// The disc as a value, so other shapes can use it as a cap.
struct DiscGeometry {
  Vec3 center;
  Frame frame;  // frame.n is the front normal
  float radius;

  DoublePlane plane;  // through the centre, with frame.n
  ExactDisc exact;    // the intersection routine's parameters, in double
  DiscGeometry(const Vec3& c, const Vec3& normal, float r);
  bool intersect(const Ray& ray, float tMin, float tMax, LocalHit& hit) const {
    DiscCrossing crossing;
    if (!exact.cross(ray, tMin, tMax, crossing)) return false;
    hit = hitAt(crossing);
    return true;
  }
  // The hit of a crossing that exact.cross or discCrossings found.
  LocalHit hitAt(const DiscCrossing& c) const {
    const double r = radius;
    return {float(c.t), frame.n, Vec2(float(0.5 + 0.5 * c.x / r), float(0.5 - 0.5 * c.y / r))};
  }
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
  void intersectLanes(const RayLanes& rays, LaneHits& out) const override;
  SurfacePoint projectToSurface(const Vec3& p, const LocalHit&) const override {
    return disc_.projectToSurface(p);
  }
  float area() const override { return disc_.area(); }
  bool flat() const override { return true; }
  ShapeSample sampleArea(Vec2 u) const override { return disc_.sampleArea(u); }

 private:
  DiscGeometry disc_;
};

}  // namespace ember
