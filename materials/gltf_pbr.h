// The glTF 2.0 metallic-roughness material exactly as the specification's Appendix B defines it,
// with the Khronos material extensions layered on it as their texts define them:
//
//   specular_brdf  = D(h) V(l, v)                      Trowbridge-Reitz (GGX) D, alpha = roughness^2,
//                                                      height-correlated Smith V (Heitz 2014, eq. 99)
//   metal_brdf     = specular_brdf * schlick(f0 = baseColor)
//   dielectric     = (1 - w max3(Fr)) base + w Fr specular_brdf     (KHR_materials_specular):
//                    Fr = schlick(f0 = min(((ior - 1) / (ior + 1))^2 specularColor, 1)), w = specular
//   base           = mix(diffuse_brdf(baseColor), specular_btdf(alpha) * baseColor, transmission)
//   material       = mix(dielectric, metal_brdf, metallic)
//   sheen layer    = sheenColor f_charlie + material * min(1 - max3(sheenColor) E(n.v),
//                                                          1 - max3(sheenColor) E(n.l))
//                    (KHR_materials_sheen; materials/sheen.h)
//   Fr, F_metal    = mix(schlick, F_thin_film, iridescence)   (KHR_materials_iridescence;
//                    materials/iridescence.h)
//   alpha_t, alpha_b = mix(roughness^2, 1, anisotropy^2), roughness^2 along and across the
//                    anisotropy direction (KHR_materials_anisotropy; anisotropic GGX D and Smith V,
//                    Heitz 2014 eqs. 80, 82, sampled by Heitz 2018's stretched visible normals)
//   coated         = mix(sheen layer, clearcoat_brdf, clearcoat * schlick(0.04, n_c.v))
//                    (KHR_materials_clearcoat: a GGX lobe of its own roughness about its own normal
//                    n_c, the geometry's normal or its own normal map)
//
// with KHR_materials_transmission, _ior and _volume (thin-walled or refracting). Without the
// extensions (w = 1, specularColor = 1, no sheen, no coat) it is Appendix B term for term.
//
// Textures are looked up at the hit (each in its own texture coordinate set, the base colour times
// COLOR_0); hit.ns is the (possibly normal-mapped) shading normal. Two-sided for reflection, like
// Lambertian. Sampled with a one-sample mixture of cosine-weighted diffuse, GGX visible-normal
// sampling (Heitz 2018) of the base and of the coat, and uniform hemisphere sampling of the sheen,
// the mixture pdf being reported, so every strategy is MIS-compatible.
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
  // KHR_materials_specular: .r = specularFactor x specularTexture.a, null = 1; the colour factor x
  // specularColorTexture (linear RGB, may exceed 1), null = white.
  std::shared_ptr<const Texture> specular, specularColor;
  // KHR_materials_sheen: the colour (linear RGB, null = no sheen layer) and .r = the roughness.
  std::shared_ptr<const Texture> sheenColor, sheenRoughness;
  // KHR_materials_clearcoat: .r = the coat's weight (null = no coat), .r = its roughness, and its
  // own tangent-space normal map (null: the geometry's interpolated normal, unmapped).
  std::shared_ptr<const Texture> clearcoat, clearcoatRoughness, clearcoatNormal;
  float clearcoatNormalScale = 1.0f;
  // KHR_materials_iridescence: .r = the film's weight (null = no film); the thickness texture's .r
  // blends between the minimum and maximum thickness (nm; null = the maximum); the film's ior.
  std::shared_ptr<const Texture> iridescence, iridescenceThickness;
  float iridescenceIor = 1.3f, iridescenceThicknessMin = 100.0f, iridescenceThicknessMax = 400.0f;
  // KHR_materials_anisotropy: the strength (> 0: anisotropic), the rotation (radians, from the
  // tangent towards the bitangent) and the texture (linear RGB: direction RG in [-1, 1] tangent
  // space, strength B; null = direction (1, 0), strength 1).
  float anisotropyStrength = 0.0f, anisotropyRotation = 0.0f;
  std::shared_ptr<const Texture> anisotropy;
  float ior = 1.5f;  // 0: the dielectric reflects totally (f0 = 1), as KHR_materials_ior allows
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
  // Where the roughness (or the coat's) can be 0: those lobes are then Dirac (gltf_pbr.cpp).
  bool hasDeltaLobes() const override { return deltaLobes_; }

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
    Color specularF0{0.04f};  // the dielectric's colour at normal incidence, before the weight
    float specularWeight = 1.0f;
    Color sheenColor{0.0f};
    float sheenRoughness = 0.0f;
    float clearcoat = 0.0f;
    Ggx coatGgx = Ggx::fromRoughness(0.0f);
    // The base's specular and transmission lobes, and the coat's, are Dirac deltas here: their
    // alphas are at Ggx::kMinAlpha.
    bool smooth = false, coatSmooth = false;
    Vec3 coatNormal{0.0f};                           // world space, on the side of hit.ng
    float iridescence = 0.0f, filmThickness = 0.0f;  // nm
    Vec3 anisotropyDirection{0.0f};                  // world space, where ggx is anisotropic: its x axis
  };
  // Probabilities with which sample() picks its lobes (they sum to 1).
  struct LobeProbabilities {
    float specular, diffuse, transmission, sheen = 0.0f, coat = 0.0f;
  };
  // The local frames of one vertex: the base's (the shading normal turned to wo) and the coat's.
  struct Frames {
    Frame base, coat;
    Vec3 o, oc;    // wo in each
    bool outside;  // wo on the side of hit.ng
    bool layers;   // the sheen and coat apply: not inside a refracting volume
  };

  Params fetch(const SurfaceHit& hit) const;
  // KHR_materials_anisotropy's distribution and direction at the hit, into p.
  void fetchAnisotropy(const SurfaceHit& hit, float roughness, Params& p) const;
  // fetch(hit.uv), remembered for the hit (materials/hit_memo.h): a vertex asks twice, for the
  // light sample's evalPdf and for sample. The reference stays valid until the thread's next
  // fetchFor.
  const Params& fetchFor(const SurfaceHit& hit) const;
  bool frames(const SurfaceHit& hit, const Vec3& wo, const Params& p, Frames& out) const;
  LobeProbabilities lobeProbabilities(const Params& p, const Frames& f) const;
  // Fresnel reflectance of the dielectric layer for the cosine between wo and the microfacet
  // normal, before the specular weight.
  Color dielectricFresnel(const Params& p, float cosOH, bool outside) const;
  // The reflectances at cos(v, h) of the dielectric (before the specular weight) and of the metal,
  // with the thin film of KHR_materials_iridescence mixed in where there is one.
  void reflectances(const Params& p, float cosOH, bool outside, Color& dielectric, Color& metal) const;
  // The clearcoat's Fresnel weight, clearcoat x schlick(0.04, n_c.v), for wo (coatWeight) or for
  // a direction of cosine cosCoat with the coat's normal (0 below it).
  float coatWeightAt(const Params& p, float cosCoat) const;
  float coatWeight(const Params& p, const Frames& f) const;
  // f |cos theta_i| of the base (Appendix B with specular and transmission) and the mixture pdf of
  // its lobes, in the base frame (o.z > 0); `reflection`: wi lies on wo's side of the geometric
  // surface.
  Color evalBase(const Params& p, const LobeProbabilities& lobes, const Vec3& o, const Vec3& i,
                 bool reflection, bool outside, float& pdf) const;
  // What the sheen and the coat leave of the base for a direction of local cosine iz: the base's
  // lobes are multiplied by it.
  float baseScale(const Params& p, const Frames& f, float iz) const;
  // The same for a smooth refraction, from the cosines of its one outside direction with the
  // base's and the coat's normals: symmetric in the pair's two directions.
  float outerLayerScale(const Params& p, float cosBase, float cosCoat) const;
  // sample() through a Dirac lobe (lobe: 0 coat, 1 specular, 2 transmission).
  bool sampleDelta(const Params& p, const LobeProbabilities& lobes, const Frames& f, const SurfaceHit& hit,
                   const Vec3& wo, int lobe, BsdfSample& out) const;
  // The whole layered BSDF, f |cos theta_i|, and sample()'s mixture pdf for world direction wi.
  Color evalLayers(const Params& p, const LobeProbabilities& lobes, const Frames& f, const SurfaceHit& hit,
                   const Vec3& wo, const Vec3& wi, float& pdf) const;
  Color evalAndPdf(const SurfaceHit& hit, const Vec3& wo, const Vec3& wi, float& pdf) const;

  GltfPbrInputs inputs_;
  float ior_;  // max(ior, 1)
  float f0_;   // ((ior - 1) / (ior + 1))^2, the dielectric's normal-incidence reflectance
  bool sheen_, coat_, film_, anisotropic_;  // the layers are present
  bool deltaLobes_;                         // some hit may be smooth (Params::smooth or coatSmooth)
  bool refracts_;  // a volumetric (bending) transmission lobe: !thinWalled and ior_ > 1
  uint64_t id_;    // fetchFor's memo key: newHitMemoOwner()
};

}  // namespace ember
