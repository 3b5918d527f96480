// Energy, reciprocity and robustness tests of the glTF 2.0 metallic-roughness material
// (materials/gltf_pbr.h) at a surface point with ng = ns = +z. Its sampling is checked against its
// pdf by tests/test_chi2.cpp; here:
//
//  - White furnace (directional albedo E(wo) = integral of eval over the sphere), two ways: a
//    deterministic quadrature of eval() and the Monte Carlo mean of sample() weights. The
//    quadrature splits the hemisphere between two analytic densities written here from the
//    papers, not taken from the material: cosine (1 / pi cos) and GGX normals (D(h) n.h, mapped
//    to wi by the reflection Jacobian 1 / (4 |wo.h|), Walter et al. 2007 eq. 14), with the balance
//    heuristic as partition of unity, each part a midpoint rule in its own warped square. That
//    resolves both the smooth diffuse part and lobes as narrow as alpha = 0.0025.
//  - Metal with F = 1 (baseColor 1): E is the single-scattering albedo of GGX with the
//    height-correlated Smith term, E = integral of D_wo(h) G2 / G1 over visible normals whose
//    reflection stays above the horizon. The reference values were computed with an independent
//    double-precision quadrature of that integral (4096^2 midpoints in the same GGX warp); at
//    normal incidence and alpha = 1 it has the closed form 1 - ln 2 = 0.3069: D = 1 / pi is
//    uniform, only half vectors within 45 degrees reflect above the horizon, and there
//    G2 = (1 - 2u) / (1 - u) with u = sin^2 theta_h uniform, whose integral over [0, 1/2] is
//    1 - ln 2. (The loss of single-scattering microfacet models at high roughness is the subject of
//    Kulla & Conty 2017, "Revisiting Physically Based Shading at Imageworks", and Heitz et al. 2016,
//    "Multiple-Scattering Microfacet BSDFs with the Smith Model".)
//  - The Appendix B dielectric matches independent values (and exceeds 1 towards grazing, as
//    specified); thin-walled transmission plus reflection add up to exactly the F = 1 metal lobe
//    (F + (1 - F) = 1 per microfacet); the volumetric interface conserves energy once the
//    1 / eta^2 radiance scaling of refraction is taken out.
//  - Reciprocity (Helmholtz for reflection, the eta^2-generalised form for refraction).
//  - Finite, non-negative eval / pdf / sample weights for random and degenerate directions.

#include "core/rng.h"
#include "materials/gltf_pbr.h"
#include "materials/texture.h"

#include <gtest/gtest.h>

#include "mc_mean.h"
#include "test_fixtures.h"

#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <numbers>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

