// Flat triangle and planar quad (two triangles (v0,v1,v2), (v0,v2,v3), as in ../shared/refs).
// The front normal is normalize(cross(v1 - v0, v2 - v0)). UVs are per-vertex and interpolated
// barycentrically; defaults: triangle (0,0), (1,0), (0,1); quad (0,0), (1,0), (1,1), (0,1).
// As a light, a rectangular quad seen from closer than about twice its size is sampled by solid
// angle (spherical_rectangle.h), and so is a triangle (spherical_triangle.h); other quads, and
// shapes seen from farther, by area.
#pragma once

#include "accel/quadric_lanes.h"
#include "accel/shape.h"

#include <array>

namespace ember {

// Moller & Trumbore 1997, "Fast, Minimum Storage Ray/Triangle Intersection", in double precision.
// On a hit, writes t and the barycentrics (b1, b2) of v1 and v2.
bool intersectTriangle(const Ray& ray, const Vec3& v0, const Vec3& v1, const Vec3& v2, float tMin, float tMax,
                       float& t, float& b1, float& b2);

class Triangle final : public Shape {
 public:
  Triangle(const std::array<Vec3, 3>& v, const std::array<Vec2, 3>& uv);

  std::string_view typeName() const override { return "triangle"; }
  Bounds bounds() const override;
  bool intersect(const Ray& ray, float tMin, float tMax, LocalHit& hit) const override;
  uint32_t candidateLanes(const RayLanes& rays) const override;
  void intersectLanes(const RayLanes& rays, LaneHits& out) const override;
  SurfacePoint projectToSurface(const Vec3& p, const LocalHit&) const override { return plane_.project(p); }
  float area() const override { return area_; }
  float uvDensity() const override;
  bool flat() const override { return true; }
  ShapeSample sampleArea(Vec2 u) const override;
  // Seen from close by, uniform in the solid angle it subtends (accel/spherical_triangle.h).
  bool sampleSolidAngle(const Vec3& ref, Vec2 u, ShapeSample& s, float& pdf) const override;
  float pdfSolidAngle(const Vec3& ref, const Vec3& p, const Vec3& n) const override;

 private:
  std::array<Vec3, 3> v_;
  std::array<Vec2, 3> uv_;
  Vec3 normal_;
  DoublePlane plane_;
  TriangleFilter filter_;
  PlaneCoordinates coords_;
  float area_;
};

class Quad final : public Shape {
 public:
  Quad(const std::array<Vec3, 4>& v, const std::array<Vec2, 4>& uv);

  std::string_view typeName() const override { return "quad"; }
  Bounds bounds() const override;
  bool intersect(const Ray& ray, float tMin, float tMax, LocalHit& hit) const override;
  uint32_t candidateLanes(const RayLanes& rays) const override;
  void intersectLanes(const RayLanes& rays, LaneHits& out) const override;
  // Onto the plane of the half (v0, v1, v2) or (v0, v2, v3) that p lies over: a quad's four
  // vertices need only be coplanar to 1e-4 of its size.
  SurfacePoint projectToSurface(const Vec3& p, const LocalHit& hit) const override;
  float area() const override { return area0_ + area1_; }
  float uvDensity() const override;
  // Only when both halves lie in the same plane: a quad folded within the loader's tolerance could
  // be met again by a grazing ray leaving its other half.
  bool flat() const override { return samePlanes_; }
  ShapeSample sampleArea(Vec2 u) const override;
  bool sampleSolidAngle(const Vec3& ref, Vec2 u, ShapeSample& s, float& pdf) const override;
  float pdfSolidAngle(const Vec3& ref, const Vec3& p, const Vec3& n) const override;
  void sampleSolidAngleLanes(SolidAngleLanes& lanes) const override { sampleQuadLanes(sampling_, lanes); }
  bool isRectangle() const { return rectangle_; }

 private:
  // The lane kernel of one half's filter.
  void halfLanes(int half, const RayLanes& rays, TriangleLanes& out) const;
  // The exact test of one half, (v0, v1, v2) or (v0, v2, v3).
  bool intersectHalf(int half, const Ray& ray, float tMin, float tMax, LocalHit& hit) const;
  // A hit the lane kernel settled as certainly inside `half` (the parallelogram, for a single
  // filter): t where the ray crosses the half's plane, if within the interval, and the UV of the
  // crossing point's barycentrics (with needsUv; else (0, 0)).
  bool settledHit(int half, const Ray& ray, float tMin, float tMax, bool needsUv, LocalHit& hit) const;
  // The UV of the point with coordinates b in the single filter's parallelogram (v0, v1, v3).
  Vec2 parallelogramUv(Vec2 b) const;
  // The UV of an axis-aligned rectangle's crossing at coordinates (a, b).
  Vec2 rectangleUv(float a, float b) const;

  bool rectangle_;
  std::array<Vec3, 4> v_;
  std::array<Vec2, 4> uv_;
  Vec3 normal_;
  DoublePlane planes_[2];       // of the halves (v0,v1,v2) and (v0,v2,v3)
  bool samePlanes_ = false;     // the two are equal bit for bit: projecting needs no side test
  TriangleFilter filters_[2];   // of the same halves, or twice the one of the whole parallelogram
  PlaneCoordinates coords_[2];  // likewise
  bool singleFilter_ = false;
  // An axis-aligned rectangle has its own test (accel/quadric_lanes.h), one float kernel per block.
  bool axisAligned_ = false;
  AxisRectangle axisRectangle_;
  float area0_, area1_;    // of (v0,v1,v2) and (v0,v2,v3)
  QuadSampling sampling_;  // what the light-sampling kernel needs
};

}  // namespace ember
