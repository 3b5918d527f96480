#include "accel/cone.h"

#include "accel/solve.h"

namespace ember {

Cone::Cone(const Vec3& baseCenter, const Vec3& apex, float radius, bool capBase)
    : base_(baseCenter),
      apex_(apex),
      axis_(glm::normalize(apex - baseCenter)),
      height_(glm::length(apex - baseCenter)),
      radius_(radius),
      capBase_(capBase),
      cap_(baseCenter, -glm::normalize(apex - baseCenter), radius) {}

Bounds Cone::bounds() const {
  Bounds b;
  cap_.extendBounds(b);
  b.extend(apex_);
  return b;
}

// Outward normal of x^2 + y^2 = k^2 (h - z)^2 with k = r / h: proportional to (cos phi, sin phi, k).
Vec3 Cone::lateralNormal(float cosPhi, float sinPhi) const {
  const float k = radius_ / height_;
  return glm::normalize(axis_.s * cosPhi + axis_.t * sinPhi + axis_.n * k);
}

bool Cone::intersect(const Ray& ray, float tMin, float tMax, LocalHit& hit) const {
  bool found = false;
  const glm::dvec3 rel = glm::dvec3(ray.origin) - glm::dvec3(base_);
  const glm::dvec3 s(axis_.s), t(axis_.t), n(axis_.n), d(ray.dir);
  const double ox = glm::dot(rel, s), oy = glm::dot(rel, t), oz = glm::dot(rel, n);
  const double dx = glm::dot(d, s), dy = glm::dot(d, t), dz = glm::dot(d, n);
  const double h = height_;
  const double k = double(radius_) / h;
  const double k2 = k * k;
  const double hz = h - oz;
  const double a = dx * dx + dy * dy - k2 * dz * dz;
  const double b = 2.0 * (ox * dx + oy * dy + k2 * hz * dz);
  const double c = ox * ox + oy * oy - k2 * hz * hz;
  double roots[2];
  if (solveQuadratic(a, b, c, roots[0], roots[1])) {
    for (double root : roots) {
      if (root <= tMin || root >= tMax) continue;
      const double z = oz + root * dz;
      if (z < 0.0 || z > h) continue;  // also rejects the mirror-image nappe above the apex
      const double x = ox + root * dx, y = oy + root * dy;
      double phi = std::atan2(y, x);
      if (phi < 0.0) phi += 2.0 * std::numbers::pi;
      hit.t = float(root);
      hit.ng = lateralNormal(float(std::cos(phi)), float(std::sin(phi)));
      hit.uv = Vec2(float(phi / (2.0 * std::numbers::pi)), float(z / h));
      tMax = hit.t;
      found = true;
      break;
    }
  }
  if (capBase_ && cap_.intersect(ray, tMin, tMax, hit)) found = true;
  return found;
}

SurfacePoint Cone::projectToSurface(const Vec3& p, const LocalHit& hit) const {
  const float margin = capBase_ ? edgeMargin(roundedPoint(glm::dvec3(p), radius_ + height_)) : 0.0f;
  if (glm::dot(hit.ng, axis_.n) < -0.99f) return cap_.projectToSurface(p, margin);  // the base faces -axis
  // A cone is ruled: its tangent plane at any lateral point contains the apex. The normal comes
  // from the float frame, so the surface is known to ~1e-7 of the cone's size.
  const SurfacePoint onPlane = DoublePlane::through(apex_, hit.ng).project(p);
  const float error = onPlane.error + roundingErrorBound(radius_ + height_);
  // Off the base's rim: slide along the generator through the point (which lies on the cone)
  // towards the apex until the point is `margin` above the base.
  const glm::dvec3 q(onPlane.p), n(axis_.n);
  const double z = glm::dot(q - glm::dvec3(base_), n);
  if (z >= double(margin) || height_ <= 2.0f * margin) return {onPlane.p, error};
  const glm::dvec3 toApex = glm::dvec3(apex_) - q;
  const double along = glm::dot(toApex, n);  // > 0 below the apex
  if (!(along > 0.0)) return {onPlane.p, error};
  return {Vec3(q + (double(margin) - z) / along * toApex), error};
}

float Cone::area() const {
  const float side = kPi * radius_ * std::sqrt(radius_ * radius_ + height_ * height_);
  return capBase_ ? side + cap_.area() : side;
}

ShapeSample Cone::sampleArea(Vec2 u) const {
  const float side = kPi * radius_ * std::sqrt(radius_ * radius_ + height_ * height_);
  float pick = u.x * area();
  if (pick < side || !capBase_) {
    // The lateral area element grows linearly with the distance from the apex, so the fraction
    // f of that distance has density 2 f: invert with f = sqrt(u).
    const float f = std::sqrt(std::min(pick / side, 1.0f));
    const float phi = 2.0f * kPi * u.y;
    const float c = std::cos(phi), s = std::sin(phi);
    const Vec3 p = apex_ + (base_ - apex_) * f + radius_ * f * (axis_.s * c + axis_.t * s);
    return {p, lateralNormal(c, s)};
  }
  pick -= side;
  return cap_.sampleArea(Vec2(std::min(pick / cap_.area(), 0.99999994f), u.y));
}

}  // namespace ember
