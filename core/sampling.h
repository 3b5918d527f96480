// Warping of uniform random numbers onto common domains, each with its density.
// Derivations: Pharr, Jakob, Humphreys, "Physically Based Rendering" 4th ed. (PBRT4), ch. A.5.
#pragma once

#include "core/math.h"

namespace ember {

// Shirley–Chiu concentric map of [0,1)^2 onto the unit disc (PBRT4 eq. A.5.1).
inline Vec2 sampleUniformDiskConcentric(Vec2 u) {
  const Vec2 o = 2.0f * u - Vec2(1.0f);
  if (o.x == 0.0f && o.y == 0.0f) return Vec2(0.0f);
  float r, theta;
  if (std::abs(o.x) > std::abs(o.y)) {
    r = o.x;
    theta = (kPi / 4.0f) * (o.y / o.x);
  } else {
    r = o.y;
    theta = (kPi / 2.0f) - (kPi / 4.0f) * (o.x / o.y);
  }
  return r * Vec2(std::cos(theta), std::sin(theta));
}

// Malley's method: cosine-weighted hemisphere around +z, pdf = cos(theta) / pi.
inline Vec3 sampleCosineHemisphere(Vec2 u) {
  const Vec2 d = sampleUniformDiskConcentric(u);
  const float z = std::sqrt(std::max(0.0f, 1.0f - d.x * d.x - d.y * d.y));
  return {d.x, d.y, z};
}
inline float cosineHemispherePdf(float cosTheta) {
  return std::max(cosTheta, 0.0f) * kInvPi;
}

// Uniform direction on the unit sphere, pdf = 1 / (4 pi).
inline Vec3 sampleUniformSphere(Vec2 u) {
  const float z = 1.0f - 2.0f * u.x;
  const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
  const float phi = 2.0f * kPi * u.y;
  return {r * std::cos(phi), r * std::sin(phi), z};
}
inline constexpr float kUniformSpherePdf = 1.0f / (4.0f * kPi);

// Uniform direction in the cone of half-angle acos(cosThetaMax) around +z,
// pdf = 1 / (2 pi (1 - cosThetaMax)).
inline Vec3 sampleUniformCone(Vec2 u, float cosThetaMax) {
  const float cosTheta = (1.0f - u.x) + u.x * cosThetaMax;
  const float sinTheta = std::sqrt(std::max(0.0f, 1.0f - cosTheta * cosTheta));
  const float phi = 2.0f * kPi * u.y;
  return {sinTheta * std::cos(phi), sinTheta * std::sin(phi), cosTheta};
}
inline float uniformConePdf(float cosThetaMax) {
  return 1.0f / (2.0f * kPi * (1.0f - cosThetaMax));
}

// Uniform barycentrics on a triangle (PBRT4 eq. A.5.4, the square-root parameterisation).
inline Vec2 sampleUniformTriangle(Vec2 u) {
  const float su = std::sqrt(u.x);
  return {1.0f - su, u.y * su};
}

// Power heuristic with beta = 2 (Veach 1997, eq. 9.13).
inline float powerHeuristic(float pdfA, float pdfB) {
  // Written as 1 / (1 + (b/a)^2) so that the huge densities of a light seen from very close or at
  // grazing (d^2 / cos) cannot overflow the squares into inf / inf.
  if (!(pdfA > 0.0f)) return 0.0f;
  if (std::isinf(pdfA)) return std::isinf(pdfB) ? 0.5f : 1.0f;
  const float r = pdfB / pdfA;
  return 1.0f / (1.0f + r * r);
}

}  // namespace ember