namespace ember {
namespace {

constexpr double kPiD = std::numbers::pi;

struct PbrConfig {
  Color baseColor{1.0f};
  float roughness = 0.5f, metallic = 0.0f, transmission = 0.0f;
  bool thinWalled = true;
  float ior = 1.5f;
};

std::shared_ptr<GltfPbrMaterial> makePbr(const PbrConfig& c) {
  GltfPbrInputs in;
  in.baseColor = std::make_shared<ConstantTexture>(c.baseColor);
  in.metallicRoughness = std::make_shared<ConstantTexture>(Color(0.0f, c.roughness, c.metallic));
  if (c.transmission > 0.0f) in.transmission = std::make_shared<ConstantTexture>(Color(c.transmission, 0, 0));
  in.thinWalled = c.thinWalled;
  in.ior = c.ior;
  return std::make_shared<GltfPbrMaterial>(std::move(in));
}

std::string describe(const PbrConfig& c, const Vec3& wo) {
  std::ostringstream s;
  s << "roughness " << c.roughness << ", metallic " << c.metallic << ", transmission " << c.transmission
    << (c.thinWalled ? " thin" : " volume") << ", ior " << c.ior << ", wo (" << wo.x << ", " << wo.y << ", "
    << wo.z << ")";
  return s.str();
}

using test::flatHit;

// Unit direction with cos theta = mu (negative: below the surface), at an azimuth in no special
// relation to the grids.
Vec3 direction(double mu) {
  const double s = std::sqrt(std::max(0.0, 1.0 - mu * mu));
  return Vec3(float(s * std::cos(0.3)), float(s * std::sin(0.3)), float(mu));
}

double mean3(const Color& c) {
  return (double(c.x) + double(c.y) + double(c.z)) / 3.0;
}

// GGX D (Walter et al. 2007 eq. 33), independent of materials/microfacet.h.
double ggxD(const glm::dvec3& h, double alpha) {
  if (h.z <= 0.0) return 0.0;
  const double a2 = alpha * alpha, t = h.z * h.z * (a2 - 1.0) + 1.0;
  return a2 / (kPiD * t * t);
}

// Integral of g over the hemisphere z > 0 (wo.z > 0), see the top comment: n x n midpoints in each
// of the cosine and the GGX-normal warps, balance-heuristic partition between their densities.
double hemisphereIntegral(const std::function<double(const Vec3&)>& g, const Vec3& woF, double alpha, int n) {
  const glm::dvec3 wo(woF);
  auto pCos = [](const glm::dvec3& w) { return w.z / kPiD; };
  auto pGgx = [&](const glm::dvec3& w) {
    const glm::dvec3 h = glm::normalize(wo + w);
    const double oh = glm::dot(wo, h);
    return oh > 0.0 ? ggxD(h, alpha) * h.z / (4.0 * oh) : 0.0;
  };
  auto term = [&](const glm::dvec3& w) {
    if (!(w.z > 0.0)) return 0.0;
    return g(Vec3(glm::normalize(w))) / (pCos(w) + pGgx(w));
  };
  double sum = 0.0;
  for (int i = 0; i < n; ++i) {
    const double u1 = (i + 0.5) / n;
    // Cosine warp: r = sqrt(u1) on the disc, lifted (Malley); GGX warp: tan^2 theta_h =
    // alpha^2 u1 / (1 - u1), the inverse CDF of D(h) cos theta_h (Walter et al. 2007 eq. 35).
    const double r = std::sqrt(u1), z = std::sqrt(1.0 - u1);
    const double t2 = alpha * alpha * u1 / (1.0 - u1);
    const double hz = 1.0 / std::sqrt(1.0 + t2), hs = std::sqrt(t2) * hz;
    for (int j = 0; j < n; ++j) {
      const double phi = 2.0 * kPiD * (j + 0.5) / n;
      const double c = std::cos(phi), s = std::sin(phi);
      sum += term(glm::dvec3(r * c, r * s, z));
      const glm::dvec3 h(hs * c, hs * s, hz);
      const double oh = glm::dot(wo, h);
      if (oh > 0.0) sum += term(2.0 * oh * h - wo);
    }
  }
  return sum / (double(n) * double(n));
}

// Deterministic albedo of the reflection (and, thin-walled, the mirrored transmission) lobes.
struct Albedo {
  double reflection = 0.0, transmission = 0.0;
  double total() const { return reflection + transmission; }
};
Albedo quadratureAlbedo(const Material& m, const Vec3& wo, float roughness, bool withTransmission,
                        int n = 512) {
  const SurfaceHit hit = flatHit();
  const double alpha = std::max(double(roughness) * roughness, 1e-3);
  Albedo a;
  a.reflection = hemisphereIntegral([&](const Vec3& wi) { return mean3(m.eval(hit, wo, wi)); }, wo, alpha, n);
  if (withTransmission) {
    a.transmission = hemisphereIntegral(
        [&](const Vec3& w) { return mean3(m.eval(hit, wo, Vec3(w.x, w.y, -w.z))); }, wo, alpha, n);
  }
  return a;
}

// Mean sample() weight (failures count 0); transmitted weights times eta^2 when `undoEta`.
test::McMean sampledAlbedo(const Material& m, const Vec3& wo, long n, uint64_t seed, bool undoEta = false) {
  const SurfaceHit hit = flatHit();
  Rng rng(seed, 7);
  test::McMean mean;
  for (long k = 0; k < n; ++k) {
    const Vec2 u(rng.uniform(), rng.uniform());
    BsdfSample bs;
    if (!m.sample(hit, wo, u, rng.uniform(), bs)) {
      mean.add(0.0);
      continue;
    }
    mean.add(mean3(bs.weight) * (undoEta ? double(bs.eta) * bs.eta : 1.0));
  }
  return mean;
}

// Single-scattering albedo of GGX with height-correlated Smith G2 and F = 1, reference values from
// an independent 4096^2 double-precision quadrature (top comment); r = glTF roughness, alpha = r^2.
struct MetalReference {
  float roughness;
  double mu, albedo;
};
constexpr MetalReference kMetalReference[] = {
    {0.05f, 1.0, 1.000000}, {0.05f, 0.5, 0.999991}, {0.05f, 0.1, 0.999602},  //
    {0.1f, 1.0, 0.999999},  {0.1f, 0.5, 0.999738},  {0.1f, 0.1, 0.993878},   //
    {0.2f, 1.0, 0.998245},  {0.2f, 0.5, 0.995385},  {0.2f, 0.1, 0.928675},   //
    {0.5f, 1.0, 0.915813},  {0.5f, 0.5, 0.857263},  {0.5f, 0.1, 0.891560},   //
    {1.0f, 1.0, 0.306853},  {1.0f, 0.5, 0.450694},  {1.0f, 0.1, 0.760210},
};

TEST(PbrFurnace, WhiteMetalMatchesGgxSingleScatteringAlbedo) {
  uint64_t seed = 1;
  for (const MetalReference& ref : kMetalReference) {
    const PbrConfig c{Color(1.0f), ref.roughness, 1.0f};
    const auto m = makePbr(c);
    const Vec3 wo = direction(ref.mu);
    const std::string what = describe(c, wo);
    const double quad = quadratureAlbedo(*m, wo, c.roughness, false).reflection;
    const test::McMean mc = sampledAlbedo(*m, wo, 200000, seed++);
    // The midpoint rule converges as 1 / n along the horizon cut-off that crosses the GGX warp
    // obliquely at grazing wo; elsewhere it is far more accurate than this.
    const double quadTol = ref.mu < 0.2 ? 4e-3 : 1e-3;
    EXPECT_NEAR(quad, ref.albedo, quadTol) << what;
    EXPECT_LE(quad, 1.0 + 1e-4) << what;
    mc.expectNear(quad, quadTol, "sampled vs quadrature albedo, " + what);
    if (ref.roughness <= 0.2f && ref.mu == 1.0) {
      EXPECT_GT(quad, 0.97) << what;
    }
  }
  // The closed form at normal incidence and alpha = 1.
  EXPECT_NEAR(quadratureAlbedo(*makePbr({Color(1.0f), 1.0f, 1.0f}), direction(1.0), 1.0f, false).reflection,
              1.0 - std::log(2.0), 2e-4);
}

// Appendix B's dielectric, baseColor 1, no transmission: the Lambertian base is weighted by
// 1 - F(|V.H|) per direction pair, not by what the specular layer leaves over, so the model is NOT
// energy conserving: at normal incidence E is 1 - (GGX loss) <= 1, but towards grazing wo the
// Fresnel-brightened specular layer comes on top of an almost undimmed base and E exceeds 1 (1.68 at
// roughness 0.1, cos 0.05). The reference values come from an independent double-precision midpoint
// rule of the Appendix B formulas on a 4000 x 8000 (cos theta, phi) grid (converged to 1e-6 where
// given; NaN: the narrow lobe is not resolved by that grid). This pins the model as specified.
struct DielectricReference {
  float roughness;
  double mu, albedo;
};
constexpr double kUnresolved = std::numeric_limits<double>::quiet_NaN();
const DielectricReference kDielectricReference[] = {
    {0.1f, 1.0, kUnresolved}, {0.1f, 0.6, 1.006938}, {0.1f, 0.3, 1.150444}, {0.1f, 0.05, kUnresolved},  //
    {0.3f, 1.0, 0.999553},    {0.3f, 0.6, 1.008157}, {0.3f, 0.3, 1.117897}, {0.3f, 0.05, 1.326515},     //
    {0.6f, 1.0, 0.992940},    {0.6f, 0.6, 0.996454}, {0.6f, 0.3, 1.022169}, {0.6f, 0.05, 1.080203},     //
    {1.0f, 1.0, 0.972228},    {1.0f, 0.6, 0.975100}, {1.0f, 0.3, 0.980069}, {1.0f, 0.05, 1.001306},
};

TEST(PbrFurnace, WhiteDielectricFollowsAppendixB) {
  uint64_t seed = 100;
  for (const DielectricReference& ref : kDielectricReference) {
    const PbrConfig c{Color(1.0f), ref.roughness, 0.0f};
    const auto m = makePbr(c);
    const Vec3 wo = direction(ref.mu);
    const std::string what = describe(c, wo);
    const double quad = quadratureAlbedo(*m, wo, c.roughness, false).reflection;
    const test::McMean mc = sampledAlbedo(*m, wo, 100000, seed++);
    std::cout << "[pbr] dielectric white furnace: " << what << ": E = " << quad << " (sampled " << mc.mean()
              << " +- " << mc.standardError() << ")\n";
    const double quadTol = ref.mu < 0.2 ? 4e-3 : 1e-3;
    mc.expectNear(quad, quadTol, "sampled vs quadrature albedo, " + what);
    if (!std::isnan(ref.albedo)) {
      EXPECT_NEAR(quad, ref.albedo, quadTol) << what;
    }
    if (ref.mu == 1.0) {
      EXPECT_LE(quad, 1.0 + 1e-3) << what;
    }
    EXPECT_GT(quad, 0.95) << what;
  }
}

TEST(PbrFurnace, ThinWalledTransmissionCompletesTheMetalLobe) {
  uint64_t seed = 200;
  for (float roughness : {0.1f, 0.4f, 1.0f}) {
    for (double mu : {1.0, 0.4}) {
      const PbrConfig thin{Color(1.0f), roughness, 0.0f, 1.0f, true};
      const auto m = makePbr(thin);
      const auto metal = makePbr({Color(1.0f), roughness, 1.0f});
      const Vec3 wo = direction(mu);
      const std::string what = describe(thin, wo);
      const Albedo a = quadratureAlbedo(*m, wo, roughness, true);
      const double metalAlbedo = quadratureAlbedo(*metal, wo, roughness, false).reflection;
      // Pointwise F + (1 - F) = 1 on the same quadrature points: equal up to float rounding.
      EXPECT_NEAR(a.total(), metalAlbedo, 1e-4) << what;
      EXPECT_LE(a.total(), 1.0 + 1e-4) << what;
      EXPECT_GT(a.transmission, 0.5 * a.total()) << what;
      sampledAlbedo(*m, wo, 200000, seed++).expectNear(a.total(), 1e-3, "sampled vs quadrature, " + what);
    }
  }
}

// Rough dielectric interface, transmission 1: reflection plus eta^2 times transmission (the radiance
// scaling undone) is at most 1, and close to 1 where GGX loses little (low roughness), from outside
// and from inside (total internal reflection included).
TEST(PbrFurnace, VolumetricInterfaceConservesEnergy) {
  uint64_t seed = 300;
  for (float roughness : {0.05f, 0.3f, 0.7f}) {
    for (double mu : {1.0, 0.5, 0.1, -1.0, -0.8, -0.5, -0.1}) {
      const PbrConfig c{Color(1.0f), roughness, 0.0f, 1.0f, false, 1.5f};
      const auto m = makePbr(c);
      const Vec3 wo = direction(mu);
      const std::string what = describe(c, wo);
      const test::McMean mc = sampledAlbedo(*m, wo, 100000, seed++, /*undoEta=*/true);
      EXPECT_LE(mc.mean(), 1.0 + mc.tolerance()) << what;
      if (roughness <= 0.05f) {
        EXPECT_GT(mc.mean(), 0.97) << what;
      }
    }
  }
  // eta reported on refraction: eta_t / eta_i.
  const auto m = makePbr({Color(1.0f), 0.3f, 0.0f, 1.0f, false, 1.5f});
  const SurfaceHit hit = flatHit();
  Rng rng(9, 9);
  int refracted[2] = {0, 0};
  for (int k = 0; k < 2000; ++k) {
    for (int side = 0; side < 2; ++side) {
      const Vec3 wo = direction(side == 0 ? 0.9 : -0.9);
      BsdfSample bs;
      if (!m->sample(hit, wo, Vec2(rng.uniform(), rng.uniform()), rng.uniform(), bs)) continue;
      if (bs.wi.z * wo.z < 0.0f) {
        ++refracted[side];
        EXPECT_FLOAT_EQ(bs.eta, side == 0 ? 1.5f : 1.0f / 1.5f);
      } else {
        EXPECT_EQ(bs.eta, 1.0f);
      }
    }
  }
  EXPECT_GT(refracted[0], 100);
  EXPECT_GT(refracted[1], 100);
}

// A roughness of 0 makes the specular and transmission lobes Dirac deltas (gltf_pbr.cpp): each
// must be its microfacet lobe's alpha -> 0 limit. The sampled albedo (transmission times eta^2)
// at roughness 0 against that at roughness 0.045 (alpha 0.002, just above the clamp), for every
// lobe mixture, from outside and inside a volume; and the smooth metal's against Schlick exactly.
TEST(PbrSmooth, DiracLobesAreTheRoughLobesLimit) {
  uint64_t seed = 500;
  const std::vector<PbrConfig> configs = {
      {Color(0.9f, 0.6f, 0.3f), 0.0f, 1.0f},                     // metal
      {Color(0.5f, 0.7f, 0.2f), 0.0f, 0.0f},                     // dielectric over diffuse
      {Color(0.8f, 0.8f, 0.9f), 0.0f, 0.0f, 1.0f, true},         // thin-walled glass
      {Color(1.0f), 0.0f, 0.0f, 1.0f, false, 1.5f},              // glass volume
      {Color(0.6f, 0.9f, 0.7f), 0.0f, 0.3f, 0.6f, false, 1.33f}  // a mixture of all
  };
  for (PbrConfig c : configs) {
    const auto smooth = makePbr(c);
    EXPECT_TRUE(smooth->hasDeltaLobes());
    c.roughness = 0.045f;
    const auto rough = makePbr(c);
    EXPECT_FALSE(rough->hasDeltaLobes());
    for (double mu : {1.0, 0.6, 0.2, -0.9, -0.75, -0.5}) {
      if (mu < 0.0 && c.thinWalled) continue;  // thin-walled: two-sided, the same from below
      const Vec3 wo = direction(mu);
      const std::string what = "roughness 0 against " + describe(c, wo);
      const test::McMean limit = sampledAlbedo(*rough, wo, 400000, seed++, true);
      const test::McMean dirac = sampledAlbedo(*smooth, wo, 400000, seed++, true);
      // The lobes at alpha 0.002 are a few hundredths of a degree wide: their albedo differs
      // from the limit's by well under 0.5%.
      EXPECT_NEAR(dirac.mean(), limit.mean(), limit.tolerance(0.005) + dirac.tolerance()) << what;
    }
  }
  // A smooth white-ish metal reflects Schlick's F at n.v, always into the mirror direction.
  const auto metal = makePbr({Color(0.9f, 0.6f, 0.3f), 0.0f, 1.0f});
  EXPECT_FALSE(metal->hasNonDeltaLobes());
  const SurfaceHit hit = flatHit();
  for (double mu : {1.0, 0.5, 0.05}) {
    const Vec3 wo = direction(mu);
    BsdfSample bs;
    ASSERT_TRUE(metal->sample(hit, wo, Vec2(0.3f, 0.7f), 0.5f, bs));
    EXPECT_TRUE(bs.delta);
    EXPECT_NEAR(glm::length(bs.wi - Vec3(-wo.x, -wo.y, wo.z)), 0.0f, 1e-6f);
    const double m = std::pow(1.0 - mu, 5.0);
    for (int k = 0; k < 3; ++k) {
      const double f0 = Color(0.9f, 0.6f, 0.3f)[k];
      EXPECT_NEAR(bs.weight[k], f0 + (1.0 - f0) * m, 1e-5) << "mu " << mu;
    }
    EXPECT_EQ(metal->eval(hit, wo, bs.wi), Color(0.0f));
  }
  // Rough materials, and those without a roughness of 0 anywhere, have none.
  EXPECT_FALSE(makePbr({Color(1.0f), 0.5f, 1.0f})->hasDeltaLobes());
  EXPECT_TRUE(makePbr({Color(1.0f), 0.0f, 0.0f})->hasNonDeltaLobes());
}

PbrConfig randomConfig(Rng& rng, bool thinWalled) {
  PbrConfig c;
  c.baseColor = Color(rng.uniform(), rng.uniform(), rng.uniform());
  c.roughness = 0.05f + 0.95f * rng.uniform();
  c.metallic = rng.uniform() < 0.3f ? 0.0f : rng.uniform();
  c.transmission = rng.uniform() < 0.3f ? 0.0f : rng.uniform();
  c.thinWalled = thinWalled;
  c.ior = 1.2f + rng.uniform();
  return c;
}

Vec3 randomDirection(Rng& rng, bool upper) {
  const float z = std::max(rng.uniform(), 1e-3f) * (upper ? 1.0f : -1.0f);
  const float s = std::sqrt(std::max(0.0f, 1.0f - z * z)), phi = 2.0f * kPi * rng.uniform();
  return Vec3(s * std::cos(phi), s * std::sin(phi), z);
}

void expectColorNear(const Color& a, const Color& b, const std::string& what) {
  for (int k = 0; k < 3; ++k)
    EXPECT_NEAR(a[k], b[k], 2e-4f * std::max(std::abs(a[k]), std::abs(b[k])) + 1e-7f) << what;
}

// f(wo, wi) = eval / |cos_i| is symmetric for reflection on either side (Helmholtz reciprocity;
// inside a volume the Fresnel term is Schlick at the outside cosine for both orders, see
// gltf_pbr.cpp); for refraction f(wi, wo) n_o^2 = f(wo, wi) n_i^2 (Veach 1997, eq. 5.14, with the
// radiance scaling folded into f); thin-walled transmission is symmetric.
TEST(PbrReciprocity, HelmholtzAndGeneralised) {
  const SurfaceHit hit = flatHit();
  Rng rng(42, 1);
  for (int k = 0; k < 3000; ++k) {
    const bool thin = k % 2 == 0;
    const PbrConfig c = randomConfig(rng, thin);
    const auto m = makePbr(c);
    const bool upper = rng.uniform() < 0.5f;
    const Vec3 wo = randomDirection(rng, upper);
    // Reflection.
    const Vec3 wi = randomDirection(rng, upper);
    expectColorNear(m->eval(hit, wo, wi) / std::abs(wi.z), m->eval(hit, wi, wo) / std::abs(wo.z),
                    "reflection, " + describe(c, wo));
    // Transmission.
    const Vec3 wt = randomDirection(rng, !upper);
    const Color forward = m->eval(hit, wo, wt) / std::abs(wt.z),
                backward = m->eval(hit, wt, wo) / std::abs(wo.z);
    const float nO = thin ? 1.0f : (upper ? 1.0f : c.ior), nI = thin ? 1.0f : (upper ? c.ior : 1.0f);
    expectColorNear(forward * nI * nI, backward * nO * nO, "transmission, " + describe(c, wo));
  }
}

// eval, pdf and sample stay finite and non-negative for random and degenerate directions, roughness
// 0 included; sample()'s pdf is pdf(wo, wi) and its weight eval / pdf.
TEST(PbrSafety, FiniteAndNonNegative) {
  const SurfaceHit hit = flatHit();
  Rng rng(7, 3);
  std::vector<PbrConfig> configs;
  for (float r : {0.0f, 0.01f, 0.5f, 1.0f}) {
    for (float metallic : {0.0f, 0.5f, 1.0f}) {
      for (float t : {0.0f, 1.0f}) {
        for (bool thin : {true, false}) {
          for (float ior : {1.0f, 1.5f, 2.5f})
            configs.push_back({Color(0.9f, 0.5f, 0.0f), r, metallic, t, thin, ior});
        }
      }
    }
  }
  configs.push_back({Color(0.0f), 0.5f, 1.0f});  // black metal
  configs.push_back({Color(0.0f), 0.0f, 0.0f, 1.0f, false});
  std::vector<Vec3> special = {Vec3(0, 0, 1),
                               Vec3(0, 0, -1),
                               Vec3(1, 0, 0),
                               glm::normalize(Vec3(1, 0, 1e-7f)),
                               glm::normalize(Vec3(1, 0, -1e-7f)),
                               glm::normalize(Vec3(0.6f, 0.8f, 1e-4f)),
                               glm::normalize(Vec3(-0.6f, -0.8f, 1e-4f))};
  auto finiteNonNegative = [](const Color& c) {
    return isFinite(c) && c.x >= 0.0f && c.y >= 0.0f && c.z >= 0.0f;
  };
  for (const PbrConfig& c : configs) {
    const auto m = makePbr(c);
    std::vector<Vec3> dirs = special;
    for (int k = 0; k < 40; ++k) dirs.push_back(randomDirection(rng, rng.uniform() < 0.5f));
    for (const Vec3& wo : dirs) {
      const std::string what = describe(c, wo);
      std::vector<Vec3> wis = dirs;
      wis.push_back(-wo);
      wis.push_back(Vec3(-wo.x, -wo.y, wo.z));  // the mirror direction
      wis.push_back(Vec3(wo.x, wo.y, -wo.z));   // its thin-walled image
      for (const Vec3& wi : wis) {
        const Color f = m->eval(hit, wo, wi);
        const float p = m->pdf(hit, wo, wi);
        ASSERT_TRUE(finiteNonNegative(f)) << what << ", wi (" << wi.x << ", " << wi.y << ", " << wi.z << ")";
        ASSERT_TRUE(std::isfinite(p) && p >= 0.0f)
            << what << ", wi (" << wi.x << ", " << wi.y << ", " << wi.z << ")";
      }
      for (int k = 0; k < 64; ++k) {
        const Vec2 u = k < 4 ? Vec2(k & 1 ? 0.99999994f : 0.0f, k & 2 ? 0.99999994f : 0.0f)
                             : Vec2(rng.uniform(), rng.uniform());
        const float uLobe = k < 4 ? 0.5f : rng.uniform();
        BsdfSample bs;
        if (!m->sample(hit, wo, u, uLobe, bs)) continue;
        ASSERT_TRUE(finiteNonNegative(bs.weight)) << what;
        ASSERT_TRUE(std::isfinite(bs.pdf) && bs.pdf > 0.0f) << what;
        ASSERT_NEAR(glm::length(bs.wi), 1.0f, 1e-5f) << what;
        if (bs.delta) {
          // Only a smooth surface has Dirac lobes; their pdf is the lobe's probability.
          ASSERT_LT(c.roughness, 0.04f) << what;
          ASSERT_LE(bs.pdf, 1.0f) << what;
          continue;
        }
        EXPECT_EQ(bs.pdf, m->pdf(hit, wo, bs.wi)) << what;
        expectColorNear(bs.weight * bs.pdf, m->eval(hit, wo, bs.wi), what);
      }
    }
  }
}

TEST(PbrInputs, MissingTexturesMeanTheGltfDefaults) {
  // No baseColor / metallicRoughness texture: factors 1, i.e. a white, fully rough metal.
  const GltfPbrMaterial defaults(GltfPbrInputs{});
  const auto metal = makePbr({Color(1.0f), 1.0f, 1.0f});
  const SurfaceHit hit = flatHit();
  const Vec3 wo = direction(0.7), wi = glm::normalize(Vec3(-0.3f, 0.2f, 0.8f));
  EXPECT_EQ(defaults.eval(hit, wo, wi), metal->eval(hit, wo, wi));
  EXPECT_EQ(defaults.pdf(hit, wo, wi), metal->pdf(hit, wo, wi));
  EXPECT_TRUE(defaults.hasNonDeltaLobes());
  EXPECT_EQ(defaults.typeName(), "gltf_pbr");
}

// The material's inputs are remembered per hit (GltfPbrMaterial::fetchFor) between a vertex's
// evalPdf and its sample. Whatever a hit's slot held before (nothing, the same inputs, another
// UV, another material, a NaN UV, a material rebuilt at the same address), every value must be what
// a first evaluation gives, bit for bit: the memo may only ever return what fetch would.
TEST(GltfPbr, RememberedInputsNeverChangeAValue) {
  std::vector<Color> texels(64 * 64);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x)
      texels[size_t(y * 64 + x)] = Color(float(x) / 63.0f, float(y) / 63.0f, float((x * y) % 64) / 63.0f);
  const auto image =
      std::make_shared<ImageTexture>(64, 64, texels, TextureFilter::Bilinear, TextureWrap::Repeat);
  GltfPbrInputs a, b;
  a.baseColor = image;
  a.metallicRoughness = image;  // roughness and metallic vary with the UV too
  b.baseColor = std::make_shared<ConstantTexture>(Color(0.2f, 0.9f, 0.4f));
  b.metallicRoughness = image;
  const GltfPbrMaterial first(a), second(b);
  const GltfPbrMaterial* materials[] = {&first, &second};

