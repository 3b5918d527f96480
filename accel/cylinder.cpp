#include "accel/cylinder.h"

#include <algorithm>

namespace ember {

Cylinder::Cylinder(const Vec3& p0, const Vec3& p1, float radius, bool caps)
    : p0_(p0),
      axis_(glm::normalize(p1 - p0)),
      height_(glm::length(p1 - p0)),
      radius_(radius),
      caps_(caps),
      cap0_(p0, -glm::normalize(p1 - p0), radius),
      cap1_(p1, glm::normalize(p1 - p0), radius) {
  lateral_.base = glm::dvec3(p0_);
  lateral_.s = glm::dvec3(axis_.s);
  lateral_.t = glm::dvec3(axis_.t);
  lateral_.n = glm::dvec3(axis_.n);
  lateral_.height = double(height_);
  lateral_.r2 = double(radius_) * double(radius_);
}

Bounds Cylinder::bounds() const {
  Bounds b;
  cap0_.extendBounds(b);
  cap1_.extendBounds(b);
  return b;
}

LocalHit Cylinder::lateralHit(const LateralRoot& root) const {
  LocalHit hit;
  hit.t = float(root.t);
  hit.ng = glm::normalize(axis_.s * float(root.x) + axis_.t * float(root.y));
  hit.uv = Vec2(0.0f, float(root.z / double(height_)));
  return hit;
}

bool Cylinder::intersect(const Ray& ray, float tMin, float tMax, LocalHit& hit) const {
  bool found = false;
  LateralRoot root;
  if (lateral_.nearestRoot(ray, tMin, tMax, root)) {
    hit = lateralHit(root);
    tMax = hit.t;
    found = true;
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

// intersect() for the whole block: the side, then each cap within what is left of the interval.
void Cylinder::intersectLanes(const RayLanes& rays, LaneHits& out) const {
  const uint32_t live = candidateLanes(rays);
  LateralLanes roots;
  out.mask = lateralRoots(rays, lateral_, live, roots);
  alignas(64) float tMax[RayLanes::kMaxLanes] = {};
  std::copy_n(rays.tfar, rays.n, tMax);
  for (uint32_t bits = out.mask; bits != 0; bits &= bits - 1) {
    const unsigned i = unsigned(__builtin_ctz(bits));
    out.set(i, lateralHit({roots.t[i], roots.x[i], roots.y[i], roots.z[i]}));
    tMax[i] = out.t[i];
  }
  if (!caps_) return;
  for (const DiscGeometry* cap : {&cap0_, &cap1_}) {
    DiscLanes crossings;
    const uint32_t capped = discCrossings(rays, cap->exact, tMax, live, crossings);
    for (uint32_t bits = capped; bits != 0; bits &= bits - 1) {
      const unsigned i = unsigned(__builtin_ctz(bits));
      out.set(i, cap->hitAt({crossings.t[i], crossings.x[i], crossings.y[i]}));
      tMax[i] = out.t[i];
    }
    out.mask |= capped;
  }
}

Vec2 Cylinder::surfaceUv(const LocalHit& hit) const {
  if (std::abs(glm::dot(hit.ng, axis_.n)) > 0.5f) return hit.uv;  // a cap's planar mapping
  float phi = std::atan2(glm::dot(hit.ng, axis_.t), glm::dot(hit.ng, axis_.s));
  if (phi < 0.0f) phi += 2.0f * kPi;
  return {phi / (2.0f * kPi), hit.uv.y};
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
