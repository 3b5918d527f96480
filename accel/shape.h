// The interface every analytic shape implements. Shapes are exact (no tessellation): Embree calls
// them through user-geometry callbacks (accel/user_geometry.cpp), and lights sample them
// (AreaLight in renderer/light.cpp). A closed shape's normal points outwards; an open shape's normal is its
// "front" side, the side an emitting shape emits on.
#pragma once

#include "accel/sampling_lanes.h"
#include "accel/shape_lanes.h"
#include "core/math.h"
#include "core/ray_spawn.h"

#include <string_view>

namespace ember {

struct Bounds {
  Vec3 lower{kInfinity};
  Vec3 upper{-kInfinity};

  void extend(const Vec3& p) {
    lower = glm::min(lower, p);
    upper = glm::max(upper, p);
  }
  void extend(const Bounds& b) {
    lower = glm::min(lower, b.lower);
    upper = glm::max(upper, b.upper);
  }
  bool empty() const { return lower.x > upper.x; }
};

// A hit point rebuilt on the surface, with the bound of its rounding error (core/ray_spawn.h).
struct SurfacePoint {
  Vec3 p;
  float error;
};

// A point on a shape's surface, chosen by a light-sampling routine.
struct ShapeSample {
  Vec3 p;
  Vec3 n;  // unit geometric normal at p (outward / front side)
};

class Shape {
 public:
  virtual ~Shape() = default;

  virtual std::string_view typeName() const = 0;
  virtual Bounds bounds() const = 0;

  // Closest hit with t in (tMin, tMax); false when there is none.
  virtual bool intersect(const Ray& ray, float tMin, float tMax, LocalHit& hit) const = 0;

  // The live lanes of an Embree packet that may hit the shape (bit i for lane i), for the default
  // intersectLanes (and for the filter tests, on every shape). Shapes with a SIMD filter
  // (accel/shape_lanes.h) clear the bits of lanes that certainly miss; the default keeps every live lane.
  virtual uint32_t candidateLanes(const RayLanes& rays) const;

  // The closest hit of each live lane with t in (tnear, tfar), for Embree's callbacks: what a
  // ray hits is always decided here, for single rays and packets alike. The default runs
  // intersect() on the candidate lanes; flat shapes settle the rays that certainly hit inside
  // their edges in their lane kernel and run intersect() on the rest.
  virtual void intersectLanes(const RayLanes& rays, LaneHits& out) const;

  // The texture coordinates of a hit that intersect() or intersectLanes() reported. Shapes whose UV needs
  // more than the closest hit's parameters (the sphere's inverse trigonometry) compute it here, once for the
  // hit that counts rather than for every candidate Embree tests.
  virtual Vec2 surfaceUv(const LocalHit& hit) const { return hit.uv; }

  // Moves a hit point p = o + t d, which float rounding of t leaves up to ~ulp(t) off the surface,
  // onto the surface as intersect() sees it (computed in double from the same float parameters),
  // so that its error is the rounding of its own coordinates, however far the ray travelled
  // (PBRT4 section 6.8.5 re-projects sphere hits the same way): rays then leave a surface seen from
  // afar as closely as one seen from nearby. `hit` is what intersectLanes() reported at p.
  // Closed shapes with edges (capped cylinders and cones, boxes) also keep the point a few error
  // bounds away from each edge, on the side of the face that was hit: within rounding of an edge a
  // point is ambiguous, and a ray offset into the shape from the far side of the edge would start
  // outside it (a leak through the rim).
  virtual SurfacePoint projectToSurface(const Vec3& p, const LocalHit& hit) const = 0;

  virtual float area() const = 0;
  // Texture coordinates per unit of length, on average over the surface (a filtered texture's
  // footprint scale, Scene::surfaceHit): the UV square spread over the area, unless the shape
  // carries its own texture coordinates.
  virtual float uvDensity() const {
    const float a = area();
    return a > 0.0f && std::isfinite(a) ? 1.0f / std::sqrt(a) : 0.0f;
  }

  // Whether the whole shape lies in one plane. A ray leaving such a shape (its origin pushed off
  // the plane to the side it travels to, core/ray_spawn.h) never meets it again, and neither does a
  // shadow ray aimed at one of its points (stopped short of the plane): Scene gives flat shapes an
  // Embree mask bit of their own, which those rays leave out (SurfaceHit::maskFor,
  // Light::shadowMask), so Embree skips their test.
  virtual bool flat() const { return false; }
  // +1 when the shape lies on the boundary of a convex solid and its normals point out of it
  // (sphere, box, cylinder and cone, capped or not): a ray leaving it to the side of its normal
  // starts in front of a plane that has the whole solid behind it, and never meets the shape
  // again. -1 when its normals point into such a solid (a FlippedShape of one); 0 otherwise.
  // Scene masks these out of the rays that leave them that way, as it does flat shapes.
  virtual int convexSide() const { return 0; }

  // A point distributed uniformly by area over the whole surface (density 1 / area()).
  virtual ShapeSample sampleArea(Vec2 u) const = 0;

