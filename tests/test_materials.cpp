// Unit tests of the materials (materials/*.h) at a surface point with ng = ns = +z.
//
// For every material and several outgoing directions wo, above and below the surface:
//  - energy: E[sample().weight] (failed samples count as 0) is at most 1 per channel, with the
//    1 / eta^2 radiance scaling of refraction taken out (it moves radiance, not energy), and equals
//    the known albedo where there is a closed form;
//  - for the non-delta lobes: sample()'s pdf equals pdf(wo, wi), its weight equals eval / pdf, and
//    its mean matches an independent estimate of the integral of eval (so the sampled directions
//    really follow pdf); pdf integrates to at most 1 over the sphere (exactly 1 for Lambertian);
//  - Fresnel against closed forms; the dielectric's reflect/refract choice and Snell's law; total
//    internal reflection; the mirror; the mixed material's absorption; Phong's energy bound.
//
// Tolerances: statistical checks allow kSigmas standard errors; exact checks allow float rounding.

#include "core/rng.h"
#include "core/sampling.h"
#include "materials/fresnel.h"
#include "materials/gltf_pbr.h"
#include "materials/lambertian.h"
#include "materials/mixed.h"
#include "materials/phong.h"
#include "materials/specular.h"
#include "materials/texture.h"

#include <gtest/gtest.h>

#include "mc_mean.h"

#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <memory>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

