// The Khronos material layers of GltfPbrMaterial (materials/gltf_pbr.h) against their definitions:
//
//  - pointwise, against formulas written here from the extension texts and papers in double
//    precision, sharing no code with the material: KHR_materials_specular's fresnel_mix, the
//    Charlie sheen of KHR_materials_sheen (Estevez & Kulla 2017) with its albedo scaling,
//    KHR_materials_clearcoat's fresnel_coat over the base, and KHR_materials_iridescence's thin
//    film (Belcour & Barla 2017) in the dielectric's and the metal's Fresnel;
//  - the sheen's directional albedo table against a finer quadrature of the definition;
//  - energy: white layers over a white diffuse base reflect at most what they receive (the
//    albedo scaling's purpose), measured by the Monte Carlo mean of sample() weights;
//  - reciprocity where the definitions have it (specular, sheen: the albedo scaling takes the
//    minimum over both directions, so it is symmetric); the coat weight reads n_c.v alone and is
//    not, as the extension defines it.
// Sampling against the pdf is tests/test_chi2.cpp (GltfSpecular_*, GltfSheen_*, GltfCoat_*,
// GltfLayers_*).

#include "core/rng.h"
#include "materials/gltf_pbr.h"
#include "materials/iridescence.h"
#include "materials/sheen.h"
#include "materials/texture.h"

#include <gtest/gtest.h>

#include "mc_mean.h"
#include "test_fixtures.h"

#include <cmath>
#include <memory>
#include <numbers>
#include <string>

