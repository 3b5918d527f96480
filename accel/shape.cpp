#include "accel/shape.h"

namespace ember {

float areaToSolidAnglePdf(float pdfArea, const Vec3& ref, const Vec3& p, const Vec3& n) {
  const Vec3 d = p - ref;
  const float dist2 = glm::dot(d, d);
  if (dist2 == 0.0f) return 0.0f;
  const float cosLight = std::abs(glm::dot(n, d)) / std::sqrt(dist2);
  if (cosLight == 0.0f) return 0.0f;
  return pdfArea * dist2 / cosLight;
}

SurfacePoint projectToPlane(const Vec3& p, const Vec3& anchor, const Vec3& n) {
  const glm::dvec3 dp(p), dn(n);
  return roundedPoint(dp - glm::dot(dp - glm::dvec3(anchor), dn) / glm::dot(dn, dn) * dn);
}

SurfacePoint projectToPlane(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const glm::dvec3 da(a), n = glm::cross(glm::dvec3(b) - da, glm::dvec3(c) - da);
  const double n2 = glm::dot(n, n);
  if (!(n2 > 0.0)) return {p, roundingErrorBound(maxComponent(glm::abs(p)))};
  const glm::dvec3 dp(p);
  return roundedPoint(dp - glm::dot(dp - da, n) / n2 * n);
}

bool Shape::sampleSolidAngle(const Vec3& ref, Vec2 u, ShapeSample& s, float& pdf) const {
  s = sampleArea(u);
  pdf = areaToSolidAnglePdf(1.0f / area(), ref, s.p, s.n);
  return pdf > 0.0f && std::isfinite(pdf);
}

float Shape::pdfSolidAngle(const Vec3& ref, const Vec3& p, const Vec3& n) const {
  return areaToSolidAnglePdf(1.0f / area(), ref, p, n);
}

}  // namespace ember