  // Many hits side by side, as in a wave; each round also evaluates a copy of its hit.
  std::vector<SurfaceHit> wave(2048, flatHit());
  Rng rng(8, 1);
  const auto bits = [](const Color& c) {
    return std::array{std::bit_cast<uint32_t>(c.x), std::bit_cast<uint32_t>(c.y),
                      std::bit_cast<uint32_t>(c.z)};
  };
  for (int round = 0; round < 3000; ++round) {
    SurfaceHit& hit = wave[size_t(rng.uniform() * 2047.0f)];
    const GltfPbrMaterial& m = *materials[round % 2];
    const Vec2 uv = round % 97 == 0  ? Vec2(std::numeric_limits<float>::quiet_NaN(), 0.5f)
                    : round % 5 == 0 ? hit.uv  // the slot's own UV again
                                     : Vec2(3.0f * rng.uniform() - 1.0f, 3.0f * rng.uniform() - 1.0f);
    hit.uv = uv;
    const Vec3 wo = glm::normalize(Vec3(rng.uniform() - 0.5f, rng.uniform() - 0.5f, 0.1f + rng.uniform()));
    const Vec3 wi = glm::normalize(Vec3(rng.uniform() - 0.5f, rng.uniform() - 0.5f, 0.1f + rng.uniform()));
    const Vec2 u(rng.uniform(), rng.uniform());
    const float uLobe = rng.uniform();
    float pdf = 0.0f;
    const Color f = m.evalPdf(hit, wo, wi, pdf);
    BsdfSample bs;
    const bool sampled = m.sample(hit, wo, u, uLobe, bs);

    // A first evaluation: a copy of the hit in a slot that a material other than m has just filled
    // (so m must fetch) and then m itself, twice over.
    SurfaceHit fresh = hit;
    const GltfPbrMaterial& other = *materials[(round + 1) % 2];
    float ignored;
    other.evalPdf(fresh, wo, wi, ignored);
    float pdfFresh = 0.0f;
    const Color fFresh = m.evalPdf(fresh, wo, wi, pdfFresh);
    BsdfSample bsFresh;
    const bool sampledFresh = m.sample(fresh, wo, u, uLobe, bsFresh);
    ASSERT_EQ(bits(f), bits(fFresh)) << "round " << round;
    ASSERT_EQ(std::bit_cast<uint32_t>(pdf), std::bit_cast<uint32_t>(pdfFresh)) << "round " << round;
    ASSERT_EQ(sampled, sampledFresh) << "round " << round;
    if (sampled) {
      ASSERT_EQ(bits(bs.weight), bits(bsFresh.weight)) << "round " << round;
      ASSERT_EQ(bits(bs.wi), bits(bsFresh.wi)) << "round " << round;
    }
  }

