// The intersection routines of the disc, the cylinder's and cone's lateral surfaces, the box and the
// axis-aligned rectangle, each in two forms computed by the same operations in the same order: a scalar
// one for a single ray (Shape::intersect) and a Highway kernel for a block of packet lanes at once
// (Shape::intersectLanes, the route of every ray Embree traces). The quadrics and the box are exact
// tests in double precision; the rectangle, the commonest flat shape, is a float test with a
// conservative margin (AxisRectangle). IEEE arithmetic rounds the same in a vector lane as in a scalar
// register, and this file's implementation is compiled without fused multiply-adds, so each lane's
// result equals the scalar routine's bit for bit (tests/test_shape_lanes.cpp). The shapes build their
// LocalHit from these results with one shared scalar function, so the hits the two routes report are
// identical too. Unlike the sphere's and the other flat shapes' kernels, no float filter runs first: a
// ray reaching one of these shapes' bounding boxes usually hits it.
#pragma once

#include "accel/shape_lanes.h"
#include "core/math.h"

#include <algorithm>
#include <cstdint>

namespace ember {

// A disc's plane crossing within (tMin, tMax) and inside its radius (DiscGeometry::intersect): t
// and the crossing's coordinates in the disc's frame.
struct DiscCrossing {
  double t, x, y;
};
struct ExactDisc {
  glm::dvec3 center{0.0}, n{0.0, 0.0, 1.0}, s{1.0, 0.0, 0.0}, t{0.0, 1.0, 0.0};
  double radius = 0.0;

  bool cross(const Ray& ray, float tMin, float tMax, DiscCrossing& out) const;
};
struct DiscLanes {
  alignas(64) double t[RayLanes::kMaxLanes];
  alignas(64) double x[RayLanes::kMaxLanes];
  alignas(64) double y[RayLanes::kMaxLanes];
};
// ExactDisc::cross for the lanes in `lanes`, lane i's interval being (rays.tnear[i], tMax[i]):
// a cap must be nearer than the lateral hit found before it. tMax has kMaxLanes entries. Bit i
// of the result is set where lane i crosses, with its crossing in lane i of `out`.
uint32_t discCrossings(const RayLanes& rays, const ExactDisc& disc, const float* tMax, uint32_t lanes,
                       DiscLanes& out);

// The lateral surface of a cylinder, x^2 + y^2 = r^2, or of a cone, x^2 + y^2 = k^2 (h - z)^2,
// for 0 <= z <= h in the frame (s, t, n) at the base's centre; its nearer root within (tMin,
// tMax), solved in double with the numerically stable quadratic (accel/solve.h).
struct LateralRoot {
  double t, x, y, z;
};
struct LateralQuadric {
  glm::dvec3 base{0.0}, s{1.0, 0.0, 0.0}, t{0.0, 1.0, 0.0}, n{0.0, 0.0, 1.0};
  double height = 0.0;
  bool cone = false;
  double r2 = 0.0;  // the cylinder's radius^2
  double k2 = 0.0;  // the cone's (radius / height)^2

  bool nearestRoot(const Ray& ray, float tMin, float tMax, LateralRoot& out) const;
};
struct LateralLanes {
  alignas(64) double t[RayLanes::kMaxLanes];
  alignas(64) double x[RayLanes::kMaxLanes];
  alignas(64) double y[RayLanes::kMaxLanes];
  alignas(64) double z[RayLanes::kMaxLanes];
};
uint32_t lateralRoots(const RayLanes& rays, const LateralQuadric& quadric, uint32_t lanes, LateralLanes& out);

// The box's slab test in its own frame (Kay & Kajiya 1986): the entry within (tMin, tMax), else
// the exit (a ray starting inside), with the point in box coordinates and the axis of its face.
struct BoxCrossing {
  double t;
  glm::dvec3 local;
  int axis;
};
struct ExactBox {
  glm::dvec3 center{0.0};
  glm::dvec3 axes[3]{{1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0}};  // the rotation's columns
  glm::dvec3 half{0.0};

