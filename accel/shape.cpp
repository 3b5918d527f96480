#include "accel/shape.h"

namespace ember {

uint32_t Shape::candidateLanes(const RayLanes& rays) const {
  return liveLanes(rays);
}

void Shape::intersectLanes(const RayLanes& rays, LaneHits& out) const {
  out.mask = 0;
  intersectEach(candidateLanes(rays), rays, out);
}

void Shape::intersectEach(uint32_t lanes, const RayLanes& rays, LaneHits& out) const {
  for (uint32_t bits = lanes; bits != 0; bits &= bits - 1) {
    const unsigned i = unsigned(__builtin_ctz(bits));
    LocalHit hit;
    if (!intersect(rays.ray(i), rays.tnear[i], rays.tfar[i], hit)) continue;
    out.set(i, hit);
    out.mask |= 1u << i;
  }
}

float areaToSolidAnglePdf(float pdfArea, const Vec3& ref, const Vec3& p, const Vec3& n) {
  const Vec3 d = p - ref;
  const float dist2 = glm::dot(d, d);
  if (dist2 == 0.0f) return 0.0f;
  const float cosLight = std::abs(glm::dot(n, d)) / std::sqrt(dist2);
  if (cosLight == 0.0f) return 0.0f;
  return pdfArea * dist2 / cosLight;
}

DoublePlane DoublePlane::through(const Vec3& anchor, const Vec3& normal) {
  DoublePlane plane;
  const glm::dvec3 n(normal);
  const double len = glm::length(n);
  if (!(len > 0.0)) return plane;
  plane.n = n / len;
  plane.d = glm::dot(plane.n, glm::dvec3(anchor));
  return plane;
}

DoublePlane DoublePlane::through(const Vec3& a, const Vec3& b, const Vec3& c) {
  const glm::dvec3 da(a);
  const glm::dvec3 n = glm::cross(glm::dvec3(b) - da, glm::dvec3(c) - da);
  const double len = glm::length(n);
  DoublePlane plane;
  if (!(len > 0.0)) return plane;
  plane.n = n / len;
  plane.d = glm::dot(plane.n, da);
  return plane;
}

PlaneCoordinates PlaneCoordinates::of(const Vec3& v0, const Vec3& v1, const Vec3& v2) {
  PlaneCoordinates c;
  c.v0 = glm::dvec3(v0);
  const glm::dvec3 e1 = glm::dvec3(v1) - c.v0, e2 = glm::dvec3(v2) - c.v0;
  const glm::dvec3 normal = glm::cross(e1, e2);
  const double len2 = glm::dot(normal, normal);
  if (!(len2 > 0.0)) return c;  // never used: no ray is settled on a triangle without area
  c.hasArea = true;
  c.g1 = glm::cross(e2, normal) / len2;
  c.g2 = glm::cross(normal, e1) / len2;
  return c;
}

SurfacePoint DoublePlane::project(const Vec3& p) const {
  const glm::dvec3 dp(p);
  return roundedPoint(dp - (glm::dot(n, dp) - d) * n);
}

bool Shape::sampleSolidAngle(const Vec3& ref, Vec2 u, ShapeSample& s, float& pdf) const {
  s = sampleArea(u);
  pdf = areaToSolidAnglePdf(1.0f / area(), ref, s.p, s.n);
  return pdf > 0.0f && std::isfinite(pdf);
}

void Shape::sampleSolidAngleLanes(SolidAngleLanes& lanes) const {
  for (unsigned i = 0; i < lanes.n; ++i) {
    ShapeSample s;
    float pdf = 0.0f;
    const Vec3 ref(lanes.ref[0][i], lanes.ref[1][i], lanes.ref[2][i]);
    if (!sampleSolidAngle(ref, Vec2(lanes.u[0][i], lanes.u[1][i]), s, pdf) || !(pdf > 0.0f))
      s = ShapeSample{Vec3(0.0f), Vec3(0.0f)}, pdf = 0.0f;
    for (int c = 0; c < 3; ++c) {
      lanes.p[c][i] = s.p[c];
      lanes.normal[c][i] = s.n[c];
    }
    lanes.pdf[i] = pdf;
  }
}

float Shape::pdfSolidAngle(const Vec3& ref, const Vec3& p, const Vec3& n) const {
  return areaToSolidAnglePdf(1.0f / area(), ref, p, n);
}

}  // namespace ember