  // A material built where a freed one lay (a second scene, a loop) is another material: at the
  // same address, for the same hit and UV, it must not get its predecessor's inputs. The values
  // it must give come from materials that all stay alive (each its own address and id).
  const SurfaceHit hit = flatHit();
  const Vec3 wo(0.0f, 0.0f, 1.0f), wi = glm::normalize(Vec3(0.3f, 0.0f, 1.0f));
  std::vector<std::unique_ptr<GltfPbrMaterial>> alive;
  std::vector<Color> want;
  for (int k = 0; k < 4; ++k) {
    GltfPbrInputs in;
    in.baseColor = std::make_shared<ConstantTexture>(Color(0.2f * float(k + 1)));
    alive.push_back(std::make_unique<GltfPbrMaterial>(in));
    float pdf;
    want.push_back(alive.back()->evalPdf(hit, wo, wi, pdf));
  }
  std::optional<GltfPbrMaterial> reused;
  for (int k = 0; k < 4; ++k) {
    reused.emplace(alive[size_t(k)]->inputs());
    float pdf;
    EXPECT_EQ(bits(reused->evalPdf(hit, wo, wi, pdf)), bits(want[size_t(k)]))
        << "material " << k << " at the address of material " << k - 1;
  }
}

}  // namespace
}  // namespace ember
