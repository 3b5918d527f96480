#include "accel/sphere.h"

#include "accel/solve.h"
#include "core/sampling.h"

#include <algorithm>
#include <iterator>

namespace ember {

Bounds Sphere::bounds() const {
  Bounds b;
  b.extend(center_ - Vec3(radius_));
  b.extend(center_ + Vec3(radius_));
  return b;
}

Vec2 Sphere::surfaceUv(const LocalHit& hit) const {
  const Vec3& n = hit.ng;
  const float u = 0.5f + std::atan2(n.x, n.z) / (2.0f * kPi);
  const float v = std::acos(std::clamp(n.y, -1.0f, 1.0f)) * kInvPi;
  return {u, v};
}

bool Sphere::intersect(const Ray& ray, float tMin, float tMax, LocalHit& hit) const {
  // Solved in double with the numerically stable quadratic (accel/solve.h).
  const glm::dvec3 oc = glm::dvec3(ray.origin) - glm::dvec3(center_);
  const glm::dvec3 d(ray.dir);
  const double a = glm::dot(d, d);
  const double b = 2.0 * glm::dot(oc, d);
  const double c = glm::dot(oc, oc) - double(radius_) * double(radius_);
  double t0, t1;
  if (!solveQuadratic(a, b, c, t0, t1)) return false;
  double t = t0;
  if (t <= tMin || t >= tMax) {
    t = t1;
    if (t <= tMin || t >= tMax) return false;
  }
  // The unit normal as the point's offset from the centre over the radius, without a square root
  // and a division: the point lies on the sphere to double precision, so its length rounds to 1
  // in float as a normalisation's does. (At tangency t's error, ~sqrt(eps) of |oc|, leaves the
  // length off by ~2e-16 (|oc| / r)^2: beyond float precision only for rays from more than ~1e4
  // radii away, and then harmless to shading.)
  const glm::dvec3 local = oc + t * d;
  hit.t = float(t);
  hit.ng = Vec3(local * (1.0 / double(radius_)));
  hit.uv = Vec2(0.0f);  // surfaceUv derives it from the normal
  return true;
}

void Sphere::intersectLanes(const RayLanes& rays, LaneHits& out) const {
  out.mask = sphereHits(rays, center_, radius_, candidateLanes(rays), out);
  if (out.mask == 0) return;  // the callback reads nothing of a block without hits
  for (auto& row : out.uv) std::fill(std::begin(row), std::end(row), 0.0f);  // surfaceUv derives it
}

SurfacePoint Sphere::projectToSurface(const Vec3& p, const LocalHit&) const {
  const glm::dvec3 c(center_), rel = glm::dvec3(p) - c;
  const double len = glm::length(rel);
  return roundedPoint(len > 0.0 ? c + double(radius_) / len * rel : glm::dvec3(p));
}

ShapeSample Sphere::sampleArea(Vec2 u) const {
  const Vec3 n = sampleUniformSphere(u);
  return {center_ + radius_ * n, n};
}

bool Sphere::sampleSolidAngle(const Vec3& ref, Vec2 u, ShapeSample& s, float& pdf) const {
  const Vec3 toCenter = center_ - ref;
  const float dist2 = glm::dot(toCenter, toCenter);
  const float r2 = radius_ * radius_;
  if (dist2 <= r2 * 1.0001f) return Shape::sampleSolidAngle(ref, u, s, pdf);

  // Uniform direction in the subtended cone, then the point it hits (PBRT4 section 6.2.4): the
  // hit is found by the law of cosines rather than by ray casting, so it never misses at grazing.
  const float dist = std::sqrt(dist2);
  const float sin2Max = r2 / dist2;
  const float cosMax = std::sqrt(std::max(0.0f, 1.0f - sin2Max));
  float oneMinusCosMax = 1.0f - cosMax;
  float cosTheta = 1.0f - u.x * oneMinusCosMax;
  float sin2Theta = 1.0f - cosTheta * cosTheta;
  if (sin2Max < 0.00068523f) {  // below ~1.5 degrees: Taylor expansion keeps precision
    sin2Theta = sin2Max * u.x;
    cosTheta = std::sqrt(1.0f - sin2Theta);
    oneMinusCosMax = sin2Max / 2.0f;
  }
  // Angle alpha at the centre between -toCenter and the sampled point.
  const float sinMax = std::sqrt(sin2Max);
  const float cosAlpha =
      sin2Theta / sinMax + cosTheta * std::sqrt(std::max(0.0f, 1.0f - sin2Theta / sin2Max));
  const float sinAlpha = std::sqrt(std::max(0.0f, 1.0f - cosAlpha * cosAlpha));
  const float phi = 2.0f * kPi * u.y;
  const Frame frame(toCenter / dist);
  const Vec3 n = frame.toWorld(Vec3(sinAlpha * std::cos(phi), sinAlpha * std::sin(phi), -cosAlpha));
  s.n = glm::normalize(n);
  s.p = center_ + radius_ * s.n;
  pdf = 1.0f / (2.0f * kPi * oneMinusCosMax);
  return true;
}

float Sphere::pdfSolidAngle(const Vec3& ref, const Vec3& p, const Vec3& n) const {
  const Vec3 toCenter = center_ - ref;
  const float dist2 = glm::dot(toCenter, toCenter);
  const float r2 = radius_ * radius_;
  if (dist2 <= r2 * 1.0001f) return Shape::pdfSolidAngle(ref, p, n);
  const float sin2Max = r2 / dist2;
  const float oneMinusCosMax =
      sin2Max < 0.00068523f ? sin2Max / 2.0f : 1.0f - std::sqrt(std::max(0.0f, 1.0f - sin2Max));
  return 1.0f / (2.0f * kPi * oneMinusCosMax);
}

}  // namespace ember
