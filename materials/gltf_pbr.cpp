// glTF 2.0 metallic-roughness BRDF (specification Appendix B) with the Khronos material extensions.
// The formulas are in gltf_pbr.h; the choices the specification leaves open:
//
//  - Inputs: a missing baseColor or metallicRoughness texture means glTF's default factors (1);
//    roughness, metallic and transmission are clamped to [0, 1], the base colour to >= 0, ior to
//    >= 1. alpha = roughness^2 is clamped to Ggx::kMinAlpha = 1e-3 (microfacet.h says why).
//  - Smooth surfaces: where alpha is at that clamp (roughness <= 0.0316, isotropic), the specular
//    reflection and the transmission are Dirac lobes, and so is the coat where its own roughness
//    is. Each is its microfacet lobe's limit as alpha -> 0: the integral of D V |cos theta_i|
//    over the lobe tends to 1 (D to a delta about n, G2 to 1), leaving the lobe's Fresnel weights
//    at n.v: a mirror weighted dielectric w Fd + metallic Fm (and the coat's clearcoat F_c),
//    thin-walled transmission straight through with dielectric t (1 - w max3(Fd)) baseColor, and
//    refraction with dielectric t (1 - F) baseColor / eta^2 (the radiance scaling, as Dielectric
//    in specular.h). The diffuse and sheen lobes are unchanged; the lobe probabilities are the
//    same, a Dirac lobe's being its sample's pdf. A smooth refraction's sheen and coat factor is
//    taken at its one outside direction whichever side wo is on (the outer coating is crossed
//    either way), so the path tracer and the light tracer, which meet the pair in opposite
//    orders, weigh it alike. So glTF glass and polished metal cast caustics
//    that the light tracer can follow (renderer/caustic_tracer.h), and the path tracer's images
//    are those of the alpha -> 0 limit rather than of alpha = 1e-3.
//  - Reflection is two-sided, like Lambertian: the shading frame is the shading normal turned to
//    wo's side of the geometric normal, and wi must lie on that side of both (sameSide on hit.ng,
//    positive cosine with the shading normal).
//  - The Fresnel factors take |V.H| with H the microfacet normal of the pair (wo, wi): the half
//    vector for reflection, that of wo and the mirrored wi for thin-walled transmission, and the
//    generalised half vector (Walter et al. 2007 eq. 16) for refraction.
//  - Thin-walled transmission (KHR_materials_transmission alone): the GGX reflection lobe mirrored
//    through the surface, f_t(wo, wi) = baseColor specular_brdf(wo, mirror(wi)), no bending.
//  - Volumetric transmission (!thinWalled, and ior > 1; an index-matched interface falls back to the
//    thin-walled lobe since its refraction lobe collapses to a Dirac delta): the rough dielectric
//    BTDF of Walter et al. 2007 (eq. 21) with the height-correlated G2, in its radiance form (PBRT3
//    section 8.4.4: the 1 / eta^2 radiance scaling of Veach 1997, section 5.2, is folded in, as the
//    Dielectric material does), eta = eta_t / eta_i, the inside lying opposite hit.ng (as
//    Interface::facing in specular.h).
//    Fresnel from the inside: Schlick evaluated at the cosine on the OUTSIDE (the refracted angle),
//    and 1 past the critical angle (total internal reflection). This is the usual way of using
//    Schlick on the dense side (e.g. Lagarde 2013, "Memo on Fresnel equations"); unlike the exact
//    Fresnel of fresnel.h on that side, it gives a refracting pair (wo, wi) the same F from both
//    sides, so the BTDF obeys the generalised reciprocity f(wo, wi) / eta_i^2 = f(wi, wo) / eta_o^2
//    exactly and stays continuous with the specification's Schlick on the outside.
//  - KHR_materials_specular: the dielectric's Fresnel is a colour, Fr = schlick(f0 = min(f0_ior
//    specularColor, 1), f90 = 1), the specular lobe weighted by w Fr and the base by
//    1 - w max3(Fr) (the extension's fresnel_mix); the metal is unchanged. Inside a refracting
//    volume Fr is taken as below, per channel. An ior of 0 (allowed for specular-glossiness
//    conversions) means f0 = 1.
//  - KHR_materials_sheen and _clearcoat layer over the whole base, transmission included, and only
//    where wo is not inside a refracting volume (they are coatings of the outer surface). The coat
//    weight uses n_c.v, as the extension defines it, so the coated BSDF is not reciprocal.
//    Emission under a coat is not darkened by it (the extension suggests so; Ember's emission is the
//    surface's, read before any material).
//  - KHR_materials_iridescence mixes the thin-film reflectance into the dielectric's and the
//    metal's Fresnel for reflection and thin-walled transmission; the refraction lobe of a volume
//    keeps Schlick's (the film's weight is no reason to break its reciprocity), and the lobe
//    probabilities use Schlick's, which only steer sampling. The optical path difference takes the
//    angle inside the film (Belcour & Barla's code; the extension's text writes cos theta_1).
//  - Sampling: a one-sample mixture of cosine-weighted diffuse, GGX visible normals (Heitz 2018)
//    reflected, (transmission > 0) the same visible normal refracted or reflected-and-mirrored,
//    uniform hemisphere directions for the sheen and the coat's own visible normals. Lobe
//    probabilities are proportional to cheap weight estimates with the Fresnel terms at n.v (the
//    dielectric's capped at 0.9): coat c F_c, sheen (1 - c F_c) max(sheen) E, and under them
//    (1 - c F_c)(1 - max(sheen) E) times: specular (1 - m) w F_d + m max(F_m), diffuse
//    (1 - m)(1 - w F_d)(1 - t) max(baseColor), transmission (1 - m)(1 - w F_d) t max(baseColor).
//    Every strategy reports the full mixture pdf,
//    and the weight is eval / pdf, so sample(), eval() and pdf() agree exactly. A sampled direction
//    that leaves its lobe's side (a reflected visible normal under the horizon, total internal
//    reflection of a refraction sample) is absorbed: such directions carry no single-scattering
//    energy, and pdf() counts only what sample() returns.
//
// Appendix B's dielectric is not energy conserving: the base is weighted by 1 - F(|V.H|) per
// direction pair rather than by what the specular layer leaves over, so towards grazing wo the
// white-furnace albedo exceeds 1: 1.08 at roughness 0.6 and 1.33 at roughness 0.3 for
// cos theta_o = 0.05 (pinned by tests/test_pbr.cpp), about 1.68 at roughness 0.1. It is implemented as
// specified all the same.
#include "materials/gltf_pbr.h"

