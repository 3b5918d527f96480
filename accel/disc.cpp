#include "accel/disc.h"

#include "core/sampling.h"

namespace ember {

DiscGeometry::DiscGeometry(const Vec3& c, const Vec3& normal, float r)
    : center(c), frame(normal), radius(r), plane(DoublePlane::through(c, normal)) {
  exact.center = glm::dvec3(c);
  exact.n = glm::dvec3(frame.n);
  exact.s = glm::dvec3(frame.s);
  exact.t = glm::dvec3(frame.t);
  exact.radius = double(r);
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

void Disc::intersectLanes(const RayLanes& rays, LaneHits& out) const {
  DiscLanes crossings;
  out.mask = discCrossings(rays, disc_.exact, rays.tfar, candidateLanes(rays), crossings);
  for (uint32_t bits = out.mask; bits != 0; bits &= bits - 1) {
    const unsigned i = unsigned(__builtin_ctz(bits));
    out.set(i, disc_.hitAt({crossings.t[i], crossings.x[i], crossings.y[i]}));
  }
}

Bounds Disc::bounds() const {
  Bounds b;
  disc_.extendBounds(b);
  return b;
}

}  // namespace ember
