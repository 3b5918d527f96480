// Normalized modified Phong: diffuse kd / pi plus the energy-conserving Phong lobe (phong_lobe.h),
// two-sided like the Lambertian. The loader checks kd + ks <= 1 per channel. Sampling picks the
// diffuse or the glossy lobe in proportion to max(kd) and max(ks) and reports the mixture pdf.
#pragma once

#include "materials/material.h"
#include "materials/phong_lobe.h"
#include "materials/texture.h"

#include <memory>

namespace ember {

class Phong final : public Material {
 public:
  Phong(std::shared_ptr<const Texture> kd, const Color& ks, float exponent)
      : kd_(std::move(kd)), ks_(ks), lobe_{exponent} {}

  std::string_view typeName() const override { return "phong"; }
  Color eval(const SurfaceHit& hit, const Vec3& wo, const Vec3& wi) const override;
  float pdf(const SurfaceHit& hit, const Vec3& wo, const Vec3& wi) const override;
  bool sample(const SurfaceHit& hit, const Vec3& wo, Vec2 u, float uLobe, BsdfSample& out) const override;
  bool readsUv() const override { return !kd_->isConstant(); }  // kd is its only texture

 private:
  float diffuseProbability(const Color& kd) const;

  std::shared_ptr<const Texture> kd_;
  Color ks_;
  PhongLobe lobe_;
};

}  // namespace ember
