// Specular reflection, refraction and the exact Fresnel equations for dielectrics.
#pragma once

#include "core/math.h"

namespace ember {

// Mirror direction of w about n (both unit, w pointing away from the surface).
inline Vec3 reflect(const Vec3& w, const Vec3& n) {
  return 2.0f * glm::dot(w, n) * n - w;
}

// Snell's law (PBRT4 eq. 9.4 ff.): w points away from the surface on n's side, eta = eta_t / eta_i.
// False on total internal reflection.
inline bool refract(const Vec3& w, const Vec3& n, float eta, Vec3& wt) {
  const float cosI = glm::dot(n, w);
  const float sin2T = std::max(0.0f, 1.0f - cosI * cosI) / (eta * eta);
  if (sin2T >= 1.0f) return false;
  const float cosT = std::sqrt(1.0f - sin2T);
  wt = glm::normalize(-w / eta + (cosI / eta - cosT) * n);
  return true;
}

// Unpolarised Fresnel reflectance of a smooth dielectric interface (Born & Wolf; PBRT4 eq. 9.5),
// cosI > 0 on the incident side, eta = eta_t / eta_i. Returns 1 on total internal reflection.
inline float fresnelDielectric(float cosI, float eta) {
  cosI = std::clamp(cosI, 0.0f, 1.0f);
  const float sin2T = (1.0f - cosI * cosI) / (eta * eta);
  if (sin2T >= 1.0f) return 1.0f;
  const float cosT = std::sqrt(1.0f - sin2T);
  const float rs = (cosI - eta * cosT) / (cosI + eta * cosT);
  const float rp = (eta * cosI - cosT) / (eta * cosI + cosT);
  return 0.5f * (rs * rs + rp * rp);
}

}  // namespace ember
