#include "accel/spherical_triangle.h"

#include <numbers>

namespace ember {

// The angle between two vectors, accurate near 0 and pi (unlike acos of the dot product).
static double angleBetween(const glm::dvec3& x, const glm::dvec3& y) {
  return std::atan2(glm::length(glm::cross(x, y)), glm::dot(x, y));
}

// The unit part of x orthogonal to the unit vector n.
static glm::dvec3 orthogonalPart(const glm::dvec3& x, const glm::dvec3& n) {
  const glm::dvec3 r = x - glm::dot(x, n) * n;
  const double len = glm::length(r);
  return len > 0.0 ? r / len : glm::dvec3(0.0);
}

SphericalTriangle::SphericalTriangle(const Vec3& v0, const Vec3& v1, const Vec3& v2, const Vec3& o) {
  const glm::dvec3 origin(o);
  const glm::dvec3 da = glm::dvec3(v0) - origin, db = glm::dvec3(v1) - origin, dc = glm::dvec3(v2) - origin;
  const double la = glm::length(da), lb = glm::length(db), lc = glm::length(dc);
  if (!(la > 0.0 && lb > 0.0 && lc > 0.0)) return;
  a_ = da / la;
  b_ = db / lb;
  c_ = dc / lc;
  const double triple = std::abs(glm::dot(a_, glm::cross(b_, c_)));
  const double denom = 1.0 + glm::dot(a_, b_) + glm::dot(b_, c_) + glm::dot(c_, a_);
  solidAngle_ = 2.0 * std::atan2(triple, denom);
  // Interior angles: between the planes of the two arcs meeting at each vertex.
  const glm::dvec3 nab = glm::cross(a_, b_), nbc = glm::cross(b_, c_), nca = glm::cross(c_, a_);
  alpha_ = angleBetween(nab, -nca);
  const double beta = angleBetween(nbc, -nab), gamma = angleBetween(nca, -nbc);
  area_ = alpha_ + beta + gamma - std::numbers::pi;
  if (!(area_ > 0.0) || !std::isfinite(area_)) solidAngle_ = 0.0;
}

Vec3 SphericalTriangle::sample(Vec2 u) const {
  // Arvo 1995, figure 2: choose the sub-triangle (a, b, c') of area u.x * area with c' on the arc
  // from a to c, then a point on the arc from b to c' with the right density.
  const double subArea = double(u.x) * area_;
  const double s = std::sin(subArea - alpha_), t = std::cos(subArea - alpha_);
  const double cosAlpha = std::cos(alpha_), sinAlpha = std::sin(alpha_);
  const double uu = t - cosAlpha;
  const double v = s + sinAlpha * glm::dot(a_, b_);
  const double den = (v * s + uu * t) * sinAlpha;
  const double q = den != 0.0 ? std::clamp(((v * t - uu * s) * cosAlpha - v) / den, -1.0, 1.0) : 1.0;
  const glm::dvec3 cHat = q * a_ + std::sqrt(std::max(0.0, 1.0 - q * q)) * orthogonalPart(c_, a_);
  const double z = 1.0 - double(u.y) * (1.0 - glm::dot(cHat, b_));
  const glm::dvec3 w = z * b_ + std::sqrt(std::max(0.0, 1.0 - z * z)) * orthogonalPart(cHat, b_);
  return Vec3(glm::normalize(w));
}

Vec2 barycentricsAlong(const Vec3& v0, const Vec3& v1, const Vec3& v2, const Vec3& o, const Vec3& w) {
  const glm::dvec3 p0(v0), e1 = glm::dvec3(v1) - p0, e2 = glm::dvec3(v2) - p0;
  const glm::dvec3 n = glm::cross(e1, e2), dir(w);
  const double dn = glm::dot(n, dir);
  if (dn == 0.0) return Vec2(1.0f / 3.0f);
  const glm::dvec3 rel = glm::dvec3(o) + (glm::dot(n, p0 - glm::dvec3(o)) / dn) * dir - p0;
  const double d00 = glm::dot(e1, e1), d01 = glm::dot(e1, e2), d11 = glm::dot(e2, e2);
  const double d20 = glm::dot(rel, e1), d21 = glm::dot(rel, e2);
  const double det = d00 * d11 - d01 * d01;
  if (!(det > 0.0)) return Vec2(1.0f / 3.0f);
  double b1 = std::max(0.0, (d11 * d20 - d01 * d21) / det), b2 = std::max(0.0, (d00 * d21 - d01 * d20) / det);
  if (b1 + b2 > 1.0) {
    const double sum = b1 + b2;
    b1 /= sum;
    b2 /= sum;
  }
  return Vec2(float(b1), float(b2));
}

std::optional<SphericalTriangle> sphericalTriangleForSampling(const Vec3& ref, const Vec3& v0, const Vec3& v1,
                                                              const Vec3& v2, float area) {
  const Vec3 d = ref - (v0 + v1 + v2) / 3.0f;
  if (!(glm::dot(d, d) < 4.0f * area)) return std::nullopt;
  SphericalTriangle st(v0, v1, v2, ref);
  if (!(st.solidAngle() > 1e-4)) return std::nullopt;
  return st;
}

}  // namespace ember
