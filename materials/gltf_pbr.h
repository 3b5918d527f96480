// The glTF 2.0 metallic-roughness material exactly as the specification's Appendix B defines it,
// extended by KHR_materials_transmission and KHR_materials_ior (and the thin-walled / volumetric
// distinction of KHR_materials_volume):
//
//   specular_brdf  = D(h) V(l, v)                      Trowbridge-Reitz (GGX) D, alpha = roughness^2,
//                                                      height-correlated Smith V (Heitz 2014, eq. 99)
//   metal_brdf     = specular_brdf * schlick(f0 = baseColor)
//   dielectric     = mix(base, specular_brdf, schlick(f0 = ((ior - 1) / (ior + 1))^2))
//   base           = mix(diffuse_brdf(baseColor), specular_btdf(alpha) * baseColor, transmission)
//   material       = mix(dielectric, metal_brdf, metallic)
//
// Textures are looked up at hit.uv; hit.ns is the (possibly normal-mapped) shading normal.
// Two-sided for reflection, like Lambertian. Sampled with a mixture of cosine-weighted diffuse and
// GGX visible-normal sampling (Heitz 2018), the mixture pdf being reported, so every strategy is
// MIS-compatible.
#pragma once

#include "materials/material.h"
#include "materials/microfacet.h"
#include "materials/texture.h"

#include <cstdint>
#include <memory>

namespace ember {

struct GltfPbrInputs {
  std::shared_ptr<const Texture> baseColor;          // linear RGB, baseColorFactor included
  std::shared_ptr<const Texture> metallicRoughness;  // .g = roughness, .b = metallic, factors included
  std::shared_ptr<const Texture> transmission;       // .r = transmission, factor included; null = 0
  float ior = 1.5f;
  // KHR_materials_transmission without KHR_materials_volume is thin-walled: light passes through
  // the surface without bending. With a volume (thicknessFactor > 0) the surface is a refracting
  // interface whose inside lies opposite the outward geometric normal.
  bool thinWalled = true;
  // KHR_materials_volume attenuation as an absorption coefficient per unit length,
  // sigma = -ln(attenuationColor) / attenuationDistance; 0 = a clear volume. Unused when thin-walled.
  Color absorption{0.0f};
};

class GltfPbrMaterial final : public Material {
 public:
  explicit GltfPbrMaterial(GltfPbrInputs inputs);
  // Not copied or moved: fetchFor's memo keys a material's inputs by its id (materials/hit_memo.h).
  GltfPbrMaterial(const GltfPbrMaterial&) = delete;
  GltfPbrMaterial& operator=(const GltfPbrMaterial&) = delete;

  std::string_view typeName() const override { return "gltf_pbr"; }
  Color eval(const SurfaceHit& hit, const Vec3& wo, const Vec3& wi) const override;
  float pdf(const SurfaceHit& hit, const Vec3& wo, const Vec3& wi) const override;
  Color evalPdf(const SurfaceHit& hit, const Vec3& wo, const Vec3& wi, float& pdfOut) const override {
    return evalAndPdf(hit, wo, wi, pdfOut);
  }
  bool sample(const SurfaceHit& hit, const Vec3& wo, Vec2 u, float uLobe, BsdfSample& out) const override;

  // Beer-Lambert through the volume (KHR_materials_volume): exp(-sigma d).
  Color interiorTransmittance(float distance) const override {
    return refracts_ ? glm::exp(-inputs_.absorption * distance) : Color(1.0f);
  }

  const GltfPbrInputs& inputs() const { return inputs_; }

 private:
  // The inputs at one surface point.
  struct Params {
    Color baseColor{0.0f};
    float metallic = 0.0f, transmission = 0.0f;
    Ggx ggx = Ggx::fromRoughness(1.0f);
  };
  // Probabilities with which sample() picks its lobes (they sum to 1).
  struct LobeProbabilities {
    float specular, diffuse, transmission;
  };

  Params fetch(Vec2 uv) const;
  // fetch(hit.uv), remembered for the hit (materials/hit_memo.h): a vertex asks twice, for the
  // light sample's evalPdf and for sample. The reference stays valid until the thread's next
  // fetchFor.
  const Params& fetchFor(const SurfaceHit& hit) const;
  LobeProbabilities lobeProbabilities(const Params& p, float cosO, bool outside) const;
  // Fresnel reflectance of the dielectric layer for the cosine between wo and the microfacet normal.
  float dielectricFresnel(float cosOH, bool outside) const;
  // f |cos theta_i| and the mixture pdf of sample() together, in the local frame of the normal that
  // faces wo (o.z > 0); `reflection`: wi lies on wo's side of the geometric surface.
  Color evalLocal(const Params& p, const LobeProbabilities& lobes, const Vec3& o, const Vec3& i,
                  bool reflection, bool outside, float& pdf) const;
  Color evalAndPdf(const SurfaceHit& hit, const Vec3& wo, const Vec3& wi, float& pdf) const;

  GltfPbrInputs inputs_;
  float ior_;      // max(ior, 1)
  float f0_;       // ((ior - 1) / (ior + 1))^2, the dielectric's normal-incidence reflectance
  bool refracts_;  // a volumetric (bending) transmission lobe: !thinWalled and ior_ > 1
  uint64_t id_;    // fetchFor's memo key: newHitMemoOwner()
};

}  // namespace ember
