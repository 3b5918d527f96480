// The specular lobe of the normalized modified Phong model (Lafortune & Willems 1994, "Using the
// Modified Phong Reflectance Model for Physically Based Rendering"): f_s = ks (n + 2) / (2 pi)
// cos^n(alpha), alpha the angle between wi and the mirror direction of wo. With kd + ks <= 1 the
// combined BRDF conserves energy. Sampled as pdf = (n + 1) / (2 pi) cos^n(alpha) around the mirror
// direction (same paper, section 3).
#pragma once

#include "materials/fresnel.h"

namespace ember {

struct PhongLobe {
  float exponent;

  // f_s / ks (without the cosine foreshortening) for unit wi and mirror direction r.
  float value(const Vec3& wi, const Vec3& r) const {
    const float c = glm::dot(wi, r);
    return c > 0.0f ? (exponent + 2.0f) / (2.0f * kPi) * std::pow(c, exponent) : 0.0f;
  }
  float pdf(const Vec3& wi, const Vec3& r) const {
    const float c = glm::dot(wi, r);
    return c > 0.0f ? (exponent + 1.0f) / (2.0f * kPi) * std::pow(c, exponent) : 0.0f;
  }
  Vec3 sample(const Vec3& r, Vec2 u) const {
    const float cosA = std::pow(u.x, 1.0f / (exponent + 1.0f));
    const float sinA = std::sqrt(std::max(0.0f, 1.0f - cosA * cosA));
    const float phi = 2.0f * kPi * u.y;
    return Frame(r).toWorld(Vec3(sinA * std::cos(phi), sinA * std::sin(phi), cosA));
  }
};

}  // namespace ember