namespace ember {
namespace {

constexpr float kFloatTol = 1e-5f;  // a few float ulps, relative
constexpr double kPiD = std::numbers::pi;

using test::kSigmas;
using test::McMean;

// One McMean per colour channel.
struct ColorMean {
  McMean c[3];
  void add(const Color& v) {
    for (int k = 0; k < 3; ++k) c[k].add(v[k]);
  }
};

std::string str(const Vec3& v) {
  std::ostringstream s;
  s.precision(7);
  s << "(" << v.x << ", " << v.y << ", " << v.z << ")";
  return s.str();
}

Vec2 next2(Rng& rng) {
  const float a = rng.uniform();
  return {a, rng.uniform()};
}

SurfaceHit flatHit() {
  SurfaceHit hit;
  hit.p = Vec3(0.0f);
  hit.ng = hit.ns = Vec3(0.0f, 0.0f, 1.0f);
  hit.uv = Vec2(0.3f, 0.7f);
  return hit;
}

Vec3 direction(float thetaDeg, float phi, bool above) {
  const float th = thetaDeg * kPi / 180.0f;
  return {std::sin(th) * std::cos(phi), std::sin(th) * std::sin(phi), (above ? 1.0f : -1.0f) * std::cos(th)};
}

// wo at 0, 30, 60 and 85 degrees from the normal, above and below the surface.
std::vector<Vec3> woDirections() {
  std::vector<Vec3> dirs;
  for (bool above : {true, false})
    for (float th : {0.0f, 30.0f, 60.0f, 85.0f}) dirs.push_back(direction(th, 0.7f, above));
  return dirs;
}

std::shared_ptr<const Texture> constant(const Color& c) {
  return std::make_shared<ConstantTexture>(c);
}

struct MaterialCase {
  std::string name;
  std::shared_ptr<Material> material;
};

const Color kAlbedo(0.2f, 0.5f, 0.8f);
const Color kPhongKd(0.3f, 0.2f, 0.1f), kPhongKs(0.5f, 0.6f, 0.7f);
const Color kMirrorR(0.9f, 0.8f, 0.7f);
const Color kTransmittance(0.9f, 0.95f, 1.0f);
constexpr float kIor = 1.5f;

MixedCoefficients mixedCoefficients() {
  MixedCoefficients c;
  c.kd = constant(Color(0.1f, 0.2f, 0.15f));  // max 0.2
  c.ks = Color(0.1f, 0.05f, 0.1f);            // max 0.1
  c.kr = Color(0.15f, 0.1f, 0.1f);            // max 0.15
  c.kt = Color(0.2f, 0.25f, 0.2f);            // max 0.25; absorbed: 1 - 0.7 = 0.3
  c.exponent = 20.0f;
  c.ior = kIor;
  return c;
}

std::vector<MaterialCase> materialCases() {
  return {
      {"lambertian", std::make_shared<Lambertian>(constant(kAlbedo))},
      {"phong", std::make_shared<Phong>(constant(kPhongKd), kPhongKs, 20.0f)},
      {"phong kd+ks=1 n=1000", std::make_shared<Phong>(constant(Color(0.3f)), Color(0.7f), 1000.0f)},
      {"phong kd+ks=1 n=5000", std::make_shared<Phong>(constant(Color(0.05f)), Color(0.95f), 5000.0f)},
      {"mirror", std::make_shared<Mirror>(kMirrorR)},
      {"refraction", std::make_shared<Refraction>(kTransmittance, kIor, 1.0f)},
      {"dielectric", std::make_shared<Dielectric>(kIor, 1.0f)},
      {"mixed", std::make_shared<Mixed>(mixedCoefficients())},
  };
}

// Material::usesDirectionSample and usesLobeSample may be false only where sample() returns the
// same for any value of those numbers, and so does sampleLanes: the wavefront passes over numbers
// a material does not read and hands it 0.5 instead (renderer/sampler_lanes.h). Bit for bit, for
// every material.
TEST(MaterialSampling, NumbersAMaterialDoesNotReadChangeNoSample) {
  const auto bits = [](const Vec3& v) {
    return std::array{std::bit_cast<uint32_t>(v.x), std::bit_cast<uint32_t>(v.y),
                      std::bit_cast<uint32_t>(v.z)};
  };
  Rng rng(5, 17);
  std::vector<MaterialCase> cases = materialCases();
  cases.push_back({"gltf", std::make_shared<GltfPbrMaterial>(GltfPbrInputs{})});
  for (const MaterialCase& c : cases) {
    const Material& m = *c.material;
    for (int i = 0; i < 2000; ++i) {
      SurfaceHit hit;
      hit.ng = hit.ns = Vec3(0.0f, 0.0f, 1.0f);
      hit.uv = next2(rng);
      hit.material = &m;
      const Vec3 wo = sampleUniformSphere(next2(rng));
      const Vec2 u = next2(rng);
      const float uLobe = rng.uniform();
      // The numbers the material claims not to read replaced by others.
      const Vec2 otherU = m.usesDirectionSample() ? u : next2(rng);
      const float otherLobe = m.usesLobeSample() ? uLobe : rng.uniform();
      BsdfSample a, b;
      const bool okA = m.sample(hit, wo, u, uLobe, a), okB = m.sample(hit, wo, otherU, otherLobe, b);
      ASSERT_EQ(okA, okB) << c.name << " sample " << i;
      if (!okA) continue;
      ASSERT_EQ(bits(a.wi), bits(b.wi)) << c.name << " sample " << i;
      ASSERT_EQ(bits(a.weight), bits(b.weight)) << c.name << " sample " << i;
      ASSERT_EQ(std::bit_cast<uint32_t>(a.pdf), std::bit_cast<uint32_t>(b.pdf)) << c.name << " sample " << i;
      ASSERT_EQ(a.delta, b.delta) << c.name << " sample " << i;
      ASSERT_EQ(std::bit_cast<uint32_t>(a.eta), std::bit_cast<uint32_t>(b.eta)) << c.name << " sample " << i;
    }
    // sampleLanes, which the wavefront calls, over a run of vertices with the same replacements.
    constexpr size_t kRun = 37;  // more than two blocks of the cosine kernel's lanes
    std::vector<SurfaceHit> hits(kRun);
    std::vector<const SurfaceHit*> hitPointers;
    std::vector<Vec3> wo(kRun);
    std::vector<Vec2> u(kRun), otherU(kRun);
    std::vector<float> uLobe(kRun), otherLobe(kRun);
    for (size_t i = 0; i < kRun; ++i) {
      hits[i].ng = hits[i].ns = Vec3(0.0f, 0.0f, 1.0f);
      hits[i].uv = next2(rng);
      hits[i].material = &m;
      hitPointers.push_back(&hits[i]);
      wo[i] = sampleUniformSphere(next2(rng));
      u[i] = next2(rng);
      uLobe[i] = rng.uniform();
      otherU[i] = m.usesDirectionSample() ? u[i] : next2(rng);
      otherLobe[i] = m.usesLobeSample() ? uLobe[i] : rng.uniform();
    }
    std::vector<BsdfSample> a(kRun), b(kRun);
    std::unique_ptr<bool[]> okA(new bool[kRun]), okB(new bool[kRun]);
    m.sampleLanes(hitPointers.data(), wo.data(), u.data(), uLobe.data(), kRun, a.data(), okA.get());
    m.sampleLanes(hitPointers.data(), wo.data(), otherU.data(), otherLobe.data(), kRun, b.data(), okB.get());
    for (size_t i = 0; i < kRun; ++i) {
      ASSERT_EQ(okA[i], okB[i]) << c.name << " lane " << i;
      if (!okA[i]) continue;
      ASSERT_EQ(bits(a[i].wi), bits(b[i].wi)) << c.name << " lane " << i;
      ASSERT_EQ(bits(a[i].weight), bits(b[i].weight)) << c.name << " lane " << i;
      ASSERT_EQ(std::bit_cast<uint32_t>(a[i].pdf), std::bit_cast<uint32_t>(b[i].pdf))
          << c.name << " lane " << i;
    }
  }
}

// Energy carried by one sample: the weight with refraction's radiance scaling 1 / eta^2 removed
// (Veach 1997, section 5.2), so that a lossless interface carries exactly 1.
Color fluxWeight(const BsdfSample& s) {
  return s.weight * (s.eta * s.eta);
}

// Runs sample() n times, returning per-channel means of the flux weight (failures count 0).
ColorMean sampledFlux(const Material& m, const SurfaceHit& hit, const Vec3& wo, Rng& rng, int n,
                      ColorMean* plainWeight = nullptr) {
  ColorMean flux;
  for (int i = 0; i < n; ++i) {
    BsdfSample s;
    const Vec2 u = next2(rng);
    const bool ok = m.sample(hit, wo, u, rng.uniform(), s);
    flux.add(ok ? fluxWeight(s) : Color(0.0f));
    if (plainWeight) plainWeight->add(ok ? s.weight : Color(0.0f));
  }
  return flux;
}

// ---------------------------------------------------------------------------------------------
// (a) Energy

TEST(MaterialEnergy, AtMostOnePerChannelForEveryMaterialAndDirection) {
  const SurfaceHit hit = flatHit();
  for (const MaterialCase& mc : materialCases()) {
    Rng rng(7, 1);
    for (const Vec3& wo : woDirections()) {
      SCOPED_TRACE(mc.name + ", wo = " + str(wo));
      ColorMean plain;
      const ColorMean flux = sampledFlux(*mc.material, hit, wo, rng, 20000, &plain);
      for (int k = 0; k < 3; ++k) {
        EXPECT_LE(flux.c[k].mean(), 1.0 + flux.c[k].tolerance(kFloatTol)) << "channel " << k;
        // Arriving from outside (above), the radiance scaling only shrinks weights too.
        if (wo.z > 0.0f) {
          EXPECT_LE(plain.c[k].mean(), 1.0 + plain.c[k].tolerance(kFloatTol)) << "channel " << k;
        }
        EXPECT_GE(flux.c[k].mean(), 0.0);
      }
    }
  }
}

// Closed forms: Lambertian returns its albedo on either side; the mirror its reflectance; the
// refraction material its transmittance (refracted or totally reflected); the lossless dielectric
// exactly 1; Phong kd + ks at normal incidence (where the mirror direction is n, the normalised
// lobe integrates (n + 2) / 2pi cos^(n+1) theta over the hemisphere to exactly 1); the mixed
// material kd + ks + kr + kt there.
TEST(MaterialEnergy, MatchesClosedFormAlbedos) {
  const SurfaceHit hit = flatHit();
  const Vec3 normal(0, 0, 1);
  struct Case {
    std::string name;
    std::shared_ptr<Material> m;
    Color expected;
    std::vector<Vec3> wos;
  };
  const MixedCoefficients mixed = mixedCoefficients();
  const std::vector<Case> cases = {
      {"lambertian", std::make_shared<Lambertian>(constant(kAlbedo)), kAlbedo, woDirections()},
      {"mirror", std::make_shared<Mirror>(kMirrorR), kMirrorR, woDirections()},
      {"refraction", std::make_shared<Refraction>(kTransmittance, kIor, 1.0f), kTransmittance,
       woDirections()},
      {"dielectric", std::make_shared<Dielectric>(kIor, 1.0f), Color(1.0f), woDirections()},
      {"phong",
       std::make_shared<Phong>(constant(kPhongKd), kPhongKs, 20.0f),
       kPhongKd + kPhongKs,
       {normal, -normal}},
      {"phong kd+ks=1 n=1000",
       std::make_shared<Phong>(constant(Color(0.3f)), Color(0.7f), 1000.0f),
       Color(1.0f),
       {normal, -normal}},
      {"mixed",
       std::make_shared<Mixed>(mixed),
       mixed.kd->eval({}) + mixed.ks + mixed.kr + mixed.kt,
       {normal, -normal}},
  };
  for (const Case& c : cases) {
    Rng rng(11, 2);
    for (const Vec3& wo : c.wos) {
      SCOPED_TRACE(c.name + ", wo = " + str(wo));
      const ColorMean flux = sampledFlux(*c.m, hit, wo, rng, 40000);
      for (int k = 0; k < 3; ++k)
        EXPECT_NEAR(flux.c[k].mean(), c.expected[k], flux.c[k].tolerance(kFloatTol)) << "channel " << k;
    }
  }
}

TEST(MaterialEnergy, PhongWithKdPlusKsOneAndHighExponentConserves) {
  const SurfaceHit hit = flatHit();
  for (float exponent : {100.0f, 1000.0f, 10000.0f}) {
    const Phong phong(constant(Color(0.1f, 0.5f, 0.0f)), Color(0.9f, 0.5f, 1.0f), exponent);
    Rng rng(13, uint64_t(exponent));
    for (bool above : {true, false}) {
      for (float th : {0.0f, 1.0f, 5.0f, 20.0f, 45.0f, 70.0f, 88.0f}) {
        const Vec3 wo = direction(th, 2.1f, above);
        SCOPED_TRACE("exponent " + std::to_string(exponent) + ", wo = " + str(wo));
        const ColorMean flux = sampledFlux(phong, hit, wo, rng, 20000);
        for (int k = 0; k < 3; ++k)
          EXPECT_LE(flux.c[k].mean(), 1.0 + flux.c[k].tolerance(kFloatTol)) << "channel " << k;
      }
    }
  }
}

// ---------------------------------------------------------------------------------------------
// (b), (c) Non-delta lobes: sample / pdf / eval consistency and normalisation

std::vector<MaterialCase> nonDeltaCases() {
  return {
      {"lambertian", std::make_shared<Lambertian>(constant(kAlbedo))},
      {"phong", std::make_shared<Phong>(constant(kPhongKd), kPhongKs, 20.0f)},
      {"phong glossy only", std::make_shared<Phong>(constant(Color(0.0f)), Color(0.8f), 50.0f)},
      {"mixed", std::make_shared<Mixed>(mixedCoefficients())},
  };
}

TEST(MaterialSampling, PdfAndWeightMatchEvalAndPdf) {
  const SurfaceHit hit = flatHit();
  for (const MaterialCase& mc : nonDeltaCases()) {
    Rng rng(17, 3);
    for (const Vec3& wo : woDirections()) {
      SCOPED_TRACE(mc.name + ", wo = " + str(wo));
      int nonDelta = 0, failures = 0;
      for (int i = 0; i < 5000 && failures < 5; ++i) {
        BsdfSample s;
        const Vec2 u = next2(rng);
        if (!mc.material->sample(hit, wo, u, rng.uniform(), s) || s.delta) continue;
        ++nonDelta;
        const float pdf = mc.material->pdf(hit, wo, s.wi);
        const Color f = mc.material->eval(hit, wo, s.wi);
        const bool ok = std::abs(glm::length(s.wi) - 1.0f) < kFloatTol && s.pdf > 0.0f &&
                        std::abs(pdf - s.pdf) <= 1e-4f * s.pdf && s.eta == 1.0f &&
                        glm::all(glm::lessThanEqual(absolute(s.weight - f / s.pdf),
                                                    1e-4f * (f / s.pdf) + 1e-7f)) &&
                        wo.z * s.wi.z > 0.0f;  // a reflection
        if (!ok) {
          ++failures;
          ADD_FAILURE() << "wi " << str(s.wi) << ": sample pdf " << s.pdf << ", pdf() " << pdf << ", weight "
                        << str(s.weight) << ", eval / pdf " << str(f / s.pdf) << ", eta " << s.eta;
        }
      }
      EXPECT_GT(nonDelta, 0);
      // Delta materials have nothing here.
    }
  }
}

// The mean of sample()'s non-delta weights estimates the integral of eval over the directions the
// sampler can produce; an independent cosine-weighted estimate of the same integral must agree,
// which checks that the sampled directions follow the reported pdf.
TEST(MaterialSampling, SampledWeightsMatchIndependentIntegralOfEval) {
  const SurfaceHit hit = flatHit();
  for (const MaterialCase& mc : nonDeltaCases()) {
    Rng rng(19, 4);
    for (const Vec3& wo : woDirections()) {
      SCOPED_TRACE(mc.name + ", wo = " + str(wo));
      const int n = 100000;
      ColorMean sampled, reference;
      const Frame frame(wo.z >= 0.0f ? Vec3(0, 0, 1) : Vec3(0, 0, -1));
      for (int i = 0; i < n; ++i) {
        BsdfSample s;
        const Vec2 u = next2(rng);
        const bool ok = mc.material->sample(hit, wo, u, rng.uniform(), s);
        sampled.add(ok && !s.delta ? s.weight : Color(0.0f));
        const Vec3 local = sampleCosineHemisphere(next2(rng));
        if (local.z <= 0.0f) {
          reference.add(Color(0.0f));
          continue;
        }
        reference.add(mc.material->eval(hit, wo, frame.toWorld(local)) / cosineHemispherePdf(local.z));
      }
      for (int k = 0; k < 3; ++k) {
        const double tol = kSigmas * std::hypot(sampled.c[k].standardError(), reference.c[k].standardError());
        EXPECT_NEAR(sampled.c[k].mean(), reference.c[k].mean(), tol + kFloatTol) << "channel " << k;
      }
    }
  }
}

// Uniform-sphere estimate of the integral of pdf over all directions: at most 1 (exactly 1 for
// Lambertian; Phong at normal incidence loses nothing below the horizon; the mixed material's
// non-delta part carries the probability max(kd) + max(ks)).
TEST(MaterialSampling, PdfIntegratesToAtMostOne) {
  const SurfaceHit hit = flatHit();
  const MixedCoefficients mixed = mixedCoefficients();
  const double mixedNonDelta = maxComponent(mixed.kd->eval({})) + maxComponent(mixed.ks);
  for (const MaterialCase& mc : nonDeltaCases()) {
    Rng rng(23, 5);
    for (const Vec3& wo : woDirections()) {
      SCOPED_TRACE(mc.name + ", wo = " + str(wo));
      McMean integral;
      for (int i = 0; i < 200000; ++i)
        integral.add(mc.material->pdf(hit, wo, sampleUniformSphere(next2(rng))) / kUniformSpherePdf);
      EXPECT_LE(integral.mean(), 1.0 + integral.tolerance(kFloatTol));
      const bool normalIncidence = std::abs(wo.z) == 1.0f;
      if (mc.name == "lambertian" || (mc.name.starts_with("phong") && normalIncidence)) {
        EXPECT_NEAR(integral.mean(), 1.0, integral.tolerance(kFloatTol));
      }
      if (mc.name == "mixed" && normalIncidence) {
        EXPECT_NEAR(integral.mean(), mixedNonDelta, integral.tolerance(kFloatTol));
      }
    }
  }
}

TEST(MaterialSampling, DeltaMaterialsHaveNoEvalOrPdf) {
  const SurfaceHit hit = flatHit();
  for (const MaterialCase& mc : materialCases()) {
    const std::string& n = mc.name;
    if (n != "mirror" && n != "refraction" && n != "dielectric") continue;
    EXPECT_FALSE(mc.material->hasNonDeltaLobes()) << n;
    Rng rng(29, 6);
    for (int i = 0; i < 100; ++i) {
      const Vec3 wo = sampleUniformSphere(next2(rng)), wi = sampleUniformSphere(next2(rng));
      EXPECT_EQ(mc.material->pdf(hit, wo, wi), 0.0f) << n;
      EXPECT_TRUE(isBlack(mc.material->eval(hit, wo, wi))) << n;
    }
  }
  EXPECT_TRUE(Lambertian(constant(kAlbedo)).hasNonDeltaLobes());
  EXPECT_FALSE(Lambertian(constant(Color(0.0f))).hasNonDeltaLobes());
}

// ---------------------------------------------------------------------------------------------
// (d) Fresnel

// Independent double-precision Fresnel from the angle forms of the Fresnel equations:
// Rs = sin^2(ti - tt) / sin^2(ti + tt), Rp = tan^2(ti - tt) / tan^2(ti + tt), sin tt = sin ti / eta.
double fresnelReference(double cosI, double eta) {
  const double ti = std::acos(cosI);
  const double sinT = std::sin(ti) / eta;
  if (sinT >= 1.0) return 1.0;
  const double tt = std::asin(sinT);
  if (ti == 0.0) return std::pow((eta - 1.0) / (eta + 1.0), 2.0);
  const double rs = std::sin(ti - tt) / std::sin(ti + tt);
  const double rp = std::tan(ti - tt) / std::tan(ti + tt);
  return 0.5 * (rs * rs + rp * rp);
}

// What float evaluation can be held to: a few ulps of the result, plus the change that rounding
// cos(theta_i) to float (relative 2^-24) causes, which grows without bound at the critical angle.
double fresnelTolerance(double cosI, double eta) {
  const double h = 1e-7;
  const double slope = std::abs(fresnelReference(std::min(1.0, cosI + h), eta) -
                                fresnelReference(std::max(0.0, cosI - h), eta)) /
                       (std::min(1.0, cosI + h) - std::max(0.0, cosI - h));
  return 4.0 * kFloatTol + 4.0 * slope * cosI * std::numeric_limits<float>::epsilon();
}

TEST(FresnelDielectric, NormalIncidence) {
  EXPECT_NEAR(fresnelDielectric(1.0f, 1.5f), 0.04f, kFloatTol * 0.04f);         // ((n - 1) / (n + 1))^2
  EXPECT_NEAR(fresnelDielectric(1.0f, 1.0f / 1.5f), 0.04f, kFloatTol * 0.04f);  // same from inside
  EXPECT_NEAR(fresnelDielectric(1.0f, 1.0f), 0.0f, kFloatTol);                  // no interface
  EXPECT_NEAR(fresnelDielectric(0.3f, 1.0f), 0.0f, kFloatTol);
}

TEST(FresnelDielectric, BrewsterAngleReflectsOnlyS) {
  const double eta = 1.5;
  const double thetaB = std::atan(eta);
  // At Brewster's angle Rp = 0 and cos(theta_t) = eta cos(theta_i), so
  // Rs = ((cos - eta^2 cos) / (cos + eta^2 cos))^2 = ((1 - eta^2) / (1 + eta^2))^2.
  const double rs = std::pow((1.0 - eta * eta) / (1.0 + eta * eta), 2.0);
  const float F = fresnelDielectric(float(std::cos(thetaB)), float(eta));
  EXPECT_NEAR(F, 0.5 * rs, kFloatTol * 0.5 * rs);
  // And from the inside at its own Brewster angle atan(1 / eta): the same Rs.
  EXPECT_NEAR(fresnelDielectric(float(std::cos(std::atan(1.0 / eta))), float(1.0 / eta)), 0.5 * rs,
              kFloatTol * 0.5 * rs);
}

TEST(FresnelDielectric, TotalInternalReflectionBeyondCriticalAngle) {
  const double eta = 1.0 / 1.5;  // from glass into air
  const double critical = std::asin(eta);
  for (double t : {critical + 1e-3, critical + 0.1, 1.2, 1.5, kPiD / 2})
    EXPECT_EQ(fresnelDielectric(float(std::cos(t)), float(eta)), 1.0f) << "theta " << t;
  // Just inside the critical angle some light is still transmitted.
  const double cosBelow = std::cos(critical - 1e-2);
  EXPECT_LT(fresnelDielectric(float(cosBelow), float(eta)), 1.0f);
  EXPECT_NEAR(fresnelDielectric(float(cosBelow), float(eta)), fresnelReference(cosBelow, eta),
              fresnelTolerance(cosBelow, eta));
  // Grazing incidence from outside reflects everything too.
  EXPECT_NEAR(fresnelDielectric(0.0f, 1.5f), 1.0f, kFloatTol);
}

TEST(FresnelDielectric, MatchesAngleFormAndIsReciprocal) {
  for (double eta : {1.5, 1.0 / 1.5, 1.33, 2.4}) {
    for (int i = 1; i < 100; ++i) {
      const double cosI = i / 100.0;
      const float F = fresnelDielectric(float(cosI), float(eta));
      EXPECT_NEAR(F, fresnelReference(cosI, eta), fresnelTolerance(cosI, eta))
          << "eta " << eta << " cos " << cosI;
      EXPECT_GE(F, 0.0f);
      EXPECT_LE(F, 1.0f);
      // Stokes reciprocity: the same reflectance from the other side at the refracted angle.
      const double sinT = std::sqrt(1.0 - cosI * cosI) / eta;
      if (sinT < 1.0) {
        const double cosT = std::sqrt(1.0 - sinT * sinT);
        EXPECT_NEAR(F, fresnelDielectric(float(cosT), float(1.0 / eta)),
                    fresnelTolerance(cosI, eta) + fresnelTolerance(cosT, 1.0 / eta))
            << "eta " << eta << " cos " << cosI;
      }
    }
  }
}

// ---------------------------------------------------------------------------------------------
// (e) Specular materials

// wi is wo mirrored about +z / -z: same side, tangential part negated.
::testing::AssertionResult isMirrorOf(const Vec3& wo, const Vec3& wi) {
  if (glm::all(glm::lessThanEqual(absolute(wi - Vec3(-wo.x, -wo.y, wo.z)), Vec3(kFloatTol))))
    return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << str(wi) << " is not the mirror image of " << str(wo);
}

// wi is wo refracted through z = 0 with eta = eta_t / eta_i: the other side, in the plane of
// incidence on the far side of the normal, and sin(theta_t) eta = sin(theta_i).
::testing::AssertionResult isRefractionOf(const Vec3& wo, const Vec3& wi, float eta) {
  const float sinI = std::hypot(wo.x, wo.y), sinT = std::hypot(wi.x, wi.y);
  if (wo.z * wi.z >= 0.0f)
    return ::testing::AssertionFailure() << str(wi) << " does not cross the surface from " << str(wo);
  if (std::abs(glm::length(wi) - 1.0f) > kFloatTol)
    return ::testing::AssertionFailure() << str(wi) << " is not unit length";
  if (std::abs(sinT * eta - sinI) > 4.0f * kFloatTol)
    return ::testing::AssertionFailure() << "Snell: sin(theta_t) eta = " << sinT * eta
                                         << " but sin(theta_i) = " << sinI << " (eta " << eta << ")";
  if (sinI > 1e-4f && (std::abs(wi.x / sinT + wo.x / sinI) > 4.0f * kFloatTol ||
                       std::abs(wi.y / sinT + wo.y / sinI) > 4.0f * kFloatTol))
    return ::testing::AssertionFailure() << str(wi) << " leaves the plane of incidence of " << str(wo);
  return ::testing::AssertionSuccess();
}

TEST(MaterialMirror, ReflectsExactly) {
  const SurfaceHit hit = flatHit();
  const Mirror mirror(kMirrorR);
  Rng rng(31, 7);
  for (const Vec3& wo : woDirections()) {
    BsdfSample s;
    ASSERT_TRUE(mirror.sample(hit, wo, next2(rng), rng.uniform(), s)) << str(wo);
    EXPECT_TRUE(isMirrorOf(wo, s.wi));
    EXPECT_TRUE(s.delta);
    EXPECT_EQ(s.pdf, 1.0f);
    EXPECT_EQ(s.eta, 1.0f);
    EXPECT_EQ(s.weight, kMirrorR);
  }
}

TEST(MaterialRefraction, RefractsBySnellAndReflectsTotallyInside) {
  const SurfaceHit hit = flatHit();
  const Refraction refr(kTransmittance, kIor, 1.0f);
  const float critical = std::asin(1.0f / kIor) * 180.0f / kPi;  // 41.8 degrees
  Rng rng(37, 8);
  for (float th : {0.0f, 20.0f, 40.0f, 43.0f, 60.0f, 89.0f}) {
    for (bool above : {true, false}) {
      const Vec3 wo = direction(th, 0.4f, above);
      SCOPED_TRACE("wo = " + str(wo));
      BsdfSample s;
      ASSERT_TRUE(refr.sample(hit, wo, next2(rng), rng.uniform(), s));
      EXPECT_TRUE(s.delta);
      EXPECT_EQ(s.pdf, 1.0f);
      const bool tir = !above && th > critical;
      if (tir) {
        EXPECT_TRUE(isMirrorOf(wo, s.wi));
        EXPECT_EQ(s.eta, 1.0f);
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(s.weight[k], kTransmittance[k], kFloatTol);
      } else {
        const float eta = above ? kIor : 1.0f / kIor;
        EXPECT_NEAR(s.eta, eta, kFloatTol);
        EXPECT_TRUE(isRefractionOf(wo, s.wi, eta));
        for (int k = 0; k < 3; ++k)
          EXPECT_NEAR(s.weight[k], kTransmittance[k] / (eta * eta), kFloatTol) << "radiance scaling";
      }
    }
  }
}

// Reflection is chosen with probability F (binomial test) and reported with pdf F; refraction with
// pdf 1 - F follows Snell's law and carries 1 / eta^2.
TEST(MaterialDielectric, ChoosesReflectionWithFresnelProbability) {
  const SurfaceHit hit = flatHit();
  const Dielectric glass(kIor, 1.0f);
  const float critical = std::asin(1.0f / kIor) * 180.0f / kPi;
  Rng rng(41, 9);
  for (float th : {0.0f, 30.0f, 56.31f, 75.0f, 89.0f}) {
    for (bool above : {true, false}) {
      const Vec3 wo = direction(th, 1.3f, above);
      SCOPED_TRACE("wo = " + str(wo));
      const float eta = above ? kIor : 1.0f / kIor;
      const double F = fresnelReference(std::abs(double(wo.z)), eta);
      if (!above && th > critical) {
        EXPECT_EQ(F, 1.0);
      }
      const int n = 20000;
      int reflected = 0, failures = 0;
      for (int i = 0; i < n && failures < 5; ++i) {
        BsdfSample s;
        ASSERT_TRUE(glass.sample(hit, wo, next2(rng), rng.uniform(), s));
        bool ok = s.delta;
        if (s.wi.z * wo.z > 0.0f) {
          ++reflected;
          ok = ok && isMirrorOf(wo, s.wi) && s.eta == 1.0f && std::abs(s.pdf - F) <= 4.0 * kFloatTol &&
               s.weight == Color(1.0f);
        } else {
          ok = ok && isRefractionOf(wo, s.wi, eta) && std::abs(s.eta - eta) <= kFloatTol &&
               std::abs(s.pdf - (1.0 - F)) <= 4.0 * kFloatTol &&
               glm::all(glm::lessThanEqual(absolute(s.weight - Color(1.0f / (eta * eta))), Color(kFloatTol)));
        }
        if (!ok) {
          ++failures;
          ADD_FAILURE() << "sample wi " << str(s.wi) << " pdf " << s.pdf << " weight " << str(s.weight)
                        << " eta " << s.eta << " delta " << s.delta << "; F = " << F << ", "
                        << isMirrorOf(wo, s.wi).message() << " / " << isRefractionOf(wo, s.wi, eta).message();
        }
      }
      const double frac = double(reflected) / n;
      const double sigma = std::sqrt(F * (1.0 - F) / n);
      EXPECT_NEAR(frac, F, kSigmas * sigma + 1.0 / n) << "fraction reflected";
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Mixed

// The lobes are chosen with probabilities max(kd), max(ks), max(kr), max(kt); the rest absorbs.
TEST(MaterialMixed, AbsorbsWithProbabilityOneMinusSumOfMaxima) {
  const SurfaceHit hit = flatHit();
  const MixedCoefficients c = mixedCoefficients();
  const Mixed mixed(c);
  const double pd = maxComponent(c.kd->eval({})), ps = maxComponent(c.ks);
  const double pr = maxComponent(c.kr), pt = maxComponent(c.kt);
  const double pSum = pd + ps + pr + pt;

  // Deterministically: any uLobe at or past the sum of the maxima absorbs.
  Rng rng(43, 10);
  for (const Vec3& wo : woDirections())
    for (int i = 0; i < 200; ++i) {
      const float uLobe = float(pSum) + 1e-4f + float(1.0 - pSum - 2e-4) * (i / 199.0f);
      BsdfSample s;
      EXPECT_FALSE(mixed.sample(hit, wo, next2(rng), uLobe, s)) << "uLobe " << uLobe << " wo " << str(wo);
    }

  // Statistically, at normal incidence (where no lobe sample can fall below the horizon):
  // absorbed 1 - sum, mirror pr, refraction pt, non-delta pd + ps.
  for (const Vec3& wo : {Vec3(0, 0, 1), Vec3(0, 0, -1)}) {
    SCOPED_TRACE("wo = " + str(wo));
    const int n = 40000;
    int absorbed = 0, mirror = 0, refracted = 0, nonDelta = 0;
    for (int i = 0; i < n; ++i) {
      BsdfSample s;
      const Vec2 u = next2(rng);
      if (!mixed.sample(hit, wo, u, rng.uniform(), s)) {
        ++absorbed;
      } else if (!s.delta) {
        ++nonDelta;
      } else if (s.wi.z * wo.z > 0.0f) {
        ++mirror;
        EXPECT_TRUE(isMirrorOf(wo, s.wi));
        EXPECT_NEAR(s.pdf, pr, kFloatTol);
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(s.weight[k], c.kr[k] / pr, kFloatTol);
      } else {
        ++refracted;
        const float eta = wo.z > 0.0f ? c.ior : 1.0f / c.ior;
        EXPECT_TRUE(isRefractionOf(wo, s.wi, eta));
        EXPECT_NEAR(s.pdf, pt, kFloatTol);
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(s.weight[k], c.kt[k] / pt / (eta * eta), kFloatTol);
      }
    }
    auto expectFraction = [n](int count, double p, const char* what) {
      EXPECT_NEAR(double(count) / n, p, kSigmas * std::sqrt(p * (1.0 - p) / n) + 1.0 / n) << what;
    };
    expectFraction(absorbed, 1.0 - pSum, "absorbed");
    expectFraction(mirror, pr, "mirror");
    expectFraction(refracted, pt, "refracted");
    expectFraction(nonDelta, pd + ps, "diffuse + glossy");
  }
}

TEST(MaterialMixed, TransmissionTotallyReflectsInside) {
  const SurfaceHit hit = flatHit();
  MixedCoefficients c;
  c.kd = constant(Color(0.0f));
  c.kt = Color(0.8f);
  c.ior = kIor;
  const Mixed mixed(c);
  Rng rng(47, 11);
  const Vec3 wo = direction(60.0f, 0.2f, false);  // inside, beyond the critical angle
  BsdfSample s;
  ASSERT_TRUE(mixed.sample(hit, wo, next2(rng), 0.5f, s));
  EXPECT_TRUE(isMirrorOf(wo, s.wi));
  EXPECT_EQ(s.eta, 1.0f);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(s.weight[k], 1.0f, kFloatTol);
  EXPECT_FALSE(mixed.sample(hit, wo, next2(rng), 0.9f, s)) << "uLobe past kt absorbs";
}

}  // namespace
}  // namespace ember

namespace ember {
namespace {

// evalPdf is what next-event estimation calls; materials that override it to share work must
// return exactly eval and pdf, on both sides, above and below the horizon.
TEST(MaterialEvalPdf, EqualsEvalAndPdf) {
  const SurfaceHit hit = flatHit();
  for (const MaterialCase& mc : materialCases()) {
    Rng rng(29, 5);
    for (const Vec3& wo : woDirections()) {
      SCOPED_TRACE(mc.name + ", wo = " + str(wo));
      for (int i = 0; i < 500; ++i) {
        const Vec3 wi = sampleUniformSphere(next2(rng));
        float pdf = -1.0f;
        const Color f = mc.material->evalPdf(hit, wo, wi, pdf);
        ASSERT_EQ(pdf, mc.material->pdf(hit, wo, wi)) << "wi " << str(wi);
        ASSERT_EQ(f, mc.material->eval(hit, wo, wi)) << "wi " << str(wi);
      }
    }
  }
}

}  // namespace
}  // namespace ember
