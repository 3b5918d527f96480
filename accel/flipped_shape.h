// A shape with its normals reversed (Mitsuba's `flip_normals`): a closed shape then faces inwards,
// so emission is seen from inside, as in the white-furnace test of a sphere around the camera.
#pragma once

#include "accel/shape.h"

#include <memory>

namespace ember {

class FlippedShape final : public Shape {
 public:
  explicit FlippedShape(std::unique_ptr<Shape> inner) : inner_(std::move(inner)) {}

  std::string_view typeName() const override { return inner_->typeName(); }
  Bounds bounds() const override { return inner_->bounds(); }
  bool intersect(const Ray& ray, float tMin, float tMax, LocalHit& hit) const override {
    if (!inner_->intersect(ray, tMin, tMax, hit)) return false;
    hit.ng = -hit.ng;
    return true;
  }
  uint32_t candidateLanes(const RayLanes& rays) const override { return inner_->candidateLanes(rays); }
  void intersectLanes(const RayLanes& rays, LaneHits& out) const override {
    inner_->intersectLanes(rays, out);
    for (auto& row : out.ng)
      for (float& x : row) x = -x;
  }
  Vec2 surfaceUv(const LocalHit& hit) const override {
    LocalHit original = hit;
    original.ng = -hit.ng;
    return inner_->surfaceUv(original);
  }
  SurfacePoint projectToSurface(const Vec3& p, const LocalHit& hit) const override {
    LocalHit original = hit;
    original.ng = -hit.ng;
    return inner_->projectToSurface(p, original);
  }
  float area() const override { return inner_->area(); }
  bool flat() const override { return inner_->flat(); }
  int convexSide() const override { return -inner_->convexSide(); }
  ShapeSample sampleArea(Vec2 u) const override {
    ShapeSample s = inner_->sampleArea(u);
    s.n = -s.n;
    return s;
  }
  bool sampleSolidAngle(const Vec3& ref, Vec2 u, ShapeSample& s, float& pdf) const override {
    if (!inner_->sampleSolidAngle(ref, u, s, pdf)) return false;
    s.n = -s.n;
    return true;
  }
  void sampleSolidAngleLanes(SolidAngleLanes& lanes) const override {
    inner_->sampleSolidAngleLanes(lanes);
    for (auto& component : lanes.normal)
      for (unsigned i = 0; i < lanes.n; ++i) component[i] = -component[i];
  }
  float pdfSolidAngle(const Vec3& ref, const Vec3& p, const Vec3& n) const override {
    return inner_->pdfSolidAngle(ref, p, -n);
  }

 private:
  std::unique_ptr<Shape> inner_;
};

}  // namespace ember
