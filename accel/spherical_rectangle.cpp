#include "accel/spherical_rectangle.h"

namespace ember {

// The angle between great circles with unit normals a and b, as atan2(|a x b|, -a.b): seen from
// near the rectangle's plane the normals are nearly parallel, where acos(-a.b) (the paper's form)
// turns the rounding of the dot product into angle errors of sqrt(eps) and the solid angle came
// out wrong by up to 16 times (tests/test_sampling_lanes.cpp).
static float interiorAngle(const Vec3& a, const Vec3& b) {
  return std::atan2(glm::length(glm::cross(a, b)), -glm::dot(a, b));
}

SphericalRectangle::SphericalRectangle(const Vec3& s, const Vec3& ex, const Vec3& ey, const Vec3& o) : o_(o) {
  const float exl = glm::length(ex), eyl = glm::length(ey);
  x_ = ex / exl;
  y_ = ey / eyl;
  z_ = glm::cross(x_, y_);
  const Vec3 d = s - o;
  z0_ = glm::dot(d, z_);
  if (z0_ > 0.0f) {  // work on the side where the rectangle lies at negative z
    z_ = -z_;
    z0_ = -z0_;
  }
  x0_ = glm::dot(d, x_);
  y0_ = glm::dot(d, y_);
  x1_ = x0_ + exl;
  y1_ = y0_ + eyl;
  if (!(z0_ < 0.0f)) return;  // o lies in the rectangle's plane: it subtends no solid angle
  // The four corners as seen from o, and the normals of the great circles through each edge.
  const Vec3 v00(x0_, y0_, z0_), v01(x0_, y1_, z0_), v10(x1_, y0_, z0_), v11(x1_, y1_, z0_);
  const Vec3 n0 = glm::normalize(glm::cross(v00, v10));
  const Vec3 n1 = glm::normalize(glm::cross(v10, v11));
  const Vec3 n2 = glm::normalize(glm::cross(v11, v01));
  const Vec3 n3 = glm::normalize(glm::cross(v01, v00));
  // Interior angles of the spherical quadrilateral; their excess over 2 pi is the solid angle.
  const float g0 = interiorAngle(n0, n1), g1 = interiorAngle(n1, n2);
  const float g2 = interiorAngle(n2, n3), g3 = interiorAngle(n3, n0);
  b0_ = n0.z;
  b1_ = n2.z;
  k_ = 2.0f * kPi - g2 - g3;
  solidAngle_ = std::max(0.0f, g0 + g1 - k_);
}

Vec3 SphericalRectangle::sample(Vec2 u) const {
  // Invert the solid-angle fraction in x (paper eq. 8 ff.), then in y along that column.
  const float au = u.x * solidAngle_ + k_;
  const float fu = (std::cos(au) * b0_ - b1_) / std::sin(au);
  float cu = std::copysign(1.0f, fu) / std::sqrt(fu * fu + b0_ * b0_);
  cu = std::clamp(cu, -1.0f, 1.0f);
  float xu = -(cu * z0_) / std::sqrt(std::max(1e-12f, 1.0f - cu * cu));
  xu = std::clamp(xu, x0_, x1_);
  const float d = std::sqrt(xu * xu + z0_ * z0_);
  const float h0 = y0_ / std::sqrt(d * d + y0_ * y0_);
  const float h1 = y1_ / std::sqrt(d * d + y1_ * y1_);
  const float hv = h0 + u.y * (h1 - h0);
  const float hv2 = hv * hv;
  const float yv = hv2 < 1.0f - 1e-6f ? hv * d / std::sqrt(1.0f - hv2) : y1_;
  return o_ + xu * x_ + std::clamp(yv, y0_, y1_) * y_ + z0_ * z_;
}

}  // namespace ember
