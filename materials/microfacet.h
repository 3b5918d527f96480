// The Trowbridge-Reitz (GGX) microfacet distribution and the pieces of a microfacet BSDF built on
// it, in a local frame where the macro-surface normal is +z, isotropic or anisotropic with
// roughness alphaX along the frame's x axis and alphaY along its y axis (Heitz 2014, eqs. 80 and
// 82; KHR_materials_anisotropy). Every direction is unit length; h is a microfacet normal with
// h.z > 0.
//
// References:
//  - Trowbridge & Reitz 1975; Walter, Marschner, Li, Torrance 2007, "Microfacet Models for
//    Refraction through Rough Surfaces" (EGSR), eqs. 33-34 (D, G1 of GGX) and 16-21 (refraction).
//  - Heitz 2014, "Understanding the Masking-Shadowing Function in Microfacet-Based BRDFs", JCGT
//    3(2): eq. 72 (Lambda of GGX) and eq. 99 (height-correlated masking-shadowing G2).
//  - Heitz 2018, "Sampling the GGX Distribution of Visible Normals", JCGT 7(4): listing 1 (the
//    sampling routine), eq. 1 (the density of visible normals), eq. 17 (its reflected density).
//  - Schlick 1994, "An Inexpensive BRDF Model for Physically-based Rendering", eq. 15.
//  - glTF 2.0 specification, Appendix B (which picks exactly these: GGX D, height-correlated V,
//    Schlick F).
#pragma once

#include "core/math.h"

namespace ember {

// Schlick's approximation of the Fresnel reflectance, F = f0 + (1 - f0) (1 - cos)^5 (Schlick 1994,
// eq. 15), with cos the cosine between the incident direction and the (micro) normal.
inline float schlickWeight(float cosTheta) {
  const float m = std::clamp(1.0f - cosTheta, 0.0f, 1.0f);
  const float m2 = m * m;
  return m2 * m2 * m;
}
inline float schlickFresnel(float f0, float cosTheta) {
  return f0 + (1.0f - f0) * schlickWeight(cosTheta);
}
inline Color schlickFresnel(const Color& f0, float cosTheta) {
  return f0 + (Color(1.0f) - f0) * schlickWeight(cosTheta);
}

struct Ggx {
  // Below this alpha the distribution is (numerically) a Dirac delta: D ~ 1 / (pi alpha^2) and the
  // lobe width ~ alpha would fall under the float resolution of a unit vector (~6e-8 per component,
  // so sin^2 of the half-vector angle resolves ~1e-7 relative to alpha^2 = 1e-6 at the clamp).
  // Clamping keeps D, the pdfs and the sample weights finite; at 1e-3 the highlight is still far
  // narrower than any pixel footprint of a realistic camera, so the look of a glTF roughness of 0
  // (a perfect mirror) is kept.
  static constexpr float kMinAlpha = 1e-3f;

  float alphaX, alphaY;

  explicit Ggx(float a) : alphaX(std::max(a, kMinAlpha)), alphaY(alphaX) {}
  Ggx(float ax, float ay) : alphaX(std::max(ax, kMinAlpha)), alphaY(std::max(ay, kMinAlpha)) {}
  // glTF's perceptual roughness maps to alpha = roughness^2 (glTF 2.0 Appendix B.3.2).
  static Ggx fromRoughness(float roughness) { return Ggx(roughness * roughness); }
  // KHR_materials_anisotropy: along the anisotropy direction (the frame's x axis) alpha rises to
  // mix(roughness^2, 1, strength^2); across it, it stays roughness^2.
  static Ggx anisotropic(float roughness, float strength) {
    const float a = roughness * roughness, s2 = strength * strength;
    return Ggx(a + (1.0f - a) * s2, a);
  }
  bool isotropic() const { return alphaX == alphaY; }

  // D(h) = alpha^2 / (pi ((n.h)^2 (alpha^2 - 1) + 1)^2) (Walter 2007 eq. 33, glTF B.3.2). Written
  // as 1 / (pi alpha^2 t^2), t = (h.x^2 + h.y^2) / alpha^2 + h.z^2, since (n.h)^2 (alpha^2 - 1) + 1
  // = sin^2 + alpha^2 cos^2 and sin^2 is exact from h.x, h.y where 1 - h.z^2 cancels for narrow
  // lobes.
  // Anisotropic: 1 / (pi ax ay t^2), t = h.x^2 / ax^2 + h.y^2 / ay^2 + h.z^2 (Heitz 2014 eq. 82);
  // the isotropic case keeps its own expression.
  float D(const Vec3& h) const {
    if (h.z <= 0.0f) return 0.0f;
    if (isotropic()) {
      const float a2 = alphaX * alphaX;
      const float t = (h.x * h.x + h.y * h.y) / a2 + h.z * h.z;
      return 1.0f / (kPi * a2 * t * t);
    }
    const float t = h.x * h.x / (alphaX * alphaX) + h.y * h.y / (alphaY * alphaY) + h.z * h.z;
    return 1.0f / (kPi * alphaX * alphaY * t * t);
  }

