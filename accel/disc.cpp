#include "accel/disc.h"

#include "core/sampling.h"

namespace ember {

bool DiscGeometry::intersect(const Ray& ray, float tMin, float tMax, LocalHit& hit) const {
  const glm::dvec3 n(frame.n);
  const double denom = glm::dot(glm::dvec3(ray.dir), n);
  if (denom == 0.0) return false;  // parallel: a zero-thickness disc is never hit edge-on
  const glm::dvec3 oc = glm::dvec3(center) - glm::dvec3(ray.origin);
  const double t = glm::dot(oc, n) / denom;
  if (t <= tMin || t >= tMax) return false;
  const glm::dvec3 rel = glm::dvec3(ray.origin) + t * glm::dvec3(ray.dir) - glm::dvec3(center);
  const double x = glm::dot(rel, glm::dvec3(frame.s));
  const double y = glm::dot(rel, glm::dvec3(frame.t));
  const double r = radius;
  if (x * x + y * y > r * r) return false;
  hit.t = float(t);
  hit.ng = frame.n;
  hit.uv = Vec2(float(0.5 + 0.5 * x / r), float(0.5 - 0.5 * y / r));
  return true;
}

SurfacePoint DiscGeometry::projectToSurface(const Vec3& p, float rimMargin) const {
  const SurfacePoint onPlane = plane.project(p);
  if (rimMargin <= 0.0f) return onPlane;
  const glm::dvec3 rel = glm::dvec3(onPlane.p) - glm::dvec3(center);
  const glm::dvec3 n(frame.n);
  const glm::dvec3 radial = rel - glm::dot(rel, n) * n;
  const double len = glm::length(radial), inner = double(radius) - double(rimMargin);
  if (!(len > inner) || inner <= 0.0) return onPlane;
  return {Vec3(glm::dvec3(onPlane.p) - (len - inner) / len * radial), onPlane.error};
}

ShapeSample DiscGeometry::sampleArea(Vec2 u) const {
  const Vec2 d = radius * sampleUniformDiskConcentric(u);
  return {center + frame.s * d.x + frame.t * d.y, frame.n};
}

void DiscGeometry::extendBounds(Bounds& b) const {
  // Exact box of a disc: extent along each axis is r * sqrt(1 - n_i^2).
  const Vec3 e = radius * glm::sqrt(glm::max(Vec3(0.0f), Vec3(1.0f) - frame.n * frame.n));
  b.extend(center - e);
  b.extend(center + e);
}

Bounds Disc::bounds() const {
  Bounds b;
  disc_.extendBounds(b);
  return b;
}

}  // namespace ember
