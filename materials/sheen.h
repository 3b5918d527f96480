// The "Charlie" sheen lobe of KHR_materials_sheen: the microfibre distribution of Estevez & Kulla
// 2017 ("Production Friendly Microfacet Sheen BRDF", SIGGRAPH course; eq. 2), their fitted
// shadowing (the Lambda fit of section 3, as the extension's implementation notes give it), and
// the directional albedo E(cos, roughness) that the extension's albedo scaling of the base layer
// needs (Estevez & Kulla section 4), tabulated by numerical integration on first use.
//
//   D(h)      = (2 + 1/alpha) sin(theta_h)^(1/alpha) / (2 pi),          alpha = sheenRoughness^2
//   V(o, i)   = 1 / ((1 + Lambda(o) + Lambda(i)) 4 |n.o| |n.i|)
//   f_sheen   = sheenColor D(h) V(o, i)
//   E(mu)     = integral over the hemisphere of D V cos(theta_i), for sheenColor = 1
//
// The roughness is clamped to >= kMinRoughness: below it the lobe lies within a few degrees of the
// horizon, where the albedo is nearly zero anyway, and its narrowness would need a far finer table.
#pragma once

#include "core/math.h"

namespace ember {

struct CharlieSheen {
  static constexpr float kMinRoughness = 0.07f;

  float roughness;  // clamped perceptual roughness
  float alpha;      // roughness^2

  explicit CharlieSheen(float sheenRoughness)
      : roughness(std::clamp(sheenRoughness, kMinRoughness, 1.0f)), alpha(roughness * roughness) {}

  // D(h) for a unit half vector with h.z = cos(theta_h) >= 0, in the local frame of the normal.
  float D(const Vec3& h) const {
    const float sin2 = std::max(0.0f, h.x * h.x + h.y * h.y);
    const float invAlpha = 1.0f / alpha;
    return (2.0f + invAlpha) * std::pow(sin2, 0.5f * invAlpha) * (0.5f * kInvPi);
  }
  // The fitted Lambda of Estevez & Kulla 2017, section 3: exp(L(cos)) for cos < 1/2, mirrored
  // about 1/2 above it so that Lambda(1) = 0 is met smoothly.
  float Lambda(float cosTheta) const {
    const float c = std::abs(cosTheta);
    return c < 0.5f ? std::exp(fit(c)) : std::exp(2.0f * fit(0.5f) - fit(1.0f - c));
  }
  // V = G2 / (4 |n.o| |n.i|) with the height-correlated form G2 = 1 / (1 + Lambda(o) + Lambda(i)).
  float V(float cosO, float cosI) const {
    const float o = std::abs(cosO), i = std::abs(cosI);
    if (!(o > 0.0f) || !(i > 0.0f)) return 0.0f;
    return 1.0f / ((1.0f + Lambda(o) + Lambda(i)) * 4.0f * o * i);
  }
  // f_sheen(o, i) cos(theta_i) for a white sheen colour; o and i in the upper local hemisphere.
  float evalCos(const Vec3& o, const Vec3& i) const {
    if (!(o.z > 0.0f) || !(i.z > 0.0f)) return 0.0f;
    const Vec3 h = glm::normalize(o + i);
    return D(h) * V(o.z, i.z) * i.z;
  }

 private:
  // L(x) of Estevez & Kulla, its five coefficients interpolated in (1 - alpha)^2 between their fits
  // at alpha = 0 and 1.
  float fit(float x) const {
    const float t = (1.0f - alpha) * (1.0f - alpha);
    const float a = lerp(21.5473f, 25.3245f, t), b = lerp(3.82987f, 3.32435f, t),
                c = lerp(0.19823f, 0.16801f, t), d = lerp(-1.97760f, -1.27393f, t),
                e = lerp(-4.32054f, -4.85967f, t);
    return a / (1.0f + b * std::pow(x, c)) + d * x + e;
  }
  static float lerp(float a, float b, float t) { return a + (b - a) * t; }
};

// E(|cos theta|, roughness): the directional albedo of the white Charlie lobe, bilinear in a
// table over sqrt(cos theta) in [0, 1] and roughness in [kMinRoughness, 1] computed once per
// process (about 0.1 s). Towards grazing angles E exceeds 1 (2.0 at cos theta = 0.02 and roughness
// 0.07): the fitted shadowing of the definition does not bound it there.
float sheenAlbedo(float cosTheta, float sheenRoughness);

// The same integral by direct quadrature (n x 2n points over the hemisphere, dense towards the
// horizon): what the table is built from, and what tests check it against at finer n.
double sheenAlbedoQuadrature(float cosTheta, float sheenRoughness, int n);

}  // namespace ember
