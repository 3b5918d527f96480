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

bool Shape::sampleSolidAngle(const Vec3& ref, Vec2 u, ShapeSample& s, float& pdf) const {
  s = sampleArea(u);
  pdf = areaToSolidAnglePdf(1.0f / area(), ref, s.p, s.n);
  return pdf > 0.0f && std::isfinite(pdf);
}

float Shape::pdfSolidAngle(const Vec3& ref, const Vec3& p, const Vec3& n) const {
  return areaToSolidAnglePdf(1.0f / area(), ref, p, n);
}

}  // namespace ember
