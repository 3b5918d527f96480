#include "accel/cylinder.h"

#include "accel/solve.h"

namespace ember {

Cylinder::Cylinder(const Vec3& p0, const Vec3& p1, float radius, bool caps)
    : p0_(p0),
      axis_(glm::normalize(p1 - p0)),
      height_(glm::length(p1 - p0)),
      radius_(radius),
      caps_(caps),
      cap0_(p0, -glm::normalize(p1 - p0), radius),
      cap1_(p1, glm::normalize(p1 - p0), radius) {}

Bounds Cylinder::bounds() const {
  Bounds b;
  cap0_.extendBounds(b);
  cap1_.extendBounds(b);
  return b;
}

bool Cylinder::intersect(const Ray& ray, float tMin, float tMax, LocalHit& hit) const {
  bool found = false;
  // Lateral surface x^2 + y^2 = r^2, 0 <= z <= h, in the axis frame, solved in double.
  const glm::dvec3 rel = glm::dvec3(ray.origin) - glm::dvec3(p0_);
  const glm::dvec3 s(axis_.s), t(axis_.t), n(axis_.n), d(ray.dir);
  const double ox = glm::dot(rel, s), oy = glm::dot(rel, t), oz = glm::dot(rel, n);
  const double dx = glm::dot(d, s), dy = glm::dot(d, t), dz = glm::dot(d, n);
  const double a = dx * dx + dy * dy;
  const double b = 2.0 * (ox * dx + oy * dy);
  const double c = ox * ox + oy * oy - double(radius_) * radius_;
  double roots[2];
  if (a > 0.0 && solveQuadratic(a, b, c, roots[0], roots[1])) {
    for (double root : roots) {
      if (root <= tMin || root >= tMax) continue;
      const double z = oz + root * dz;
      if (z < 0.0 || z > height_) continue;
      const double x = ox + root * dx, y = oy + root * dy;
      double phi = std::atan2(y, x);
      if (phi < 0.0) phi += 2.0 * std::numbers::pi;
      hit.t = float(root);
      hit.ng = glm::normalize(axis_.s * float(x) + axis_.t * float(y));
      hit.uv = Vec2(float(phi / (2.0 * std::numbers::pi)), float(z / height_));
      tMax = hit.t;
      found = true;
      break;
    }
  }
  if (caps_) {
    if (cap0_.intersect(ray, tMin, tMax, hit)) {
      tMax = hit.t;
      found = true;
    }
    if (cap1_.intersect(ray, tMin, tMax, hit)) found = true;
  }
  return found;
}

SurfacePoint Cylinder::projectToSurface(const Vec3& p, const LocalHit& hit) const {
  // Caps face along the axis, the lateral surface across it.
  const float along = glm::dot(hit.ng, axis_.n);
  const float margin = caps_ ? edgeMargin(roundedPoint(glm::dvec3(p), radius_ + height_)) : 0.0f;
  if (along < -0.5f) return cap0_.projectToSurface(p, margin);
  if (along > 0.5f) return cap1_.projectToSurface(p, margin);
  // In the axis frame intersect() uses: x^2 + y^2 = r^2, 0 <= z <= h (kept off the caps' rims).
  const glm::dvec3 s(axis_.s), t(axis_.t), n(axis_.n), rel = glm::dvec3(p) - glm::dvec3(p0_);
  const double x = glm::dot(rel, s), y = glm::dot(rel, t), len = std::sqrt(x * x + y * y);
  if (!(len > 0.0)) return {p, roundingErrorBound(maxAbsComponent(p) + radius_ + height_)};
  const double scale = double(radius_) / len;
  double z = glm::dot(rel, n);
  if (height_ > 2.0f * margin) z = std::clamp(z, double(margin), double(height_ - margin));
  return roundedPoint(glm::dvec3(p0_) + scale * x * s + scale * y * t + z * n, radius_ + height_);
}

float Cylinder::area() const {
  const float side = 2.0f * kPi * radius_ * height_;
  return caps_ ? side + cap0_.area() + cap1_.area() : side;
}

ShapeSample Cylinder::sampleArea(Vec2 u) const {
  const float side = 2.0f * kPi * radius_ * height_;
  const float total = area();
  float pick = u.x * total;
  if (pick < side || !caps_) {
    const float z = std::min(pick / side, 1.0f) * height_;
    const float phi = 2.0f * kPi * u.y;
    const Vec3 n = axis_.s * std::cos(phi) + axis_.t * std::sin(phi);
    return {p0_ + axis_.n * z + radius_ * n, n};
  }
  // Reuse the remainder of u.x as a fresh uniform number for the chosen cap.
  pick -= side;
  const float capArea = cap0_.area();
  const DiscGeometry& cap = pick < capArea ? cap0_ : cap1_;
  const float ux = std::min((pick < capArea ? pick : pick - capArea) / capArea, 0.99999994f);
  return cap.sampleArea(Vec2(ux, u.y));
}

}  // namespace ember