  // A point seen from `ref`, with its density per unit solid angle at `ref`. The default converts
  // area sampling (PBRT4 eq. 4.9: p_w = p_A d^2 / |cos theta_light|); shapes with a better
  // strategy (the sphere's cone of directions) override both functions together.
  virtual bool sampleSolidAngle(const Vec3& ref, Vec2 u, ShapeSample& s, float& pdf) const;
  virtual float pdfSolidAngle(const Vec3& ref, const Vec3& p, const Vec3& n) const;
  // sampleSolidAngle for the live lanes of `lanes` at once (accel/sampling_lanes.h), a pdf of 0
  // where it returns false. Shapes with a lane kernel override it; the default goes lane by lane.
  virtual void sampleSolidAngleLanes(SolidAngleLanes& lanes) const;

 protected:
  // intersect() on each lane of `lanes`, adding the lanes it hits to out.mask.
  void intersectEach(uint32_t lanes, const RayLanes& rays, LaneHits& out) const;
};

// A plane dot(n, x) = d in double precision (n of unit length), precomputed so that projecting a
// hit point onto it costs a dot product: the plane through a disc's centre with its normal (which
// defines it), or through a triangle's float vertices (which double-precision Moller-Trumbore
// sees exactly).
struct DoublePlane {
  glm::dvec3 n{0.0, 0.0, 1.0};
  double d = 0.0;  // four doubles, no padding: two planes compare bit for bit with memcmp

  static DoublePlane through(const Vec3& anchor, const Vec3& normal);
  static DoublePlane through(const Vec3& a, const Vec3& b, const Vec3& c);
  SurfacePoint project(const Vec3& p) const;
  // Whether the ray meets the plane at a t in (tMin, tMax): a cheap first test for flat shapes,
  // which rejects the many shadow rays that end just short of an emitter on this plane.
  bool crossedWithin(const Ray& ray, float tMin, float tMax) const {
    const glm::dvec3 dir(ray.dir);
    const double denom = glm::dot(n, dir);
    if (denom == 0.0) return false;
    const double t = (d - glm::dot(n, glm::dvec3(ray.origin))) / denom;
    return t > double(tMin) && t < double(tMax);
  }
  // The same, also writing the crossing's t (whether or not it is within the interval), measured
  // from `anchor`, a point of the plane near the shape (a vertex): t = n.(anchor - o) / n.dir then
  // cancels relative to the distance from the shape, not from the origin (as Moller-Trumbore does),
  // which keeps a short t accurate far from the origin. anchor - o is exact in double.
  bool crossedWithin(const Ray& ray, float tMin, float tMax, const glm::dvec3& anchor, double& t) const {
    const double denom = glm::dot(n, glm::dvec3(ray.dir));
    if (denom == 0.0) return false;
    t = glm::dot(n, anchor - glm::dvec3(ray.origin)) / denom;
    return t > double(tMin) && t < double(tMax);
  }
};

// Coordinates in a triangle's plane, in double: a point p of the plane is v0 + b1 (v1 - v0) +
// b2 (v2 - v0) with b_k = dot(p - v0, g_k), where g1, g2 are the dual vectors of the edges.
// Moller-Trumbore's u and v are these b1 and b2 of the crossing point.
struct PlaneCoordinates {
  glm::dvec3 v0{0.0}, g1{0.0}, g2{0.0};
  bool hasArea = false;  // false for a degenerate triangle, whose g1, g2 stay zero

  static PlaneCoordinates of(const Vec3& v0, const Vec3& v1, const Vec3& v2);
  Vec2 at(const glm::dvec3& p) const {
    const glm::dvec3 rel = p - v0;
    return Vec2(float(glm::dot(rel, g1)), float(glm::dot(rel, g2)));
  }
};

// The error bound of a point rounded to float from its double-precision value on a surface:
// roundingErrorBound of its coordinates, plus that of `size` for shapes whose surface is known
// only to ~1e-7 of their size (float frames and rotations that are not exactly orthonormal).
// Assembled field by field from scalars: returned as {f, bound}, GCC built the struct on the stack
// with narrow stores and read it back with a wide load, which waits for those stores to reach the
// cache (no store-to-load forwarding): a third of the sphere's and the rectangle's projections'
// time on an AVX-512 Xeon (`perf annotate`).
inline SurfacePoint roundedPoint(float x, float y, float z, float size = 0.0f) {
  SurfacePoint out;
  out.p.x = x;
  out.p.y = y;
  out.p.z = z;
  out.error = roundingErrorBound(maxAbsComponent(out.p) + size);
  return out;
}
inline SurfacePoint roundedPoint(const glm::dvec3& p, float size = 0.0f) {
  return roundedPoint(float(p.x), float(p.y), float(p.z), size);
}

// How far a projected point is kept from an edge of its face: after the offset along the normal
// (one error bound) and rounding (another), it is still on the face's side of the edge.
inline float edgeMargin(const SurfacePoint& p) {
  return 4.0f * p.error;
}

// Converts a density per unit area at p (normal n) into one per unit solid angle seen from ref.
float areaToSolidAnglePdf(float pdfArea, const Vec3& ref, const Vec3& p, const Vec3& n);

}  // namespace ember