#include "core/sampling.h"
#include "materials/fresnel.h"
#include "materials/hit_memo.h"
#include "materials/iridescence.h"
#include "materials/sheen.h"
#include "materials/surface_maps.h"

namespace ember {

namespace {

// KHR_materials_clearcoat's layer is a dielectric of ior 1.5: f0 = ((1.5 - 1) / (1.5 + 1))^2.
constexpr float kCoatF0 = 0.04f;

float maxOf(const Color& c) {
  return std::max(c.x, std::max(c.y, c.z));
}

}  // namespace

GltfPbrMaterial::GltfPbrMaterial(GltfPbrInputs inputs) : inputs_(std::move(inputs)), id_(newHitMemoOwner()) {
  if (inputs_.ior == 0.0f) {
    ior_ = 1.0f;
    f0_ = 1.0f;  // ((0 - 1) / (0 + 1))^2
  } else {
    ior_ = std::max(inputs_.ior, 1.0f);
    const float r = (ior_ - 1.0f) / (ior_ + 1.0f);
    f0_ = r * r;  // 0.04 at ior 1.5 (glTF B.3.4, KHR_materials_ior)
  }
  refracts_ = !inputs_.thinWalled && ior_ > 1.0f + 1e-3f;
  sheen_ = inputs_.sheenColor && !isBlack(inputs_.sheenColor->maxValue());
  coat_ = inputs_.clearcoat && inputs_.clearcoat->maxValue().x > 0.0f;
  film_ = inputs_.iridescence && inputs_.iridescence->maxValue().x > 0.0f;
  anisotropic_ = inputs_.anisotropyStrength > 0.0f;

  // Where a roughness can reach the clamp: the same test as fetch's Params::smooth (alpha =
  // roughness^2 at the clamp), so the two agree to the last bit of rounding. Anisotropy only widens
  // the lobe, so "may be smooth" ignores it.
  const auto smooth = [](float roughness) {
    const float r = std::clamp(roughness, 0.0f, 1.0f);
    return r * r <= Ggx::kMinAlpha;
  };
  const auto smoothSomewhere = [&](const std::shared_ptr<const Texture>& t, int channel, float absent) {
    return smooth(t ? t->minValue()[channel] : absent);
  };
  const auto smoothEverywhere = [&](const std::shared_ptr<const Texture>& t, int channel, float absent) {
    return smooth(t ? t->maxValue()[channel] : absent);
  };
  deltaLobes_ = smoothSomewhere(inputs_.metallicRoughness, 1, 1.0f) ||
                (coat_ && smoothSomewhere(inputs_.clearcoatRoughness, 0, 0.0f));
  // Only Dirac lobes: a smooth metal, or smooth glass that transmits all it does not reflect,
  // without a sheen or a rough coat. Then no light sample is worth a shadow ray.
  const bool noDiffuse =
      (inputs_.metallicRoughness ? inputs_.metallicRoughness->minValue().b : 1.0f) >= 1.0f ||
      (inputs_.transmission && inputs_.transmission->minValue().r >= 1.0f);
  nonDeltaLobes_ = !(smoothEverywhere(inputs_.metallicRoughness, 1, 1.0f) && !anisotropic_ && !sheen_ &&
                     (!coat_ || smoothEverywhere(inputs_.clearcoatRoughness, 0, 0.0f)) && noDiffuse);
}

const GltfPbrMaterial::Params& GltfPbrMaterial::fetchFor(const SurfaceHit& hit) const {
  return HitMemo<Params, GltfPbrMaterial>::at(hit, id_, [&] { return fetch(hit); });
}

GltfPbrMaterial::Params GltfPbrMaterial::fetch(const SurfaceHit& hit) const {
  Params p;
  p.baseColor = Color(1.0f);
  p.metallic = 1.0f;
  if (inputs_.baseColor) p.baseColor = glm::max(inputs_.baseColor->evalFresh(hit), Color(0.0f));
  float roughness = 1.0f;
  if (inputs_.metallicRoughness) {
    const Color mr = inputs_.metallicRoughness->evalFresh(hit);
    roughness = std::clamp(mr.g, 0.0f, 1.0f);
    p.ggx = Ggx::fromRoughness(roughness);
    p.metallic = std::clamp(mr.b, 0.0f, 1.0f);
  }
  if (inputs_.transmission) p.transmission = std::clamp(inputs_.transmission->evalFresh(hit).r, 0.0f, 1.0f);
  const Color specularColor =
      inputs_.specularColor ? glm::max(inputs_.specularColor->evalFresh(hit), Color(0.0f)) : Color(1.0f);
  p.specularF0 = glm::min(f0_ * specularColor, Color(1.0f));
  if (inputs_.specular) p.specularWeight = std::clamp(inputs_.specular->evalFresh(hit).r, 0.0f, 1.0f);
  if (sheen_) {
    p.sheenColor = glm::clamp(inputs_.sheenColor->evalFresh(hit), Color(0.0f), Color(1.0f));
    p.sheenRoughness = inputs_.sheenRoughness ? inputs_.sheenRoughness->evalFresh(hit).r : 0.0f;
  }
  if (coat_) {
    p.clearcoat = std::clamp(inputs_.clearcoat->evalFresh(hit).r, 0.0f, 1.0f);
    const float roughness = inputs_.clearcoatRoughness ? inputs_.clearcoatRoughness->evalFresh(hit).r : 0.0f;
    p.coatGgx = Ggx::fromRoughness(std::clamp(roughness, 0.0f, 1.0f));
    // The coat's normal: the geometry's interpolated one, not the base's normal map (the
    // extension: "if clearcoatNormalTexture is not given, no normal mapping is applied").
    Vec3 n = hit.attributes ? hit.attributes->normalAt(hit.prim, hit.bary) : hit.ns;
    if (inputs_.clearcoatNormal && hit.attributes)
      n = SurfaceMaps::perturbNormal(*inputs_.clearcoatNormal, inputs_.clearcoatNormalScale, n,
                                     hit.attributes->tangentAt(hit.prim, hit.bary),
                                     hit.texCoord(inputs_.clearcoatNormal->texCoordSet()));
    p.coatNormal = glm::dot(n, hit.ng) < 0.0f ? -n : n;
  }
  if (anisotropic_) fetchAnisotropy(hit, roughness, p);
  p.smooth = std::max(p.ggx.alphaX, p.ggx.alphaY) <= Ggx::kMinAlpha;
  p.coatSmooth = coat_ && p.coatGgx.alphaX <= Ggx::kMinAlpha;
  if (film_) {
    p.iridescence = std::clamp(inputs_.iridescence->evalFresh(hit).r, 0.0f, 1.0f);
    const float t = inputs_.iridescenceThickness
                        ? std::clamp(inputs_.iridescenceThickness->evalFresh(hit).r, 0.0f, 1.0f)
                        : 1.0f;
    p.filmThickness = inputs_.iridescenceThicknessMin +
                      (inputs_.iridescenceThicknessMax - inputs_.iridescenceThicknessMin) * t;
  }
  return p;
}

void GltfPbrMaterial::fetchAnisotropy(const SurfaceHit& hit, float roughness, Params& p) const {
  // The direction in tangent space: the texture's RG mapped to [-1, 1] (default (1, 0)), rotated
  // by anisotropyRotation; the strength times the texture's B (KHR_materials_anisotropy).
  Vec2 d(1.0f, 0.0f);
  float strength = inputs_.anisotropyStrength;
  if (inputs_.anisotropy) {
    const Color t = inputs_.anisotropy->evalFresh(hit);
    const Vec2 texel(2.0f * t.x - 1.0f, 2.0f * t.y - 1.0f);
    const float len = glm::length(texel);
    d = len > 1e-6f ? texel / len : Vec2(1.0f, 0.0f);
    strength *= std::clamp(t.z, 0.0f, 1.0f);
  }
  const float c = std::cos(inputs_.anisotropyRotation), s = std::sin(inputs_.anisotropyRotation);
  d = Vec2(c * d.x - s * d.y, s * d.x + c * d.y);
  p.ggx = Ggx::anisotropic(roughness, std::clamp(strength, 0.0f, 1.0f));
  // The world direction in the (T, B, N) frame of the mesh (B = cross(N, T) w, glTF 2.0 section
  // 3.7.2.1); without tangents (an analytic shape) the shading frame's own first axis.
  if (!hit.attributes) return;
  const glm::vec4 tangent = hit.attributes->tangentAt(hit.prim, hit.bary);
  const Vec3 n = hit.attributes->normalAt(hit.prim, hit.bary);
  Vec3 t = Vec3(tangent) - n * glm::dot(n, Vec3(tangent));
  const float tl = glm::length(t);
  if (!(tl > 1e-6f)) return;
  t /= tl;
  const Vec3 b = glm::cross(n, t) * (tangent.w < 0.0f ? -1.0f : 1.0f);
  p.anisotropyDirection = d.x * t + d.y * b;
}

bool GltfPbrMaterial::frames(const SurfaceHit& hit, const Vec3& wo, const Params& p, Frames& f) const {
  f.outside = glm::dot(wo, hit.ng) >= 0.0f;
  f.base = Frame(f.outside ? hit.ns : -hit.ns);  // facingNormal(hit, wo)
  if (anisotropic_) {
    // The x axis along the anisotropy direction, made orthogonal to the shading normal; without
    // one, Frame's own x axis.
    const Vec3 t = p.anisotropyDirection - f.base.n * glm::dot(f.base.n, p.anisotropyDirection);
    const float tl = glm::length(t);
    if (tl > 1e-6f) {
      f.base.s = t / tl;
      f.base.t = glm::cross(f.base.n, f.base.s);
    }
  }
  f.o = f.base.toLocal(wo);
  if (!(f.o.z > 0.0f)) return false;  // wo under the shading hemisphere
  f.layers = !refracts_ || f.outside;
  if (coat_ && f.layers) {
    f.coat = Frame(f.outside ? p.coatNormal : -p.coatNormal);
    f.oc = f.coat.toLocal(wo);
  } else {
    f.oc = Vec3(0.0f);
  }
  return true;
}

float GltfPbrMaterial::coatWeightAt(const Params& p, float cosCoat) const {
  return coat_ && cosCoat > 0.0f ? p.clearcoat * schlickFresnel(kCoatF0, cosCoat) : 0.0f;
}

float GltfPbrMaterial::coatWeight(const Params& p, const Frames& f) const {
  return f.layers ? coatWeightAt(p, f.oc.z) : 0.0f;
}

GltfPbrMaterial::LobeProbabilities GltfPbrMaterial::lobeProbabilities(const Params& p,
                                                                      const Frames& f) const {
  const float cosO = f.o.z;
  // The layer's Fresnel term at n.v, capped below 1 inside a volume: past the critical angle most
  // visible microfacets reflect totally, but those tilted towards wo still refract, so the
  // transmission lobe must keep some probability.
  const float fd = std::min(p.specularWeight * maxOf(dielectricFresnel(p, cosO, f.outside)), 0.9f);
  const float fm = maxComponent(schlickFresnel(p.baseColor, cosO));
  const float dielectric = 1.0f - p.metallic;
  const float coat = coatWeight(p, f);
  const float sheen = sheen_ && f.layers ? maxOf(p.sheenColor) * sheenAlbedo(cosO, p.sheenRoughness) : 0.0f;
  const float under = (1.0f - coat) * std::max(0.0f, 1.0f - sheen);
  const float base = under * dielectric * (1.0f - fd) * maxComponent(p.baseColor);
  const float ws = under * (dielectric * fd + p.metallic * fm);
  const float wd = base * (1.0f - p.transmission);
  const float wt = base * p.transmission;
  const float wsh = (1.0f - coat) * sheen;
  const float sum = ws + wd + wt + wsh + coat;
  if (!(sum > 0.0f)) return {1.0f, 0.0f, 0.0f, 0.0f, 0.0f};
  return {ws / sum, wd / sum, wt / sum, wsh / sum, coat / sum};
}

Color GltfPbrMaterial::dielectricFresnel(const Params& p, float cosOH, bool outside) const {
  if (!refracts_ || outside) return schlickFresnel(p.specularF0, cosOH);
  // Inside a volume (eta_t / eta_i = 1 / ior): Snell's sin_t = ior sin_i; past the critical angle
  // everything is reflected, otherwise Schlick at the outside cosine (see the top comment).
  const float sin2T = std::max(0.0f, 1.0f - cosOH * cosOH) * ior_ * ior_;
  if (sin2T >= 1.0f) return Color(1.0f);
  return schlickFresnel(p.specularF0, std::sqrt(1.0f - sin2T));
}

void GltfPbrMaterial::reflectances(const Params& p, float cosOH, bool outside, Color& dielectric,
                                   Color& metal) const {
  dielectric = dielectricFresnel(p, cosOH, outside);
  metal = schlickFresnel(p.baseColor, cosOH);
  if (!(p.iridescence > 0.0f) || (refracts_ && !outside)) return;
  // The film lies on the outer surface, under the coat if there is one (whose ior, 1.5, is then
  // the outside medium's, as the extension says).
  const float outsideIor = p.clearcoat > 0.0f ? 1.5f : 1.0f;
  const float ior = inputs_.iridescenceIor;
  dielectric = glm::mix(dielectric, thinFilmFresnel(outsideIor, ior, cosOH, p.filmThickness, p.specularF0),
                        p.iridescence);
  metal =
      glm::mix(metal, thinFilmFresnel(outsideIor, ior, cosOH, p.filmThickness, p.baseColor), p.iridescence);
}

Color GltfPbrMaterial::evalBase(const Params& p, const LobeProbabilities& lobes, const Vec3& o, const Vec3& i,
                                bool reflection, bool outside, float& pdf) const {
  pdf = 0.0f;
  const Ggx& g = p.ggx;
  const float dielectric = 1.0f - p.metallic;
  if (reflection) {
    if (!(i.z > 0.0f)) return Color(0.0f);
    const Vec3 h = glm::normalize(o + i);  // o.z, i.z > 0: the sum is never zero
    const float cosOH = glm::dot(o, h);
    const float specular = g.D(h) * g.V(o, i);  // specular_brdf = D V (glTF B.3.2)
    Color fd, fm;
    reflectances(p, cosOH, outside, fd, fm);
    fd *= p.specularWeight;
    // mix(fresnel_mix(base, specular), conductor_fresnel(specular), metallic), base = the diffuse
    // part only (the BTDF is zero for a reflection).
    // A smooth surface's specular lobe is a Dirac delta (see the top comment): not evaluated here.
    const Color diffuse = dielectric * (1.0f - maxOf(fd)) * (1.0f - p.transmission) * kInvPi * p.baseColor;
    pdf = lobes.diffuse * cosineHemispherePdf(i.z);
    if (p.smooth) return diffuse * i.z;
    const Color f = diffuse + dielectric * fd * specular + p.metallic * specular * fm;
    pdf += lobes.specular * g.reflectionPdf(o, h);
    return f * i.z;
  }

  if (p.smooth || !(i.z < 0.0f) || !(p.transmission > 0.0f) || !(dielectric > 0.0f)) return Color(0.0f);
  const float scale = dielectric * p.transmission;
  if (!refracts_) {
    // Thin-walled: the reflection lobe of the mirrored direction (flip along the normal).
    const Vec3 m(i.x, i.y, -i.z);
    const Vec3 h = glm::normalize(o + m);
    Color fr, fm;
    reflectances(p, glm::dot(o, h), outside, fr, fm);
    const float fd = p.specularWeight * maxOf(fr);
    pdf = lobes.transmission * g.reflectionPdf(o, h);
    return (scale * (1.0f - fd) * g.D(h) * g.V(o, m) * m.z) * p.baseColor;
  }

  // Refraction (Walter et al. 2007). Generalised half vector h ~ -(eta_i wo + eta_t wi) (eq. 16),
  // turned to the +z side; a refracting microfacet is seen from wo's side and from wi's other side.
  const float eta = outside ? ior_ : 1.0f / ior_;
  Vec3 h = o + eta * i;
  const float len2 = glm::dot(h, h);  // (o.h + eta i.h)^2, the denominator of eqs. 17 and 21
  if (!(len2 > 1e-12f)) return Color(0.0f);
  h /= std::sqrt(len2);
  if (h.z < 0.0f) h = -h;
  const float cosOH = glm::dot(o, h), cosIH = glm::dot(i, h);
  if (!(cosOH > 0.0f) || !(cosIH < 0.0f)) return Color(0.0f);
  // Schlick at the outside cosine (see the top comment). Both cosines of a refracting pair are at
  // hand here, so the outside one is taken directly rather than through Snell's law, whose
  // cos_t = sqrt(1 - sin_t^2) loses precision near the critical angle: F is then exactly the same
  // for (wo, wi) and (wi, wo).
  const float F = p.specularWeight * maxOf(schlickFresnel(p.specularF0, outside ? cosOH : -cosIH));
  // Radiance BTDF times |cos_i|: (1 - F) D G2 |i.h| |o.h| / (|o.z| (o.h + eta i.h)^2) (Walter eq. 21
  // divided by eta^2). G2 / |o.z| = 2 |i.z| / (|i.z| root(o) + |o.z| root(i)) stays finite as o.z -> 0.
  const float ai = -i.z;
  const float g2OverCosO = 2.0f * ai / (ai * g.root(o) + o.z * g.root(i));
  // Jacobian of the refracted direction, d(h) / d(wi) = eta^2 |i.h| / (o.h + eta i.h)^2 (eq. 17).
  const float jacobian = eta * eta * -cosIH / len2;
  pdf = lobes.transmission * g.visibleNormalPdf(o, h) * jacobian;
  return (scale * (1.0f - F) * g.D(h) * g2OverCosO * -cosIH * cosOH / len2) * p.baseColor;
}

float GltfPbrMaterial::baseScale(const Params& p, const Frames& f, float iz) const {
  if (!f.layers) return 1.0f;
  float scale = 1.0f;
  if (sheen_) {
    // Albedo scaling of the base (Estevez & Kulla 2017, section 4; the extension's
    // sheenAlbedoScaling), clamped at 0: towards grazing angles E exceeds 1 (materials/sheen.h).
    const float m = maxOf(p.sheenColor);
    scale = std::max(0.0f, std::min(1.0f - m * sheenAlbedo(f.o.z, p.sheenRoughness),
                                    1.0f - m * sheenAlbedo(iz, p.sheenRoughness)));
  }
  if (coat_) scale *= 1.0f - coatWeight(p, f);
  return scale;
}

float GltfPbrMaterial::outerLayerScale(const Params& p, float cosBase, float cosCoat) const {
  float scale = 1.0f;
  if (sheen_) scale = std::max(0.0f, 1.0f - maxOf(p.sheenColor) * sheenAlbedo(cosBase, p.sheenRoughness));
  if (coat_) scale *= 1.0f - coatWeightAt(p, cosCoat);
  return scale;
}

Color GltfPbrMaterial::evalLayers(const Params& p, const LobeProbabilities& lobes, const Frames& f,
                                  const SurfaceHit& hit, const Vec3& wo, const Vec3& wi, float& pdf) const {
  const bool reflection = sameSide(hit, wo, wi);
  const Vec3 i = f.base.toLocal(wi);
  Color result = evalBase(p, lobes, f.o, i, reflection, f.outside, pdf) * baseScale(p, f, i.z);
  if (!f.layers) return result;
  const float coat = coatWeight(p, f);
  if (sheen_ && reflection && i.z > 0.0f) {
    result += (1.0f - coat) * CharlieSheen(p.sheenRoughness).evalCos(f.o, i) * p.sheenColor;
    pdf += lobes.sheen * (0.5f * kInvPi);
  }
  if (coat_ && !p.coatSmooth) {
    const Vec3 ic = f.coat.toLocal(wi);
    if (reflection && coat > 0.0f && ic.z > 0.0f) {
      const Vec3 h = glm::normalize(f.oc + ic);
      result += Color(coat * p.coatGgx.D(h) * p.coatGgx.V(f.oc, ic) * ic.z);
      pdf += lobes.coat * p.coatGgx.reflectionPdf(f.oc, h);
    }
  }
  return result;
}

Color GltfPbrMaterial::evalAndPdf(const SurfaceHit& hit, const Vec3& wo, const Vec3& wi, float& pdf) const {
  pdf = 0.0f;
  const Params& p = fetchFor(hit);
  Frames f;
  if (!frames(hit, wo, p, f)) return Color(0.0f);
  return evalLayers(p, lobeProbabilities(p, f), f, hit, wo, wi, pdf);
}

Color GltfPbrMaterial::eval(const SurfaceHit& hit, const Vec3& wo, const Vec3& wi) const {
  float pdf;
  return evalAndPdf(hit, wo, wi, pdf);
}

float GltfPbrMaterial::pdf(const SurfaceHit& hit, const Vec3& wo, const Vec3& wi) const {
  float pdf;
  evalAndPdf(hit, wo, wi, pdf);
  return pdf;
}

bool GltfPbrMaterial::sample(const SurfaceHit& hit, const Vec3& wo, Vec2 u, float uLobe,
                             BsdfSample& out) const {
  const Params& p = fetchFor(hit);
  Frames f;
  if (!frames(hit, wo, p, f)) return false;
  const LobeProbabilities lobes = lobeProbabilities(p, f);
  const Vec3& o = f.o;

  // The lobes in the order coat, sheen, specular, diffuse, transmission along uLobe; rounding that
  // leaves uLobe past the last one of non-zero probability falls back to it.
  Vec3 wi;
  bool transmit = false;
  float eta = 1.0f;
  float edge = lobes.coat;
  if (uLobe < edge) {
    if (p.coatSmooth) return sampleDelta(p, lobes, f, hit, wo, 0, out);
    const Vec3 ic = reflect(f.oc, p.coatGgx.sampleVisibleNormal(f.oc, u));
    if (!(ic.z > 0.0f)) return false;  // under the coat's horizon: absorbed, as the base's lobes
    wi = f.coat.toWorld(ic);
  } else if (uLobe < (edge += lobes.sheen)) {
    const Vec3 d = sampleCosineHemisphere(u);
    // Uniform in the hemisphere: the cosine-weighted direction's polar angle remapped,
    // cos theta = 1 - (1 - cos theta_c^2) (an equal-area map: cos^2 is uniform, so is 1 - cos^2).
    const float sin2 = d.x * d.x + d.y * d.y;
    const float cosT = 1.0f - sin2;
    const float scale = sin2 > 0.0f ? std::sqrt(std::max(0.0f, 1.0f - cosT * cosT) / sin2) : 0.0f;
    wi = f.base.toWorld(Vec3(d.x * scale, d.y * scale, cosT));
  } else {
    const float rest = uLobe - edge;
    const bool specular = rest < lobes.specular || (!(lobes.diffuse > 0.0f) && !(lobes.transmission > 0.0f));
    const bool diffuse = !specular && (rest < lobes.specular + lobes.diffuse || !(lobes.transmission > 0.0f));
    if (p.smooth && !diffuse) return sampleDelta(p, lobes, f, hit, wo, specular ? 1 : 2, out);
    Vec3 i;
    if (specular) {
      i = reflect(o, p.ggx.sampleVisibleNormal(o, u));
    } else if (diffuse) {
      i = sampleCosineHemisphere(u);
    } else {
      transmit = true;
      const Vec3 h = p.ggx.sampleVisibleNormal(o, u);
      if (refracts_) {
        eta = f.outside ? ior_ : 1.0f / ior_;
        if (!refract(o, h, eta, i)) return false;  // total internal reflection on this microfacet
      } else {
        i = reflect(o, h);
        i.z = -i.z;
      }
    }
    // A direction outside its lobe's hemisphere is absorbed (see the top comment).
    if (transmit ? !(i.z < 0.0f) : !(i.z > 0.0f)) return false;
    wi = f.base.toWorld(i);
  }
  out.wi = glm::normalize(wi);
  const bool reflection = sameSide(hit, wo, out.wi);
  if (reflection == transmit) return false;  // crossed the geometric surface the wrong way

  // The same evaluation as eval() and pdf() on the returned direction, so the three agree exactly.
  const Color fval = evalLayers(p, lobes, f, hit, wo, out.wi, out.pdf);
  if (!(out.pdf > 0.0f)) return false;
  out.weight = fval / out.pdf;
  out.delta = false;
  out.eta = transmit ? eta : 1.0f;
  return true;
}

bool GltfPbrMaterial::sampleDelta(const Params& p, const LobeProbabilities& lobes, const Frames& f,
                                  const SurfaceHit& hit, const Vec3& wo, int lobe, BsdfSample& out) const {
  // Each lobe's alpha -> 0 limit (see the top comment).
  Color value;
  float probability, eta = 1.0f;
  Vec3 wi;
  if (lobe == 0) {
    wi = f.coat.toWorld(Vec3(-f.oc.x, -f.oc.y, f.oc.z));
    value = Color(coatWeight(p, f));
    probability = lobes.coat;
  } else {
    const Vec3& o = f.o;
    const float dielectric = 1.0f - p.metallic;
    Color fd, fm;
    reflectances(p, o.z, f.outside, fd, fm);
    Vec3 i;
    if (lobe == 1) {
      i = Vec3(-o.x, -o.y, o.z);
      value = dielectric * p.specularWeight * fd + p.metallic * fm;
      probability = lobes.specular;
    } else {
      const float scale = dielectric * p.transmission;
      if (!refracts_) {
        i = -o;
        value = (scale * (1.0f - p.specularWeight * maxOf(fd))) * p.baseColor;
      } else {
        eta = f.outside ? ior_ : 1.0f / ior_;
        // Total internal reflection: the specular lobe, with F = 1, carries it.
        if (!refract(o, Vec3(0.0f, 0.0f, 1.0f), eta, i)) return false;
        const float F = p.specularWeight * maxOf(schlickFresnel(p.specularF0, f.outside ? o.z : -i.z));
        value = (scale * (1.0f - F) / (eta * eta)) * p.baseColor;
        // The sheen and the coat lie on the outer surface, which light crosses whichever way it
        // goes: weighed at the outside direction's cosines from both sides, so that a pair taken
        // camera side first (the path tracer) or light side first (the light tracer, which owns
        // these caustics) carries the same factor.
        const Vec3 outsideDir = f.outside ? wo : f.base.toWorld(i);
        value *= outerLayerScale(p, f.outside ? o.z : -i.z, glm::dot(outsideDir, p.coatNormal));
      }
      probability = lobes.transmission;
    }
    if (lobe != 2 || !refracts_) value *= baseScale(p, f, i.z);
    wi = f.base.toWorld(i);
  }
  if (!(probability > 0.0f)) return false;
  out.wi = glm::normalize(wi);
  if (sameSide(hit, wo, out.wi) == (lobe == 2)) return false;  // crossed the geometric surface the wrong way
  out.weight = value / probability;
  out.pdf = probability;
  out.delta = true;
  out.eta = lobe == 2 ? eta : 1.0f;
  return true;
}

}  // namespace ember
