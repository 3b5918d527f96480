// Two-sided Lambertian diffuse reflector: f = R / pi on both sides (../shared/refs conventions),
// sampled with a cosine-weighted hemisphere, so a sample's weight is exactly R.
#pragma once

#include "materials/material.h"
#include "materials/texture.h"

#include <memory>

namespace ember {

class Lambertian final : public Material {
 public:
  explicit Lambertian(std::shared_ptr<const Texture> reflectance)
      : reflectance_(std::move(reflectance)),
        constant_(reflectance_->isConstant()),
        constantValue_(reflectance_->maxValue()) {
    mayAbsorb_ = reflectance_->mayBeBlack();
    usesLobe_ = false;                                    // one lobe
    nonDeltaLobes_ = !isBlack(reflectance_->maxValue());  // some channel reflects somewhere
  }

  std::string_view typeName() const override { return "diffuse"; }
  Color eval(const SurfaceHit& hit, const Vec3& wo, const Vec3& wi) const override;
  float pdf(const SurfaceHit& hit, const Vec3& wo, const Vec3& wi) const override;
  // eval and pdf share the side test and the cosine.
  Color evalPdf(const SurfaceHit& hit, const Vec3& wo, const Vec3& wi, float& pdfOut) const override;
  bool sample(const SurfaceHit& hit, const Vec3& wo, Vec2 u, float uLobe, BsdfSample& out) const override;
  // Blocks of sampleCosineLanes.
  void sampleLanes(const SurfaceHit* const* hits, const Vec3* wo, const Vec2* u, const float* uLobe, size_t n,
                   BsdfSample* out, bool* ok) const override;
  bool readsUv() const override { return !constant_; }
  // Lambertian about the shading normal, so the driver's form wherever that is the geometric one.
  bool lambertianAt(const SurfaceHit& hit, Color& reflectance) const override {
    if (hit.ns != hit.ng) return false;
    reflectance = reflectanceAt(hit);
    return true;
  }
  // The reflectance where it is the same everywhere; null where a texture varies it.
  const Color* uniformLambertian() const override { return constant_ ? &constantValue_ : nullptr; }

 private:
  bool absorbsEverythingAt(const SurfaceHit& hit) const override { return isBlack(reflectanceAt(hit)); }
  // The reflectance at the hit: a constant one without the texture's virtual call, which
  // evalPdf and the BSDF sample would otherwise make at every vertex.
  Color reflectanceAt(const SurfaceHit& hit) const {
    return constant_ ? constantValue_ : reflectance_->evalAt(hit);
  }
  // The sample from the kernel's direction and pdf.
  bool finishSample(const SurfaceHit& hit, const Vec3& wo, const Vec3& wi, float pdf, BsdfSample& out) const;

 public:
  // Whether a cosine-sampled direction wi (density pdf) is kept: with a shading normal it can dip
  // below the geometric surface, and is then absorbed. The batched driver's inline Lambertian
  // vertices take the same test (packet/wave_integrator.cpp).
  static bool keepsSample(const Vec3& ng, const Vec3& wo, const Vec3& wi, float pdf) {
    return !(pdf <= 0.0f) && glm::dot(wo, ng) * glm::dot(wi, ng) > 0.0f;
  }

 private:
  std::shared_ptr<const Texture> reflectance_;
  bool constant_;        // the texture is the same everywhere (Texture::isConstant)
  Color constantValue_;  // then its value, which is its maxValue
};

}  // namespace ember