namespace ember {
namespace {

constexpr double kPiD = std::numbers::pi;

std::shared_ptr<const Texture> constant(const Color& c) {
  return std::make_shared<ConstantTexture>(c);
}

struct Layers {
  Color base{0.5f, 0.4f, 0.3f};
  float roughness = 0.5f, metallic = 0.0f;
  float specular = 1.0f;
  Color specularColor{1.0f};
  Color sheen{0.0f};
  float sheenRoughness = 0.5f;
  float coat = 0.0f, coatRoughness = 0.2f;
  float iridescence = 0.0f, filmIor = 1.3f, filmThickness = 400.0f;
};

std::shared_ptr<GltfPbrMaterial> make(const Layers& l) {
  GltfPbrInputs in;
  in.baseColor = constant(l.base);
  in.metallicRoughness = constant(Color(0.0f, l.roughness, l.metallic));
  in.specular = constant(Color(l.specular));
  in.specularColor = constant(l.specularColor);
  if (!isBlack(l.sheen)) {
    in.sheenColor = constant(l.sheen);
    in.sheenRoughness = constant(Color(l.sheenRoughness));
  }
  if (l.coat > 0.0f) {
    in.clearcoat = constant(Color(l.coat));
    in.clearcoatRoughness = constant(Color(l.coatRoughness));
  }
  if (l.iridescence > 0.0f) {
    in.iridescence = constant(Color(l.iridescence));
    in.iridescenceIor = l.filmIor;
    in.iridescenceThicknessMax = l.filmThickness;
  }
  return std::make_shared<GltfPbrMaterial>(std::move(in));
}

// --- The definitions, in double precision, local frame n = +z ---------------------------------

using D3 = glm::dvec3;

double schlick(double f0, double cosTheta) {
  return f0 + (1.0 - f0) * std::pow(1.0 - std::abs(cosTheta), 5.0);
}

// glTF 2.0 Appendix B.3.2: D_GGX and V_GGX (the height-correlated Smith visibility).
double ggxD(double nh, double alpha) {
  const double a2 = alpha * alpha, t = nh * nh * (a2 - 1.0) + 1.0;
  return nh > 0.0 ? a2 / (kPiD * t * t) : 0.0;
}
double ggxV(double nl, double nv, double alpha) {
  const double a2 = alpha * alpha;
  const double gv = nl * std::sqrt(nv * nv * (1.0 - a2) + a2), gl = nv * std::sqrt(nl * nl * (1.0 - a2) + a2);
  return gv + gl > 0.0 ? 0.5 / (gv + gl) : 0.0;
}

// KHR_materials_sheen, "Sheen distribution" and "Sheen visibility" (alphaG = sheenRoughness^2).
double charlieD(double nh, double alpha) {
  const double invR = 1.0 / alpha, sin2h = 1.0 - nh * nh;
  return (2.0 + invR) * std::pow(std::max(sin2h, 0.0), invR * 0.5) / (2.0 * kPiD);
}
double sheenL(double x, double alpha) {
  const double t = (1.0 - alpha) * (1.0 - alpha);
  const auto mix = [t](double a, double b) { return a * (1.0 - t) + b * t; };
  const double a = mix(21.5473, 25.3245), b = mix(3.82987, 3.32435), c = mix(0.19823, 0.16801),
               d = mix(-1.97760, -1.27393), e = mix(-4.32054, -4.85967);
  return a / (1.0 + b * std::pow(x, c)) + d * x + e;
}
double sheenLambda(double cosTheta, double alpha) {
  return std::abs(cosTheta) < 0.5 ? std::exp(sheenL(cosTheta, alpha))
                                  : std::exp(2.0 * sheenL(0.5, alpha) - sheenL(1.0 - cosTheta, alpha));
}
double sheenV(double nl, double nv, double alpha) {
  return 1.0 / ((1.0 + sheenLambda(nv, alpha) + sheenLambda(nl, alpha)) * (4.0 * nv * nl));
}
// E(mu) of the white Charlie lobe by midpoint quadrature over the whole azimuth, n x 2n points,
// with cos theta_i = t^3 (points dense at the horizon, where the lobe peaks): d(cos) = 3 t^2 dt.
double sheenAlbedoDefinition(double mu, double roughness, int n) {
  const double alpha = roughness * roughness;
  const D3 v(std::sqrt(1.0 - mu * mu), 0.0, mu);
  double sum = 0.0;
  for (int a = 0; a < n; ++a) {
    const double t = (a + 0.5) / n, ci = t * t * t, si = std::sqrt(1.0 - ci * ci);
    for (int b = 0; b < 2 * n; ++b) {
      const double phi = 2.0 * kPiD * (b + 0.5) / (2 * n);
      const D3 l(si * std::cos(phi), si * std::sin(phi), ci);
      const D3 h = glm::normalize(v + l);
      sum += 3.0 * t * t * charlieD(h.z, alpha) * sheenV(l.z, v.z, alpha) * l.z;
    }
  }
  return sum * 2.0 * kPiD / (double(n) * 2.0 * n);
}

// KHR_materials_iridescence's implementation notes (Belcour & Barla 2017): the thin-film
// reflectance, written from the extension's pseudo-code in double precision, with the optical path
// difference inside the film (cos theta_2, as Belcour & Barla's own code has it).
glm::dvec3 thinFilm(double n1, double n2Film, double cos1, double d, const glm::dvec3& f0) {
  const double t = std::clamp(d / 30.0, 0.0, 1.0);
  const double n2 = n1 + (n2Film - n1) * t * t * (3.0 - 2.0 * t);  // the sample viewer's fade to no film
  const double sin2 = (n1 / n2) * (n1 / n2) * (1.0 - cos1 * cos1);
  if (sin2 >= 1.0) return glm::dvec3(1.0);
  const double cos2 = std::sqrt(1.0 - sin2);
  const auto f0Of = [](double nt, double ni) { return (nt - ni) * (nt - ni) / ((nt + ni) * (nt + ni)); };
  const double r12 = schlick(f0Of(n2, n1), cos1), t121 = 1.0 - r12;
  glm::dvec3 n3, r23, phi;
  for (int k = 0; k < 3; ++k) {
    const double s = std::sqrt(std::min(f0[k] + 1e-4, 0.9999));
    n3[k] = (1.0 + s) / (1.0 - s);
    r23[k] = schlick(f0Of(n3[k], n2), cos2);
    phi[k] = (n2 < n1 ? 0.0 : kPiD) + (n3[k] < n2 ? kPiD : 0.0);
  }
  const double opd = 2.0 * n2 * d * cos2;
  const glm::dvec3 r123 = glm::clamp(r12 * r23, 1e-5, 0.9999);
  const glm::dvec3 rs = t121 * t121 * r23 / (1.0 - r123);
  glm::dvec3 I = r12 + rs, cm = rs - t121;
  for (int m = 1; m <= 2; ++m) {
    cm *= glm::sqrt(r123);
    const double phase = 2.0 * kPiD * m * opd * 1e-9;
    const double val[3] = {5.4856e-13, 4.4201e-13, 5.2481e-13}, pos[3] = {1.6810e+06, 1.7953e+06, 2.2084e+06},
                 var[3] = {4.3278e+09, 9.3046e+09, 6.6121e+09};
    glm::dvec3 xyz;
    for (int k = 0; k < 3; ++k)
      xyz[k] = val[k] * std::sqrt(2.0 * kPiD * var[k]) * std::cos(pos[k] * phase + m * phi[k]) *
               std::exp(-phase * phase * var[k]);
    xyz.x += 9.7470e-14 * std::sqrt(2.0 * kPiD * 4.5282e+09) * std::cos(2.2399e+06 * phase + m * phi[0]) *
             std::exp(-4.5282e+09 * phase * phase);
    xyz /= 1.0685e-7;
    const glm::dvec3 rgb(3.2404542 * xyz.x - 1.5371385 * xyz.y - 0.4985314 * xyz.z,
                         -0.9692660 * xyz.x + 1.8760108 * xyz.y + 0.0415560 * xyz.z,
                         0.0556434 * xyz.x - 0.2040259 * xyz.y + 1.0572252 * xyz.z);
    I += cm * 2.0 * rgb;
  }
  return glm::clamp(I, glm::dvec3(0.0), glm::dvec3(1.0));  // Ember's clamp at 1 (iridescence.h)
}

// The whole layered definition, f cos(theta_l), for an opaque dielectric or metal with all four
// extensions (gltf_pbr.h's formulas; each from its extension text).
glm::dvec3 definition(const Layers& L, const D3& v, const D3& l) {
  if (!(v.z > 0.0) || !(l.z > 0.0)) return glm::dvec3(0.0);
  const D3 h = glm::normalize(v + l);
  const double vh = glm::dot(v, h);
  const double alpha = double(L.roughness) * L.roughness;
  const double spec = ggxD(h.z, alpha) * ggxV(l.z, v.z, alpha);
  const glm::dvec3 base(L.base);
  // KHR_materials_specular: f0 = min(0.04 specularColor, 1), fresnel_mix with weight w.
  glm::dvec3 fr;
  glm::dvec3 f0d;
  for (int k = 0; k < 3; ++k) f0d[k] = std::min(0.04 * L.specularColor[k], 1.0);
  for (int k = 0; k < 3; ++k) fr[k] = schlick(f0d[k], vh);
  const double outsideIor = L.coat > 0.0f ? 1.5 : 1.0;
  if (L.iridescence > 0.0f)
    fr = glm::mix(fr, thinFilm(outsideIor, L.filmIor, vh, L.filmThickness, f0d), double(L.iridescence));
  const double w = L.specular;
  const double frMax = std::max(fr.x, std::max(fr.y, fr.z));
  const glm::dvec3 dielectric = (1.0 - w * frMax) * base / kPiD + w * fr * spec;
  glm::dvec3 fm;
  for (int k = 0; k < 3; ++k) fm[k] = schlick(base[k], vh);
  if (L.iridescence > 0.0f)
    fm = glm::mix(fm, thinFilm(outsideIor, L.filmIor, vh, L.filmThickness, base), double(L.iridescence));
  glm::dvec3 f = (1.0 - L.metallic) * dielectric + double(L.metallic) * fm * spec;
  // KHR_materials_sheen with albedo scaling.
  if (!isBlack(L.sheen)) {
    const double r = std::max(double(L.sheenRoughness), double(CharlieSheen::kMinRoughness));
    const double sMax = std::max(L.sheen.x, std::max(L.sheen.y, L.sheen.z));
    const double scaling = std::max(0.0, std::min(1.0 - sMax * sheenAlbedoDefinition(v.z, r, 128),
                                                  1.0 - sMax * sheenAlbedoDefinition(l.z, r, 128)));
    f = glm::dvec3(L.sheen) * charlieD(h.z, r * r) * sheenV(l.z, v.z, r * r) + f * scaling;
  }
  // KHR_materials_clearcoat: fresnel_coat(n, 1.5, clearcoat, base, clearcoat_brdf), n.v.
  if (L.coat > 0.0f) {
    const double ac = double(L.coatRoughness) * L.coatRoughness;
    const double coatBrdf = ggxD(h.z, ac) * ggxV(l.z, v.z, ac);
    const double weight = L.coat * schlick(0.04, v.z);
    f = f * (1.0 - weight) + glm::dvec3(weight * coatBrdf);
  }
  return f * l.z;
}

Vec3 randomUpper(Rng& rng) {
  const float z = 0.05f + 0.95f * rng.uniform(), phi = 2.0f * kPi * rng.uniform();
  const float s = std::sqrt(1.0f - z * z);
  return Vec3(s * std::cos(phi), s * std::sin(phi), z);
}

void expectNear(const Color& got, const glm::dvec3& want, double relTol, const std::string& what) {
  for (int k = 0; k < 3; ++k)
    EXPECT_NEAR(got[k], want[k], relTol * std::abs(want[k]) + 1e-6) << what << " channel " << k;
}

// --- Tests ---------------------------------------------------------------------------------------

// Each layer alone, then all together, equals its definition at random direction pairs. The
// sheen's albedo table is bilinear, so the tolerance allows its interpolation error (the next test
// bounds it); the rest agree to float rounding.
TEST(GltfLayers, MatchTheKhronosDefinitionsPointwise) {
  const SurfaceHit hit = test::flatHit();
  struct Case {
    const char* name;
    Layers layers;
    double tol;
  };
  Layers specular;
  specular.specular = 0.6f;
  specular.specularColor = Color(3.0f, 1.0f, 0.2f);  // factors above 1, as SpecularTest has
  Layers sheen;
  sheen.sheen = Color(0.9f, 0.4f, 0.2f);
  sheen.sheenRoughness = 0.45f;
  Layers coat;
  coat.coat = 0.8f;
  coat.coatRoughness = 0.15f;
  Layers film;
  film.roughness = 0.3f;
  film.iridescence = 0.8f;
  film.filmThickness = 450.0f;
  Layers filmMetal = film;
  filmMetal.metallic = 0.7f;
  filmMetal.filmIor = 1.8f;
  Layers all = sheen;
  all.metallic = 0.3f;
  all.specular = 0.7f;
  all.specularColor = Color(1.2f, 1.0f, 0.8f);
  all.coat = 0.6f;
  all.coatRoughness = 0.3f;
  all.iridescence = 0.5f;
  for (const Case& c :
       {Case{"specular", specular, 2e-4}, Case{"sheen", sheen, 1e-2}, Case{"coat", coat, 2e-4},
        Case{"iridescence", film, 2e-4}, Case{"iridescent metal", filmMetal, 2e-4}, Case{"all", all, 1e-2}}) {
    const auto m = make(c.layers);
    Rng rng(7, 3);
    for (int k = 0; k < 200; ++k) {
      const Vec3 wo = randomUpper(rng), wi = randomUpper(rng);
      expectNear(m->eval(hit, wo, wi), definition(c.layers, D3(wo), D3(wi)), c.tol,
                 std::string(c.name) + " at sample " + std::to_string(k));
    }
  }
}

// The sheen's E(mu, roughness) table against the definition's own quadrature at a finer
// resolution, between and on its nodes: within 1% or 2e-3. (E reaches 2 at grazing angles.)
TEST(GltfLayers, SheenAlbedoTableMatchesQuadrature) {
  for (double roughness : {0.07, 0.2, 0.45, 0.73, 1.0})
    for (double mu : {0.02, 0.1, 0.33, 0.5, 0.71, 0.97}) {
      const double want = sheenAlbedoDefinition(mu, roughness, 400);
      EXPECT_NEAR(sheenAlbedo(float(mu), float(roughness)), want, std::max(2e-3, 0.01 * want))
          << "roughness " << roughness << ", cos " << mu;
    }
}

// White sheen and white coat over a white diffuse base (no specular lobe: specular weight 0)
// reflect at most all light: the albedo scaling and the coat's mix take from the base what the
// layer adds. With a dark sheen the base keeps almost everything.
TEST(GltfLayers, LayersOverAWhiteBaseConserveEnergy) {
  const SurfaceHit hit = test::flatHit();
  Layers sheen;
  sheen.base = Color(1.0f);
  sheen.specular = 0.0f;
  sheen.sheen = Color(1.0f);
  sheen.sheenRoughness = 0.6f;
  Layers coat = sheen;
  coat.sheen = Color(0.0f);
  coat.coat = 1.0f;
  coat.coatRoughness = 0.3f;
  Layers both = sheen;
  both.coat = 1.0f;
  for (const auto& [name, layers] :
       {std::pair{"sheen", sheen}, std::pair{"coat", coat}, std::pair{"both", both}}) {
    const auto m = make(layers);
    for (float mu : {0.15f, 0.5f, 0.95f}) {
      const Vec3 wo(std::sqrt(1.0f - mu * mu), 0.0f, mu);
      Rng rng(11, 5);
      test::McMean albedo;
      for (int k = 0; k < 200000; ++k) {
        BsdfSample s;
        const bool ok = m->sample(hit, wo, Vec2(rng.uniform(), rng.uniform()), rng.uniform(), s);
        albedo.add(ok ? double(s.weight.x) : 0.0);
      }
      EXPECT_LE(albedo.mean(), 1.0 + albedo.tolerance(1e-4)) << name << " at cos " << mu;
      EXPECT_GT(albedo.mean(), 0.85) << name << " at cos " << mu << ": the layers should lose little";
    }
  }
}

// The thin film's limits: a film thinning to nothing is nearly no film (Schlick's reflectance of
// the base alone, within 0.04: the approximation's first interface keeps Schlick's (1 - cos)^5
// even when index-matched, and its interference terms scale with the root of that), and a
// reflectance stays in [0, 1].
TEST(GltfLayers, ThinFilmLimits) {
  for (float cos : {0.7f, 0.9f, 1.0f})
    for (const Color& f0 : {Color(0.04f), Color(0.9f, 0.6f, 0.3f)}) {
      const Color none = thinFilmFresnel(1.0f, 1.3f, cos, 0.0f, f0);
      for (int k = 0; k < 3; ++k) EXPECT_NEAR(none[k], schlickFresnel(f0[k], cos), 0.04f) << cos << " " << k;
      for (float d : {50.0f, 250.0f, 500.0f, 1200.0f}) {
        const Color f = thinFilmFresnel(1.0f, 1.5f, cos, d, f0);
        for (int k = 0; k < 3; ++k) {
          EXPECT_GE(f[k], 0.0f);
          EXPECT_LE(f[k], 1.0f + 1e-3f) << "cos " << cos << ", thickness " << d;
        }
      }
    }
}

// A mesh point with normal +z and tangent (1, 0, 0), bitangent sign w: the frame in which the
// anisotropy direction is given.
struct TangentFrame final : VertexAttributes {
  float w = 1.0f;
  Vec2 texCoordAt(int, uint32_t, Vec2 b) const override { return b; }
  glm::vec4 colorAt(uint32_t, Vec2) const override { return glm::vec4(1.0f); }
  Vec3 normalAt(uint32_t, Vec2) const override { return Vec3(0.0f, 0.0f, 1.0f); }
  glm::vec4 tangentAt(uint32_t, Vec2) const override { return glm::vec4(1.0f, 0.0f, 0.0f, w); }
};

// KHR_materials_anisotropy: a metal's f cos equals the extension's D_GGX_anisotropic and
// V_GGX_anisotropic (written here from its implementation section, the V without its clamp, as
// Appendix B's isotropic V has none) with alpha_t = mix(alpha, 1, strength^2) along the direction
// rotated from the tangent by anisotropyRotation, towards the bitangent of either handedness.
TEST(GltfLayers, AnisotropyMatchesTheKhronosDefinition) {
  for (const float w : {1.0f, -1.0f}) {
    TangentFrame frame;
    frame.w = w;
    SurfaceHit hit = test::flatHit();
    hit.attributes = &frame;
    GltfPbrInputs in;
    in.baseColor = constant(Color(0.9f, 0.6f, 0.3f));
    in.metallicRoughness = constant(Color(0.0f, 0.35f, 1.0f));
    in.anisotropyStrength = 0.7f;
    in.anisotropyRotation = 0.5f;
    const GltfPbrMaterial m(in);
    const double alpha = 0.35 * 0.35, at = alpha + (1.0 - alpha) * 0.49, ab = alpha;
    const D3 t(std::cos(0.5), w * std::sin(0.5), 0.0);  // B = cross(N, T) w = w y
    const D3 b = glm::cross(D3(0, 0, 1), t);
    Rng rng(17, 2);
    for (int k = 0; k < 300; ++k) {
      const D3 v(randomUpper(rng)), l(randomUpper(rng));
      const D3 h = glm::normalize(v + l);
      const double a2 = at * ab;
      const D3 f(ab * glm::dot(t, h), at * glm::dot(b, h), a2 * h.z);
      const double w2 = a2 / glm::dot(f, f);
      const double D = a2 * w2 * w2 / kPiD;
      const double gv = l.z * glm::length(D3(at * glm::dot(t, v), ab * glm::dot(b, v), v.z));
      const double gl = v.z * glm::length(D3(at * glm::dot(t, l), ab * glm::dot(b, l), l.z));
      const double V = 0.5 / (gv + gl);
      glm::dvec3 want;
      for (int c = 0; c < 3; ++c)
        want[c] = schlick(in.baseColor->maxValue()[c], glm::dot(v, h)) * D * V * l.z;
      expectNear(m.eval(hit, Vec3(v), Vec3(l)), want, 2e-4, "anisotropy, w " + std::to_string(w));
    }
  }
}

// A white anisotropic metal reflects at most all light, and no less than its roughest direction
// alone would: between the isotropic albedos at alpha = 1 and at its own roughness.
TEST(GltfLayers, AnisotropicWhiteMetalStaysWithinItsIsotropicBounds) {
  TangentFrame frame;
  SurfaceHit hit = test::flatHit();
  hit.attributes = &frame;
  const auto albedo = [&](float roughness, float strength, float mu) {
    GltfPbrInputs in;
    in.baseColor = constant(Color(1.0f));
    in.metallicRoughness = constant(Color(0.0f, roughness, 1.0f));
    in.anisotropyStrength = strength;
    const GltfPbrMaterial m(in);
    const Vec3 wo(std::sqrt(1.0f - mu * mu), 0.0f, mu);
    Rng rng(23, 4);
    test::McMean mean;
    for (int k = 0; k < 100000; ++k) {
      BsdfSample s;
      mean.add(m.sample(hit, wo, Vec2(rng.uniform(), rng.uniform()), rng.uniform(), s) ? double(s.weight.x)
                                                                                       : 0.0);
    }
    return mean;
  };
  for (float mu : {0.3f, 0.8f}) {
    const test::McMean aniso = albedo(0.3f, 0.8f, mu), smooth = albedo(0.3f, 0.0f, mu),
                       rough = albedo(1.0f, 0.0f, mu);
    EXPECT_LE(aniso.mean(), smooth.mean() + aniso.tolerance() + smooth.tolerance()) << "cos " << mu;
    EXPECT_GE(aniso.mean(), rough.mean() - aniso.tolerance() - rough.tolerance()) << "cos " << mu;
    EXPECT_LE(aniso.mean(), 1.0 + aniso.tolerance(1e-4)) << "cos " << mu;
  }
}

// f(wo, wi) = f(wi, wo) for the specular and sheen layers (their scaling is symmetric by the min).
TEST(GltfLayers, SpecularAndSheenAreReciprocal) {
  const SurfaceHit hit = test::flatHit();
  Layers l;
  l.specular = 0.5f;
  l.specularColor = Color(2.0f, 1.0f, 0.5f);
  l.sheen = Color(0.7f, 0.5f, 0.9f);
  const auto m = make(l);
  Rng rng(3, 9);
  for (int k = 0; k < 500; ++k) {
    const Vec3 a = randomUpper(rng), b = randomUpper(rng);
    const Color fab = m->eval(hit, a, b) / b.z, fba = m->eval(hit, b, a) / a.z;
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(fab[c], fba[c], 3e-4f * std::max(fab[c], fba[c]) + 1e-7f) << k;
  }
}

// Without the extensions' inputs the material is Appendix B: a specular weight of 1 and a white
// specular colour change nothing, bit for bit.
TEST(GltfLayers, NeutralExtensionInputsChangeNothing) {
  const SurfaceHit hit = test::flatHit();
  GltfPbrInputs plain;
  plain.baseColor = constant(Color(0.6f, 0.3f, 0.2f));
  plain.metallicRoughness = constant(Color(0.0f, 0.4f, 0.25f));
  GltfPbrInputs neutral = plain;
  neutral.specular = constant(Color(1.0f));
  neutral.specularColor = constant(Color(1.0f));
  neutral.clearcoat = constant(Color(0.0f));
  const GltfPbrMaterial a(plain), b(neutral);
  Rng rng(5, 1);
  for (int k = 0; k < 300; ++k) {
    const Vec3 wo = randomUpper(rng), wi = randomUpper(rng);
    const Color fa = a.eval(hit, wo, wi), fb = b.eval(hit, wo, wi);
    EXPECT_EQ(fa, fb) << k;
    EXPECT_EQ(a.pdf(hit, wo, wi), b.pdf(hit, wo, wi)) << k;
  }
}

}  // namespace
}  // namespace ember
