#include "accel/cone.h"

#include <algorithm>

namespace ember {

Cone::Cone(const Vec3& baseCenter, const Vec3& apex, float radius, bool capBase)
    : base_(baseCenter),
      apex_(apex),
      axis_(glm::normalize(apex - baseCenter)),
      height_(glm::length(apex - baseCenter)),
      radius_(radius),
      capBase_(capBase),
      cap_(baseCenter, -glm::normalize(apex - baseCenter), radius) {
  lateral_.base = glm::dvec3(base_);
  lateral_.s = glm::dvec3(axis_.s);
  lateral_.t = glm::dvec3(axis_.t);
  lateral_.n = glm::dvec3(axis_.n);
  lateral_.height = double(height_);
  lateral_.cone = true;
  const double k = double(radius_) / double(height_);
  lateral_.k2 = k * k;
}

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

LocalHit Cone::lateralHit(const LateralRoot& root) const {
  // The direction (cos phi, sin phi) around the axis; at the apex, where it has none, phi = 0.
  const double len = std::sqrt(root.x * root.x + root.y * root.y);
  const float cosPhi = len > 0.0 ? float(root.x / len) : 1.0f;
  const float sinPhi = len > 0.0 ? float(root.y / len) : 0.0f;
  LocalHit hit;
  hit.t = float(root.t);
  hit.ng = lateralNormal(cosPhi, sinPhi);
  hit.uv = Vec2(0.0f, float(root.z / double(height_)));
  return hit;
}

bool Cone::intersect(const Ray& ray, float tMin, float tMax, LocalHit& hit) const {
  bool found = false;
  LateralRoot root;
  if (lateral_.nearestRoot(ray, tMin, tMax, root)) {
    hit = lateralHit(root);
    tMax = hit.t;
    found = true;
  }
  if (capBase_ && cap_.intersect(ray, tMin, tMax, hit)) found = true;
  return found;
}

// intersect() for the whole block: the side, then the base within what is left of the interval.
void Cone::intersectLanes(const RayLanes& rays, LaneHits& out) const {
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
  if (!capBase_) return;
  DiscLanes crossings;
  const uint32_t capped = discCrossings(rays, cap_.exact, tMax, live, crossings);
  for (uint32_t bits = capped; bits != 0; bits &= bits - 1) {
    const unsigned i = unsigned(__builtin_ctz(bits));
    out.set(i, cap_.hitAt({crossings.t[i], crossings.x[i], crossings.y[i]}));
  }
  out.mask |= capped;
}

Vec2 Cone::surfaceUv(const LocalHit& hit) const {
  if (glm::dot(hit.ng, axis_.n) < -0.99f) return hit.uv;  // the base's planar mapping
  // The normal's component across the axis points along (cos phi, sin phi).
  float phi = std::atan2(glm::dot(hit.ng, axis_.t), glm::dot(hit.ng, axis_.s));
  if (phi < 0.0f) phi += 2.0f * kPi;
  return {phi / (2.0f * kPi), hit.uv.y};
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
