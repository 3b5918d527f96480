// Uniform sampling of the solid angle a triangle subtends: Arvo 1995, "Stratified Sampling of
// Spherical Triangles" (SIGGRAPH), section 2. Every direction inside the triangle's solid angle is
// equally likely (pdf = 1 / solid angle), which removes the d^2 / cos variation that area sampling
// leaves in next-event estimation right next to a triangle light. Computed in double: a triangle
// close enough to be worth it is cheap to sample either way, and the inversion is ill-conditioned
// in float near the triangle's edges.
#pragma once

#include "core/math.h"

#include <optional>

namespace ember {

class SphericalTriangle {
 public:
  // The triangle (v0, v1, v2) seen from o.
  SphericalTriangle(const Vec3& v0, const Vec3& v1, const Vec3& v2, const Vec3& o);

  // Van Oosterom and Strackee 1983: tan(omega / 2) = |a . (b x c)| / (1 + a.b + b.c + c.a).
  double solidAngle() const { return solidAngle_; }
  // The unit direction from o given by u, uniform in the solid angle; needs solidAngle() > 0.
  Vec3 sample(Vec2 u) const;

 private:
  glm::dvec3 a_, b_, c_;  // unit directions from o to the vertices
  double alpha_ = 0.0;    // interior angle at a
  double area_ = 0.0;     // alpha + beta + gamma - pi (Girard), the area the inversion uses
  double solidAngle_ = 0.0;
};

// The barycentrics (b1, b2) of v1 and v2 where the ray o + t w meets the triangle's plane,
// clamped into the triangle.
Vec2 barycentricsAlong(const Vec3& v0, const Vec3& v1, const Vec3& v2, const Vec3& o, const Vec3& w);

// The spherical triangle light sampling from ref should use, if any: only close to the triangle
// (nearer than about twice its size), where area sampling's variance is large, and where the solid
// angle exceeds 1e-4 sr so that the inversion stays precise (a far triangle gains little and would
// cost the inverse trigonometry; docs/performance.md).
std::optional<SphericalTriangle> sphericalTriangleForSampling(const Vec3& ref, const Vec3& v0, const Vec3& v1,
                                                              const Vec3& v2, float area);

}  // namespace ember