  // sqrt(cos^2 (1 - alpha^2) + alpha^2) = sqrt(cos^2 + alpha^2 sin^2) for a unit w, the recurring
  // term of Lambda and of the glTF visibility term; |w.z| + this = 2 |w.z| (1 + Lambda(w)).
  // Anisotropic: sqrt(w.z^2 + ax^2 w.x^2 + ay^2 w.y^2) (Heitz 2014 eq. 80, the projected roughness).
  float root(const Vec3& w) const {
    if (isotropic()) return std::sqrt(w.z * w.z + alphaX * alphaX * (w.x * w.x + w.y * w.y));
    return std::sqrt(w.z * w.z + alphaX * alphaX * w.x * w.x + alphaY * alphaY * w.y * w.y);
  }

  // Smith Lambda(w) = (-1 + sqrt(1 + alpha^2 tan^2 theta)) / 2 (Heitz 2014 eq. 72); symmetric in
  // the sign of w.z (the microsurface seen from below is the mirrored one, for transmission).
  float Lambda(const Vec3& w) const {
    const float z = std::abs(w.z);
    if (z <= 0.0f) return kInfinity;
    return 0.5f * (root(w) / z - 1.0f);
  }
  // Smith masking G1(w) = 1 / (1 + Lambda(w)) = 2 |w.z| / (|w.z| + root(w)) (Heitz 2014 eq. 43).
  float G1(const Vec3& w) const {
    const float z = std::abs(w.z);
    const float den = z + root(w);
    return den > 0.0f ? 2.0f * z / den : 0.0f;
  }
  // Height-correlated masking-shadowing G2 = 1 / (1 + Lambda(wo) + Lambda(wi)) (Heitz 2014 eq. 99),
  // as 2 |o.z| |i.z| / (|i.z| root(o) + |o.z| root(i)). Used for reflection and, as in pbrt-v4, for
  // transmission (the exact height-correlated form for transmission is a Beta function, Heitz 2014
  // eq. 101; the two agree where either direction is near the normal).
  float G2(const Vec3& wo, const Vec3& wi) const {
    const float o = std::abs(wo.z), i = std::abs(wi.z);
    const float den = i * root(wo) + o * root(wi);
    return den > 0.0f ? 2.0f * o * i / den : 0.0f;
  }
  // The glTF visibility term V = G2 / (4 |n.l| |n.v|) = 0.5 / (|n.l| sqrt((n.v)^2 (1 - alpha^2) +
  // alpha^2) + |n.v| sqrt((n.l)^2 (1 - alpha^2) + alpha^2)) (glTF 2.0 B.3.2, Heitz 2014 eq. 99):
  // finite at grazing angles, where G2 and the cosines both vanish.
  float V(const Vec3& wo, const Vec3& wi) const {
    const float den = std::abs(wi.z) * root(wo) + std::abs(wo.z) * root(wi);
    return den > 0.0f ? 0.5f / den : 0.0f;
  }

  // Visible normal h for wo (wo.z > 0) by Heitz 2018, listing 1: stretch wo to the hemisphere
  // configuration (alpha = 1), sample the projected hemisphere (a disc, its far half squashed by
  // s = (1 + Vh.z) / 2), lift back onto the hemisphere and unstretch. (The listing clamps nh.z at 0;
  // 1e-7 keeps a sample exactly at the horizon of the hemisphere from becoming h.z = 0, where D = 0.)
  Vec3 sampleVisibleNormal(const Vec3& wo, Vec2 u) const {
    const Vec3 vh = glm::normalize(Vec3(alphaX * wo.x, alphaY * wo.y, wo.z));
    const float lensq = vh.x * vh.x + vh.y * vh.y;
    const Vec3 t1 = lensq > 0.0f ? Vec3(-vh.y, vh.x, 0.0f) / std::sqrt(lensq) : Vec3(1.0f, 0.0f, 0.0f);
    const Vec3 t2 = glm::cross(vh, t1);
    const float r = std::sqrt(u.x);
    const float phi = 2.0f * kPi * u.y;
    const float p1 = r * std::cos(phi);
    float p2 = r * std::sin(phi);
    const float s = 0.5f * (1.0f + vh.z);
    p2 = (1.0f - s) * std::sqrt(std::max(0.0f, 1.0f - p1 * p1)) + s * p2;
    const Vec3 nh = p1 * t1 + p2 * t2 + std::sqrt(std::max(0.0f, 1.0f - p1 * p1 - p2 * p2)) * vh;
    return glm::normalize(Vec3(alphaX * nh.x, alphaY * nh.y, std::max(1e-7f, nh.z)));
  }
  // Density of sampleVisibleNormal in h: D_wo(h) = G1(wo) max(0, wo.h) D(h) / wo.z (Heitz 2018
  // eq. 1), with G1(wo) / wo.z = 2 / (wo.z + root(wo)) so that it stays finite at grazing wo.
  float visibleNormalPdf(const Vec3& wo, const Vec3& h) const {
    const float cosOH = glm::dot(wo, h);
    if (wo.z <= 0.0f || cosOH <= 0.0f) return 0.0f;
    return 2.0f * D(h) * cosOH / (wo.z + root(wo));
  }
  // Density of the direction wi = reflect(wo, h), h a visible normal: D_wo(h) / (4 wo.h) (Heitz
  // 2018 eq. 17) = D(h) / (2 (wo.z + root(wo))); h = normalize(wo + wi).
  float reflectionPdf(const Vec3& wo, const Vec3& h) const {
    if (wo.z <= 0.0f || glm::dot(wo, h) <= 0.0f) return 0.0f;
    return D(h) / (2.0f * (wo.z + root(wo)));
  }
};

}  // namespace ember
