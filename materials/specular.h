// The Dirac (perfectly specular) materials. They have no non-delta lobe: eval and pdf are zero and
// light sampling skips them; paths through them find lights by BSDF sampling alone.
//
// Mirror:     perfect reflection scaled by a reflectance colour (no Fresnel), as in ../shared/refs.
// Refraction: perfect transmission by Snell's law, total internal reflection where Snell has no
//             solution; no Fresnel reflection.
// Dielectric: a smooth dielectric interface with exact unpolarised Fresnel (fresnel.h); reflection
//             or refraction is chosen with the Fresnel probability. `iorInside` lies opposite the
//             outward geometric normal, which is how inside and outside are told apart.
// Refracted radiance is scaled by 1 / eta^2 (Veach 1997, section 5.2: radiance is not invariant
// across an interface); for a closed object the factors cancel between entry and exit.
#pragma once

#include "materials/material.h"

namespace ember {

class Mirror final : public Material {
 public:
  explicit Mirror(const Color& reflectance) : reflectance_(reflectance) {
    usesDirection_ = usesLobe_ = false;  // one direction, always taken
    nonDeltaLobes_ = false;
  }
  std::string_view typeName() const override { return "mirror"; }
  Color eval(const SurfaceHit&, const Vec3&, const Vec3&) const override { return Color(0.0f); }
  float pdf(const SurfaceHit&, const Vec3&, const Vec3&) const override { return 0.0f; }
  bool sample(const SurfaceHit& hit, const Vec3& wo, Vec2 u, float uLobe, BsdfSample& out) const override;
  bool hasDeltaLobes() const override { return true; }
  bool readsUv() const override { return false; }

 private:
  Color reflectance_;
};

class Refraction final : public Material {
 public:
  Refraction(const Color& transmittance, float iorInside, float iorOutside)
      : transmittance_(transmittance), iorInside_(iorInside), iorOutside_(iorOutside) {
    usesDirection_ = usesLobe_ = false;  // Snell's direction, or total internal reflection
    nonDeltaLobes_ = false;
  }
  std::string_view typeName() const override { return "refraction"; }
  Color eval(const SurfaceHit&, const Vec3&, const Vec3&) const override { return Color(0.0f); }
  float pdf(const SurfaceHit&, const Vec3&, const Vec3&) const override { return 0.0f; }
  bool sample(const SurfaceHit& hit, const Vec3& wo, Vec2 u, float uLobe, BsdfSample& out) const override;
  bool hasDeltaLobes() const override { return true; }
  bool readsUv() const override { return false; }

 private:
  Color transmittance_;
  float iorInside_, iorOutside_;
};

class Dielectric final : public Material {
 public:
  Dielectric(float iorInside, float iorOutside) : iorInside_(iorInside), iorOutside_(iorOutside) {
    usesDirection_ = false;  // uLobe chooses reflection or refraction, each one direction
    nonDeltaLobes_ = false;
  }
  std::string_view typeName() const override { return "dielectric"; }
  Color eval(const SurfaceHit&, const Vec3&, const Vec3&) const override { return Color(0.0f); }
  float pdf(const SurfaceHit&, const Vec3&, const Vec3&) const override { return 0.0f; }
  bool sample(const SurfaceHit& hit, const Vec3& wo, Vec2 u, float uLobe, BsdfSample& out) const override;
  bool hasDeltaLobes() const override { return true; }
  bool readsUv() const override { return false; }

 private:
  float iorInside_, iorOutside_;
};

// Shared by Refraction, Dielectric and the mixed material's transmission event: the interface seen
// from wo. n faces wo, eta = eta_t / eta_i for a ray arriving from wo's side.
struct Interface {
  Vec3 n;
  float eta;
  static Interface facing(const SurfaceHit& hit, const Vec3& wo, float iorInside, float iorOutside) {
    const bool outside = glm::dot(wo, hit.ng) >= 0.0f;
    return {outside ? hit.ns : -hit.ns, outside ? iorInside / iorOutside : iorOutside / iorInside};
  }
};

// Perfect refraction through the interface, or total internal reflection. Fills wi, eta, weight
// (unit throughput times the 1 / eta^2 radiance scaling), delta = true; pdf is left to the caller.
void refractOrReflect(const Interface& iface, const Vec3& wo, BsdfSample& out);

}  // namespace ember