  bool cross(const Ray& ray, float tMin, float tMax, BoxCrossing& out) const;
};
struct BoxLanes {
  alignas(64) double t[RayLanes::kMaxLanes];
  alignas(64) double local[3][RayLanes::kMaxLanes];
  alignas(64) double axis[RayLanes::kMaxLanes];  // 0, 1 or 2 where the lane crosses
};
uint32_t boxCrossings(const RayLanes& rays, const ExactBox& box, uint32_t lanes, BoxLanes& out);

// An axis-aligned rectangle, the commonest flat shape (walls, floors, area lights): the plane
// x[axis] = c crossed within (tMin, tMax) at a point whose other two coordinates (along across[0]
// and across[1]) lie in [lo, hi], bounds included. In float, 16 lanes per AVX-512 vector: the
// plane's denominator is the direction's own component, so t = (c - o[axis]) / dir[axis] is two
// roundings from the exact quotient (one where c and o[axis] are within a factor of two, as for a
// ray leaving the plane, whose t is then exactly signed). The crossing's coordinates a = o + t dir
// carry at most 4 ulps of |o| + |t dir| of error (t's two roundings, the product's and the sum's),
// so the bounds are widened by kMargin times that much, lane by lane: a ray that crosses the
// exact rectangle is never missed, so two rectangles that share an edge leave no crack between
// them. The price: a ray that passes outside any edge (a light's rim too) by less than the margin,
// a few ulps of |o| + |t dir|, counts as a hit; its texture coordinates are those of the nearest
// point of the rectangle (edgeCoordinates clamps them). The bound is relative: it assumes no
// underflow (scenes at 1e-30 scale) and no overflow (|o| + |t dir| near 1e38, where every lane
// becomes a hit).
struct RectangleCrossing {
  float t, a, b;  // the coordinates along across[0] and across[1]
};
struct AxisRectangle {
  // 8 ulps (2^-24 each) of |o| + |t dir|: twice the error bound, as a safety factor (2^-21, so
  // multiplying by it is exact; the comparisons themselves need none, as lo and hi are floats).
  static constexpr float kMargin = 8.0f * 0x1p-24f;
  int axis = 2;
  int across[2] = {0, 1};
  float c = 0.0f;
  float lo[2] = {0.0f, 0.0f}, hi[2] = {0.0f, 0.0f};
  float corner[2] = {0.0f, 0.0f};  // v0 along across[0], across[1]
  float edge[2] = {1.0f, 1.0f};    // v1 - v0 along across[0] and v3 - v0 along across[1], signed

  // The rectangle of the quad with corners v0, v1, v2, v3, if it is one: the corners share one
  // coordinate bit for bit, the edges v1 - v0 and v3 - v0 each run along one of the other two axes
  // (non-zero and finite), and v2 = v1 + v3 - v0 exactly.
  static bool of(const Vec3& v0, const Vec3& v1, const Vec3& v2, const Vec3& v3, AxisRectangle& out);
  bool cross(const Ray& ray, float tMin, float tMax, RectangleCrossing& out) const;
  // The quad's texture coordinates' parameters at a crossing: the crossing along v1 - v0 and
  // v3 - v0 in units of the edges, clamped to [0, 1] (a hit in the margin outside an edge takes
  // the edge's coordinates, not those a repeating texture would wrap to the opposite edge).
  Vec2 edgeCoordinates(float a, float b) const {
    const auto unit = [](float x) { return std::min(std::max(x, 0.0f), 1.0f); };
    return {unit((a - corner[0]) / edge[0]), unit((b - corner[1]) / edge[1])};
  }
};

// The rectangle's test for the lanes of `rays` named by `lanes`: the mask of those that cross it.
uint32_t axisRectangleCrossings(const RayLanes& rays, const AxisRectangle& rect, uint32_t lanes);
// The test for the rays' live lanes (valid), writing each lane's t into t[0, rays.n): a quad's
// hits in one call. With `uvCorners` (the quad's UV at v0..v3) also each lane's texture
// coordinates into u and v, exactly as Quad::rectangleUv computes them from the crossing: its
// edgeCoordinates, then the UV of the half (v0, v1, v2) or (v0, v2, v3) they fall in.
uint32_t axisRectangleHits(const RayLanes& rays, const AxisRectangle& rect, float* t,
                           const Vec2* uvCorners = nullptr, float* u = nullptr, float* v = nullptr);

}  // namespace ember
