// The mixed material: a diffuse part kd, a Phong glossy part ks, a perfect mirror part kr and a
// perfect refraction part kt (index `ior` inside). At each scattering event one part is chosen by
// Russian roulette with probability equal to its coefficient's largest channel; the remainder,
// 1 - sum of those maxima, absorbs the path. The loader checks that the probabilities sum to <= 1
// (which implies kd + ks + kr + kt <= 1 per channel: energy conservation).
// The diffuse and glossy parts together form the non-delta part that light sampling sees: eval
// returns their BRDF sum, pdf their sampling densities weighted by their selection probabilities,
// so MIS between light and BSDF sampling stays consistent.
#pragma once

#include "materials/material.h"
#include "materials/phong_lobe.h"
#include "materials/texture.h"

#include <memory>

namespace ember {

struct MixedCoefficients {
  std::shared_ptr<const Texture> kd;
  Color ks{0.0f}, kr{0.0f}, kt{0.0f};
  float exponent = 32.0f;
  float ior = 1.5f;
};

class Mixed final : public Material {
 public:
  explicit Mixed(MixedCoefficients c) : c_(std::move(c)), lobe_{c_.exponent} {
    nonDeltaLobes_ = !isBlack(c_.kd->maxValue()) || !isBlack(c_.ks);
  }

  std::string_view typeName() const override { return "mixed"; }
  Color eval(const SurfaceHit& hit, const Vec3& wo, const Vec3& wi) const override;
  float pdf(const SurfaceHit& hit, const Vec3& wo, const Vec3& wi) const override;
  bool sample(const SurfaceHit& hit, const Vec3& wo, Vec2 u, float uLobe, BsdfSample& out) const override;
  bool hasDeltaLobes() const override;
  bool readsUv() const override { return !c_.kd->isConstant(); }  // kd is its only texture

 private:
  MixedCoefficients c_;
  PhongLobe lobe_;
};

}  // namespace ember
