// Chi-square goodness-of-fit tests of every sampling routine against the density it reports,
// in the spirit of pbrt-v4's bsdfs_test.cpp and Mitsuba 3's chi2 tests (independent code).
//
// Method, for a routine that draws directions w with a claimed solid-angle density pdf(w):
//  - Directions are binned on the unit sphere in a (cos theta, phi) grid around a chosen pole
//    (equal-area cells, since d(omega) = d(cos theta) d(phi)). A grid may cover only the cap
//    cos theta >= zMin around the pole (to zoom onto a small light seen from afar); everything
//    below zMin is one extra cell. Samples the routine rejects (absorbed paths, failed light
//    samples, delta lobes) are not binned; they only count against the normalisation (below).
//  - Expected counts: N times the integral of pdf over each cell, by the midpoint rule on a k x k
//    sub-grid in (cos theta, phi); cells where the pdf varies a lot across the sub-grid (an edge
//    of a light or a hemisphere, a narrow lobe) are integrated again on a much finer sub-grid.
//    Conditional on the number S of successful samples the counts are multinomial, so a cell
//    expects S (integral over the cell) / (integral over the sphere).
//  - Cells expecting fewer than 5 samples are pooled into one cell (topping the pool up with the
//    next smallest cells until it expects at least 5), the usual validity condition of the test.
//  - Pearson's chi-square over the cells, p-value from the chi-square distribution with
//    (cells - 1) degrees of freedom via the regularized upper incomplete gamma function
//    (Numerical Recipes, 3rd ed., section 6.2: series and Lentz continued fraction).
//  - Rejection at alpha = 0.01 for the whole file: with m independent cases the Sidak-corrected
//    level per case is 1 - (1 - alpha)^(1/m). kNumCases declares m and a test checks it equals the
//    number of registered cases; every case runs exactly one chi-square test (checked too).
//  - Besides: the pdf integrates to at most 1 (+ the integration tolerance) over the sphere, and
//    the fraction of successful samples matches that integral within the binomial standard error
//    times the Sidak-corrected normal quantile (+ the integration tolerance).
//
// Shapes (light sampling seen from a reference point). The direction from ref towards a sampled
// point has density pdfSolidAngle(ref, p, n) only if no other sampled surface point lies along the
// same direction; otherwise the direction density is the sum over all points on that ray. Hence:
//  - Convex flat shapes (Disc, Triangle, Quad) seen from any point off their plane: each direction
//    meets the shape at most once, so directions are tested against pdfSolidAngle directly. This
//    covers both strategies of Quad: area sampling (general quads, and rectangles subtending a tiny
//    solid angle) and uniform spherical-rectangle sampling of rectangles (close, oblique, behind).
//  - The sphere seen from outside samples the cone it subtends and returns only the visible
//    point: one point per direction, tested directly as well (three distances, one of them in the
//    small-angle Taylor branch).
//  - Closed shapes that are area sampled (Sphere from inside, Cylinder and Cone with caps, Box,
//    FlippedShape(Sphere) from inside): tested from a reference point INSIDE the (convex) shape,
//    where every direction meets the surface exactly once, so the direction density is exactly
//    pdfSolidAngle(ref, p(w), n(w)) = d^2 / (A |cos|). Area sampling does not depend on ref at
//    all, so this tests the area distribution of sampleArea (uniform over every face, side, cap
//    and the split between them) together with the area-to-solid-angle conversion; from outside
//    the same formula applies per point, only the per-direction density would be a sum over the
//    near and far side, which is why no exterior ref is used for them.
//
// Lights: AreaLight(Quad) and TriangleLight directions against Light::pdf; the LightSampler's
// choice of light against the lights' power (chi-square over the light index); and the full
// next-event mixture (sampler choice, then the chosen light's sample) against
// sum_i pmf_i pdf_i(w), with pmf_i computed here from the powers, not taken from the sampler.
//
// A last case feeds Lambertian samples to the machinery with a wrong (uniform hemisphere) pdf and
// expects the test to reject, so a silently permissive test would be noticed.

#include "accel/box.h"
#include "accel/cone.h"
#include "accel/cylinder.h"
#include "accel/disc.h"
#include "accel/flipped_shape.h"
#include "accel/sphere.h"
#include "accel/triangle.h"
#include "accel/triangle_mesh.h"
#include "core/alias_table.h"
#include "core/rng.h"
#include "core/sampling.h"
#include "materials/gltf_pbr.h"
#include "materials/lambertian.h"
#include "materials/mixed.h"
#include "materials/phong.h"
#include "materials/texture.h"
#include "renderer/caustic_tracer.h"
#include "renderer/light.h"
#include "renderer/light_sampler.h"
#include "test_fixtures.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <functional>
#include <future>
#include <iostream>
#include <memory>
#include <numbers>
#include <numeric>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace ember {
namespace {

// ---------------------------------------------------------------------------------------------
// Parameters of the test as a whole.

constexpr double kAlpha = 0.01;     // family-wise significance level over every case in the file
constexpr int kNumCases = 79;       // m for the Sidak correction: must equal allCases().size()
constexpr long kSamples = 1000000;  // samples per case
constexpr double kMinExpected = 5.0;
// Absolute error allowed on integrals of the pdf over the sphere: the midpoint rule on the
// refined sub-grids is far more accurate (errors ~1e-5 on the discontinuous cases here), this only
// absorbs the float rounding of the pdfs and the O(sin^2) Taylor branch of the sphere's cone.
constexpr double kIntegralTol = 1e-3;
constexpr int kCoarseSub = 8;  // k x k midpoint sub-grid per cell
constexpr int kFineSub = 64;   // sub-grid where the pdf varies by more than kRefineRatio
constexpr double kRefineRatio = 1.5;
constexpr double kPiD = std::numbers::pi;

double sidakAlpha() {
  return 1.0 - std::pow(1.0 - kAlpha, 1.0 / double(kNumCases));
}

// Two-sided standard normal quantile: z with erfc(z / sqrt 2) = a, by bisection.
double normalQuantileTwoSided(double a) {
  double lo = 0.0, hi = 40.0;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (std::erfc(mid / std::numbers::sqrt2) > a ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

// ---------------------------------------------------------------------------------------------
// Regularized upper incomplete gamma function Q(a, x) = Gamma(a, x) / Gamma(a) (Numerical Recipes
// 3rd ed., section 6.2): the power series for P = 1 - Q when x < a + 1, the continued fraction
// (modified Lentz) otherwise. The chi-square survival function is Q(dof / 2, chi2 / 2).

double gammaQ(double a, double x) {
  if (x <= 0.0) return 1.0;
  const double logPrefactor = -x + a * std::log(x) - std::lgamma(a);
  if (x < a + 1.0) {
    double ap = a, del = 1.0 / a, sum = del;
    for (int n = 0; n < 100000; ++n) {
      ap += 1.0;
      del *= x / ap;
      sum += del;
      if (std::abs(del) < std::abs(sum) * 1e-16) break;
    }
    return std::clamp(1.0 - sum * std::exp(logPrefactor), 0.0, 1.0);
  }
  constexpr double kTiny = 1e-300;
  double b = x + 1.0 - a, c = 1.0 / kTiny, d = 1.0 / b, h = d;
  for (int i = 1; i < 100000; ++i) {
    const double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::abs(d) < kTiny) d = kTiny;
    c = b + an / c;
    if (std::abs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    const double del = d * c;
    h *= del;
    if (std::abs(del - 1.0) < 1e-16) break;
  }
  return std::clamp(std::exp(logPrefactor) * h, 0.0, 1.0);
}

double chi2Survival(double chi2, int dof) {
  return gammaQ(0.5 * dof, 0.5 * chi2);
}

// ---------------------------------------------------------------------------------------------
// Pearson's chi-square with pooling of the sparse cells.

struct Chi2Outcome {
  double chi2 = 0.0;
  int dof = 0;
  double pValue = 1.0;
  int cells = 0;        // cells after pooling
  int pooledCells = 0;  // original cells that went into the pool
  std::string worst;    // the cells contributing most, for the failure message
};

int g_chi2Runs = 0;  // chi-square tests evaluated so far (each case must run exactly one)

Chi2Outcome chi2Test(const std::vector<double>& observed, const std::vector<double>& expected,
                     const std::function<std::string(size_t)>& label) {
  ++g_chi2Runs;
  const size_t n = observed.size();
  std::vector<size_t> order(n);
  std::iota(order.begin(), order.end(), size_t(0));
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return expected[a] < expected[b]; });

  Chi2Outcome r;
  double poolObs = 0.0, poolExp = 0.0;
  size_t i = 0;
  while (i < n && (expected[order[i]] < kMinExpected || (r.pooledCells > 0 && poolExp < kMinExpected))) {
    poolObs += observed[order[i]];
    poolExp += expected[order[i]];
    ++r.pooledCells;
    ++i;
  }
  struct Term {
    double value;
    std::string what;
  };
  std::vector<Term> terms;
  auto add = [&](double o, double e, const std::string& what) {
    const double t = e > 0.0 ? (o - e) * (o - e) / e : (o > 0.0 ? kInfinity : 0.0);
    r.chi2 += t;
    ++r.cells;
    std::ostringstream s;
    s << what << ": observed " << o << ", expected " << e;
    terms.push_back({t, s.str()});
  };
  for (; i < n; ++i) add(observed[order[i]], expected[order[i]], label(order[i]));
  if (r.pooledCells > 0) add(poolObs, poolExp, "pool of " + std::to_string(r.pooledCells) + " cells");
  r.dof = std::max(1, r.cells - 1);
  r.pValue = std::isfinite(r.chi2) ? chi2Survival(r.chi2, r.dof) : 0.0;

  std::sort(terms.begin(), terms.end(), [](const Term& a, const Term& b) { return a.value > b.value; });
  std::ostringstream s;
  for (size_t k = 0; k < std::min<size_t>(5, terms.size()); ++k)
    s << "\n    chi2 term " << terms[k].value << " from " << terms[k].what;
  r.worst = s.str();
  return r;
}

// ---------------------------------------------------------------------------------------------
// The sphere grid.

using SampleFn = std::function<bool(Rng&, Vec3&)>;  // false: no direction (failed / absorbed)
using PdfFn = std::function<double(const Vec3&)>;   // claimed solid-angle density

struct SphereGrid {
  Vec3 pole{0.0f, 0.0f, 1.0f};
  double zMin = -1.0;  // the cells cover cos theta in [zMin, 1]; the rest is one cell
  int nz = 40, nphi = 80;
};

struct Basis {
  glm::dvec3 s, t, n;
  explicit Basis(const Vec3& pole) {
    const Frame f(glm::normalize(pole));
    n = glm::normalize(glm::dvec3(f.n));
    s = glm::normalize(glm::dvec3(f.s) - glm::dot(glm::dvec3(f.s), n) * n);
    t = glm::cross(n, s);
  }
  Vec3 direction(double z, double phi) const {
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    return Vec3(glm::normalize(s * (r * std::cos(phi)) + t * (r * std::sin(phi)) + n * z));
  }
};

// Midpoint rule on a k x k sub-grid of the cell [z0, z1] x [phi0, phi1], midpoints taken in the
// polar angle theta = acos z (weight sin theta, rescaled so the weights sum to the cell's exact
// solid angle): uniform in z would squeeze the sub-samples of the rows at the poles into a tiny
// band of angles and miss features there. Also reports the range of the sub-samples' values.
struct CellIntegral {
  double value = 0.0, lo = kInfinity, hi = 0.0;
};
CellIntegral midpoint(const Basis& b, double z0, double z1, double phi0, double phi1, int k,
                      const PdfFn& pdf) {
  const double theta0 = std::acos(std::clamp(z1, -1.0, 1.0));
  const double theta1 = std::acos(std::clamp(z0, -1.0, 1.0));
  CellIntegral r;
  double sum = 0.0, weights = 0.0;
  for (int i = 0; i < k; ++i) {
    const double theta = theta0 + (theta1 - theta0) * (i + 0.5) / k;
    const double w = std::sin(theta);
    weights += w;
    for (int j = 0; j < k; ++j) {
      const double v = pdf(b.direction(std::cos(theta), phi0 + (phi1 - phi0) * (j + 0.5) / k));
      sum += w * v;
      r.lo = std::min(r.lo, v);
      r.hi = std::max(r.hi, v);
    }
  }
  r.value = weights > 0.0 ? sum / (weights * k) * (z1 - z0) * (phi1 - phi0) : 0.0;
  return r;
}

// fn(0) ... fn(n - 1) on a few threads (fn must be safe to call concurrently).
void parallelFor(int n, const std::function<void(int)>& fn) {
  std::atomic<int> next{0};
  auto worker = [&] {
    for (int i = next++; i < n; i = next++) fn(i);
  };
  const int threads = int(std::clamp(std::thread::hardware_concurrency(), 1u, 4u));
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(worker);
  worker();
  for (std::thread& t : pool) t.join();
}

// Integrals of pdf over the nz x nphi cells of [z0, z1] x [0, 2 pi), row-major. Coarse sub-grid
// first; a cell is integrated again on the fine sub-grid when the pdf varies by more than
// kRefineRatio over the coarse sub-samples of the cell and its neighbours. Looking at the
// neighbours catches an edge (of a light, of a hemisphere) that only clips a cell between its
// coarse sub-samples: the neighbour on the other side of the edge then differs. The cells of a
// row touching a pole all meet there, so for them the neighbours are that row and the next one.
std::vector<double> integrateGrid(const Basis& b, double z0, double z1, int nz, int nphi, const PdfFn& pdf) {
  const double dz = (z1 - z0) / nz, dphi = 2.0 * kPiD / nphi;
  std::vector<CellIntegral> coarse(size_t(nz * nphi));
  parallelFor(nz, [&](int iz) {
    for (int ip = 0; ip < nphi; ++ip)
      coarse[size_t(iz * nphi + ip)] =
          midpoint(b, z0 + iz * dz, z0 + (iz + 1) * dz, ip * dphi, (ip + 1) * dphi, kCoarseSub, pdf);
  });
  auto range = [&](int izLo, int izHi, int ipLo, int ipHi, double& lo, double& hi) {
    for (int jz = std::max(0, izLo); jz <= std::min(nz - 1, izHi); ++jz) {
      for (int jp = ipLo; jp <= ipHi; ++jp) {
        const CellIntegral& c = coarse[size_t(jz * nphi + (jp + nphi) % nphi)];
        lo = std::min(lo, c.lo);
        hi = std::max(hi, c.hi);
      }
    }
  };
  std::vector<double> out(coarse.size());
  parallelFor(nz, [&](int iz) {
    const bool southPole = iz == 0 && z0 <= -1.0, northPole = iz == nz - 1 && z1 >= 1.0;
    for (int ip = 0; ip < nphi; ++ip) {
      double lo = kInfinity, hi = 0.0;
      range(iz - 1, iz + 1, ip - 1, ip + 1, lo, hi);
      if (southPole) range(0, 1, 0, nphi - 1, lo, hi);
      if (northPole) range(nz - 2, nz - 1, 0, nphi - 1, lo, hi);
      const size_t cell = size_t(iz * nphi + ip);
      out[cell] =
          hi > kRefineRatio * lo
              ? midpoint(b, z0 + iz * dz, z0 + (iz + 1) * dz, ip * dphi, (ip + 1) * dphi, kFineSub, pdf).value
              : coarse[cell].value;
    }
  });
  return out;
}

struct DirectionalCase {
  SphereGrid grid;
  long samples = kSamples;
  uint64_t seed = 1;
  SampleFn sample;
  PdfFn pdf;
  bool expectReject = false;  // the deliberately wrong pdf
};

struct CaseSummary {
  double pValue, integral, successFraction;
};

void report(const std::string& what, const Chi2Outcome& r, double integral, double success) {
  std::ostringstream s;
  s.precision(4);
  s << "[chi2] " << what << ": chi2 " << r.chi2 << ", dof " << r.dof << ", p " << r.pValue << ", pooled "
    << r.pooledCells << ", integral " << integral << ", success " << success;
  std::cout << s.str() << std::endl;
}

std::string currentTestName() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  return info ? std::string(info->name()) : std::string("?");
}

// Decides the case from its p-value at the Sidak-corrected level.
void judge(const Chi2Outcome& r, bool expectReject) {
  const double level = sidakAlpha();
  if (expectReject) {
    EXPECT_LT(r.pValue, level) << "a wrong pdf was not rejected: chi2 " << r.chi2 << ", dof " << r.dof;
  } else {
    EXPECT_GE(r.pValue, level) << "samples do not follow the pdf: chi2 " << r.chi2 << ", dof " << r.dof
                               << ", Sidak level " << level << r.worst;
  }
}

CaseSummary runDirectional(const DirectionalCase& c) {
  const SphereGrid& g = c.grid;
  const Basis basis(g.pole);
  const int gridCells = g.nz * g.nphi;
  const int outsideCell = gridCells;
  const double dz = (1.0 - g.zMin) / g.nz, dphi = 2.0 * kPiD / g.nphi;

  // Expected, integrated on other threads while this one samples (pdfs are const and pure).
  std::future<std::vector<double>> inGridFuture =
      std::async(std::launch::async, [&] { return integrateGrid(basis, g.zMin, 1.0, g.nz, g.nphi, c.pdf); });
  std::future<std::vector<double>> belowFuture = std::async(std::launch::async, [&] {
    return g.zMin > -1.0 ? integrateGrid(basis, -1.0, g.zMin, 20, g.nphi, c.pdf) : std::vector<double>{};
  });

  // Observed.
  std::vector<double> observed(size_t(gridCells + 1), 0.0);
  Rng rng(c.seed, 0x5eed);
  long successes = 0;
  for (long k = 0; k < c.samples; ++k) {
    Vec3 w;
    if (!c.sample(rng, w) || !(glm::dot(w, w) > 0.0f)) continue;
    ++successes;
    const glm::dvec3 d = glm::normalize(glm::dvec3(w));
    const double z = std::clamp(glm::dot(d, basis.n), -1.0, 1.0);
    int cell = outsideCell;
    if (z >= g.zMin) {
      const int iz = std::clamp(int((z - g.zMin) / dz), 0, g.nz - 1);
      double phi = std::atan2(glm::dot(d, basis.t), glm::dot(d, basis.s));
      if (phi < 0.0) phi += 2.0 * kPiD;
      const int ip = std::clamp(int(phi / dphi), 0, g.nphi - 1);
      cell = iz * g.nphi + ip;
    }
    observed[size_t(cell)] += 1.0;
  }

  std::vector<double> expected = inGridFuture.get();
  const std::vector<double> below = belowFuture.get();
  expected.push_back(std::accumulate(below.begin(), below.end(), 0.0));  // the outside cell
  const double integral = std::accumulate(expected.begin(), expected.end(), 0.0);
  // Conditional on the number of successful samples S, the cell counts are multinomial with
  // probabilities (integral over the cell) / (integral over the sphere): the chi-square tests the
  // shape of the distribution, and the normalisation (S / N against the integral) is tested
  // separately below. Conditioning keeps the test exact while the failed samples have a tiny
  // probability, where a "failed" cell expecting N (1 - integral) would be dominated by the
  // (small, but not small against 1 / N) integration error.
  const double n = double(c.samples);
  for (double& e : expected) e *= integral > 0.0 ? double(successes) / integral : 0.0;

  auto label = [&](size_t cell) -> std::string {
    if (int(cell) == outsideCell) return "cells below zMin";
    std::ostringstream s;
    const int iz = int(cell) / g.nphi, ip = int(cell) % g.nphi;
    s << "cos theta [" << g.zMin + iz * dz << ", " << g.zMin + (iz + 1) * dz << "], phi [" << ip * dphi
      << ", " << (ip + 1) * dphi << "]";
    return s.str();
  };
  const Chi2Outcome r = chi2Test(observed, expected, label);
  const double success = double(successes) / n;
  report(currentTestName(), r, integral, success);

  // The pdf integrates to at most one, and to the probability that a sample is produced.
  EXPECT_LE(integral, 1.0 + kIntegralTol);
  const double p = std::clamp(integral, 0.0, 1.0);
  const double tol = normalQuantileTwoSided(sidakAlpha()) * std::sqrt(p * (1.0 - p) / n) + kIntegralTol;
  EXPECT_NEAR(success, integral, tol) << "fraction of successful samples vs integral of the pdf";
  judge(r, c.expectReject);
  return {r.pValue, integral, success};
}

// Relative agreement of two densities computed along different float paths.
bool densitiesAgree(double a, double b) {
  return std::abs(a - b) <= 1e-3 * std::max(a, b) + 1e-6;
}

// ---------------------------------------------------------------------------------------------
// Materials.

using test::flatHit;

std::shared_ptr<const Texture> constant(const Color& c) {
  return std::make_shared<ConstantTexture>(c);
}

// Material sampling: the non-delta samples must follow pdf(wo, wi); delta samples and absorbed
// paths count as failed (pdf integrates to the probability of a non-delta, non-absorbed sample).
void runMaterial(std::shared_ptr<const Material> m, Vec3 wo, uint64_t seed, bool wrongPdf = false,
                 const VertexAttributes* attributes = nullptr) {
  SurfaceHit hit = flatHit();
  hit.attributes = attributes;
  wo = glm::normalize(wo);
  long inconsistent = 0;
  DirectionalCase c;
  c.seed = seed;
  c.sample = [&](Rng& rng, Vec3& wi) {
    const Vec2 u(rng.uniform(), rng.uniform());
    const float uLobe = rng.uniform();
    BsdfSample bs;
    if (!m->sample(hit, wo, u, uLobe, bs) || bs.delta) return false;
    if (!densitiesAgree(bs.pdf, m->pdf(hit, wo, bs.wi))) ++inconsistent;
    wi = bs.wi;
    return true;
  };
  if (wrongPdf) {
    // Deliberately wrong: uniform over the hemisphere of wo instead of cosine-weighted.
    c.pdf = [&](const Vec3& wi) { return wi.z * wo.z > 0.0f ? 1.0 / (2.0 * kPiD) : 0.0; };
    c.expectReject = true;
  } else {
    c.pdf = [&](const Vec3& wi) { return double(m->pdf(hit, wo, wi)); };
  }
  runDirectional(c);
  EXPECT_EQ(inconsistent, 0) << "BsdfSample::pdf differs from pdf(wo, wi)";
}

// ---------------------------------------------------------------------------------------------
// Shapes.

// A grid whose cells cover the cone around the direction from ref to a bounding sphere (with a
// margin, so the cone's edge falls inside the cells, where it is integrated on the fine grid).
SphereGrid zoomedGrid(const Vec3& ref, const Vec3& center, double radius) {
  SphereGrid g;
  const glm::dvec3 d = glm::dvec3(center) - glm::dvec3(ref);
  const double dist = glm::length(d);
  g.pole = Vec3(d / dist);
  const double sin2 = std::min(1.0, radius * radius / (dist * dist));
  const double oneMinusCos = sin2 / (1.0 + std::sqrt(1.0 - sin2));
  g.zMin = std::max(-1.0, 1.0 - 1.25 * oneMinusCos);
  return g;
}

// Density of the direction w from ref under shape.sampleSolidAngle, where w meets the shape at
// most once (see the header comment): pdfSolidAngle at that point, zero if w misses.
PdfFn shapeDirectionPdf(const Shape& shape, const Vec3& ref) {
  return [&shape, ref](const Vec3& w) -> double {
    LocalHit h;
    if (!shape.intersect(Ray{ref, w}, 0.0f, kInfinity, h)) return 0.0;
    return shape.pdfSolidAngle(ref, ref + h.t * w, h.ng);
  };
}

void runShape(const Shape& shape, const Vec3& ref, const SphereGrid& grid, uint64_t seed) {
  long inconsistent = 0;
  DirectionalCase c;
  c.grid = grid;
  c.seed = seed;
  c.sample = [&](Rng& rng, Vec3& w) {
    const Vec2 u(rng.uniform(), rng.uniform());
    ShapeSample s;
    float pdf;
    if (!shape.sampleSolidAngle(ref, u, s, pdf)) return false;
    if (!densitiesAgree(pdf, shape.pdfSolidAngle(ref, s.p, s.n))) ++inconsistent;
    w = s.p - ref;
    return true;
  };
  c.pdf = shapeDirectionPdf(shape, ref);
  runDirectional(c);
  EXPECT_EQ(inconsistent, 0) << "sampleSolidAngle's pdf differs from pdfSolidAngle";
}

// A full-sphere grid with a pole in no special direction, for interior reference points.
SphereGrid tiltedGrid() {
  SphereGrid g;
  g.pole = glm::normalize(Vec3(0.3f, 0.5f, 0.8f));
  return g;
}

const Vec3 kSphereCenter(0.3f, -0.2f, 0.5f);
constexpr float kSphereRadius = 1.0f;
const Vec3 kOffAxis = glm::normalize(Vec3(1.0f, 2.0f, -0.5f));

void sphereFrom(float distanceInRadii, bool flipped, uint64_t seed) {
  std::unique_ptr<Shape> shape = std::make_unique<Sphere>(kSphereCenter, kSphereRadius);
  if (flipped) shape = std::make_unique<FlippedShape>(std::move(shape));
  const Vec3 ref = kSphereCenter + distanceInRadii * kSphereRadius * kOffAxis;
  const SphereGrid grid =
      distanceInRadii > 1.0f ? zoomedGrid(ref, kSphereCenter, kSphereRadius) : tiltedGrid();
  runShape(*shape, ref, grid, seed);
}

// A frame to place planar shapes and the box in no special orientation.
const Frame kPlacement(glm::normalize(Vec3(0.3f, -0.5f, 0.8f)));
Vec3 placed(const Vec3& origin, float x, float y) {
  return origin + x * kPlacement.s + y * kPlacement.t;
}

double boundingRadius(const std::vector<Vec3>& pts, Vec3& center) {
  center = Vec3(0.0f);
  for (const Vec3& p : pts) center += p / float(pts.size());
  double r = 0.0;
  for (const Vec3& p : pts) r = std::max(r, double(glm::length(p - center)));
  return r;
}

void flatShape(const Shape& shape, const std::vector<Vec3>& pts, const Vec3& ref, uint64_t seed) {
  Vec3 center;
  const double r = boundingRadius(pts, center);
  runShape(shape, ref, zoomedGrid(ref, center, r), seed);
}

const Vec3 kQuadOrigin(0.2f, 0.4f, -0.1f);
std::array<Vec3, 4> quadVertices() {
  // Planar, convex, not a parallelogram, and its two triangles have different areas.
  return {placed(kQuadOrigin, 0.0f, 0.0f), placed(kQuadOrigin, 2.0f, 0.0f), placed(kQuadOrigin, 2.5f, 1.5f),
          placed(kQuadOrigin, -0.3f, 1.0f)};
}
const std::array<Vec2, 4> kQuadUv = {Vec2(0, 0), Vec2(1, 0), Vec2(1, 1), Vec2(0, 1)};

std::array<Vec3, 3> triangleVertices() {
  return {Vec3(-0.4f, 0.1f, 0.3f), Vec3(1.1f, -0.2f, 0.6f), Vec3(0.2f, 0.9f, -0.5f)};
}

// ---------------------------------------------------------------------------------------------
// Lights.

TriangleMesh lightMesh() {
  TriangleMesh mesh;
  mesh.positions = {Vec3(-1.0f, 2.0f, 0.0f), Vec3(0.5f, 2.2f, 0.3f), Vec3(-0.2f, 2.1f, 1.4f),
                    Vec3(1.0f, 2.5f, 1.5f)};
  mesh.indices = {glm::uvec3(0, 1, 2), glm::uvec3(1, 3, 2)};
  return mesh;
}

// Density of direction w from ref for the TriangleLight of triangle `prim`.
PdfFn triangleLightPdf(const TriangleMesh& mesh, uint32_t prim, const Light& light, const Vec3& ref) {
  return [&mesh, prim, &light, ref](const Vec3& w) -> double {
    const glm::uvec3 idx = mesh.indices[prim];
    const Vec3 &a = mesh.positions[idx.x], &b = mesh.positions[idx.y], &c = mesh.positions[idx.z];
    float t, b1, b2;
    if (!intersectTriangle(Ray{ref, w}, a, b, c, 0.0f, kInfinity, t, b1, b2)) return 0.0;
    return light.pdf(ref, ref + t * w, glm::normalize(glm::cross(b - a, c - a)));
  };
}

PdfFn areaLightPdf(const Shape& shape, const Light& light, const Vec3& ref) {
  return [&shape, &light, ref](const Vec3& w) -> double {
    LocalHit h;
    if (!shape.intersect(Ray{ref, w}, 0.0f, kInfinity, h)) return 0.0;
    return light.pdf(ref, ref + h.t * w, h.ng);
  };
}

SampleFn lightSampleFn(const Light& light, const Vec3& ref) {
  return [&light, ref](Rng& rng, Vec3& w) {
    const Vec2 u(rng.uniform(), rng.uniform());
    LightSample ls;
    if (!light.sample(ref, u, ls)) return false;
    w = ls.wi;
    return true;
  };
}

const Vec3 kLightRef(0.1f, -0.3f, 0.2f);

void triangleLightCase(uint64_t seed) {
  const TriangleMesh mesh = lightMesh();
  const TriangleLight light(&mesh, 1, Color(2.0f));
  DirectionalCase c;
  std::vector<Vec3> pts = {mesh.positions[1], mesh.positions[3], mesh.positions[2]};
  Vec3 center;
  const double r = boundingRadius(pts, center);
  c.grid = zoomedGrid(kLightRef, center, r);
  c.seed = seed;
  c.sample = lightSampleFn(light, kLightRef);
  c.pdf = triangleLightPdf(mesh, 1, light, kLightRef);
  runDirectional(c);
}

// From close by (0.15 from the triangle, off its centroid) TriangleLight samples the spherical
// triangle (accel/spherical_triangle.h): uniform in solid angle, pdf 1 / omega. The reference lies
// behind the triangle's front face, where a one-sided light gives no sample (seesOnlyBack): the
// light is two-sided here, which changes no direction or density.
void triangleLightNearCase(uint64_t seed) {
  const TriangleMesh mesh = lightMesh();
  const TriangleLight light(&mesh, 1, Color(2.0f), nullptr, /*twoSided=*/true);
  const Vec3 &a = mesh.positions[1], &b = mesh.positions[3], &cc = mesh.positions[2];
  const Vec3 centroid = (a + b + cc) / 3.0f;
  const Vec3 ref = centroid - 0.15f * glm::normalize(glm::cross(b - a, cc - a)) + 0.2f * (b - centroid);
  Vec3 center;
  const double r = boundingRadius({a, b, cc}, center);
  DirectionalCase c;
  c.grid = zoomedGrid(ref, center, r);
  c.seed = seed;
  c.sample = lightSampleFn(light, ref);
  c.pdf = triangleLightPdf(mesh, 1, light, ref);
  runDirectional(c);
}

void quadLightCase(uint64_t seed) {
  const Quad quad(quadVertices(), kQuadUv);
  const AreaLight light(&quad, Color(1.0f, 0.5f, 0.25f));
  const auto v = quadVertices();
  Vec3 center;
  const double r = boundingRadius({v.begin(), v.end()}, center);
  const Vec3 ref = center + 1.7f * glm::normalize(Vec3(0.1f, 0.4f, 1.0f));
  DirectionalCase c;
  c.grid = zoomedGrid(ref, center, r);
  c.seed = seed;
  c.sample = lightSampleFn(light, ref);
  c.pdf = areaLightPdf(quad, light, ref);
  runDirectional(c);
}

// The lights the LightSampler cases choose among, with their powers computed here.
struct LightSet {
  TriangleMesh mesh = lightMesh();
  Quad quad{quadVertices(), kQuadUv};
  Sphere sphere{Vec3(-2.0f, -1.0f, 0.5f), 0.5f};
  Disc dark{Vec3(0.0f, -3.0f, 0.0f), Vec3(0.0f, 1.0f, 0.0f), 1.0f};
  AreaLight quadLight{&quad, Color(1.0f, 0.5f, 0.25f)};
  TriangleLight triLight{&mesh, 0, Color(0.5f, 2.0f, 1.0f)};
  AreaLight sphereLight{&sphere, Color(3.0f)};
  AreaLight darkLight{&dark, Color(0.0f)};  // zero power: must never be chosen
  PointLight point{Vec3(0.0f, 3.0f, 0.0f), Color(1.0f)};
  EnvironmentLight env{Color(0.02f)};
  static constexpr float kSceneRadius = 5.0f;

  std::vector<Light*> all() { return {&quadLight, &triLight, &sphereLight, &darkLight, &point, &env}; }
  // Probability of choosing each light of all(): luminance of power / total, in double.
  std::vector<double> expectedPmf() {
    std::vector<double> w;
    for (Light* l : all()) {
      const Color p = l->power(kSceneRadius);
      w.push_back(0.2126 * p.x + 0.7152 * p.y + 0.0722 * p.z);
    }
    const double total = std::accumulate(w.begin(), w.end(), 0.0);
    for (double& x : w) x /= total;
    return w;
  }
};

void lightSamplerIndexCase(uint64_t seed) {
  LightSet set;
  const std::vector<Light*> lights = set.all();
  const LightSampler sampler(lights, LightSet::kSceneRadius);
  const std::vector<double> pmf = set.expectedPmf();
  std::vector<double> observed(lights.size(), 0.0), expected(lights.size());
  for (size_t i = 0; i < lights.size(); ++i) {
    expected[i] = pmf[i] * double(kSamples);
    EXPECT_NEAR(sampler.pmf(lights[i]), pmf[i], 1e-6 + 1e-5 * pmf[i]) << "light " << i;
  }
  EXPECT_EQ(set.darkLight.samplerIndex, -1);
  EXPECT_EQ(sampler.size(), lights.size() - 1) << "only the zero-power light is left out";
  Rng rng(seed, 0x5eed);
  long inconsistent = 0;
  for (long k = 0; k < kSamples; ++k) {
    float p = 0.0f;
    const Light* chosen = sampler.sample(rng.uniform(), p);
    const auto it = std::find(lights.begin(), lights.end(), chosen);
    ASSERT_NE(it, lights.end());
    observed[size_t(it - lights.begin())] += 1.0;
    if (p != sampler.pmf(chosen)) ++inconsistent;
  }
  EXPECT_EQ(observed[3], 0.0) << "the zero-power light was chosen";
  EXPECT_EQ(inconsistent, 0) << "sample()'s pmf differs from pmf(light)";
  const Chi2Outcome r = chi2Test(observed, expected, [](size_t i) { return "light " + std::to_string(i); });
  report(currentTestName(), r, 1.0, 1.0);
  judge(r, false);
}

// The alias table behind the LightSampler, over many outcomes whose weights span five orders
// of magnitude, some of them zero: what a scene of thousands of emitters of mixed sizes gives it.
// The caustic tracer's emission directions (renderer/caustic_tracer.h): a mixture of uniform
// cones towards casters' bounding spheres, two of them overlapping (a direction in both has the
// sum of the densities) and, with `inside`, one sphere containing the point (uniform over the
// sphere). The grid zooms onto the overlapping pair unless the whole sphere is sampled.
void causticEmissionCase(bool inside, uint64_t seed) {
  const Vec3 from(0.2f, 1.7f, -0.1f);
  std::vector<CausticCaster> casters = {{Vec3(0.5f, 0.4f, 0.2f), 0.45f}, {Vec3(0.1f, 0.5f, -0.3f), 0.3f}};
  if (inside) casters.push_back({from + Vec3(0.1f, -0.2f, 0.05f), 0.5f});
  const CausticTracer tracer(casters, {}, true);
  DirectionalCase c;
  c.grid = inside ? tiltedGrid() : zoomedGrid(from, Vec3(0.3f, 0.45f, -0.05f), 0.75);
  c.seed = seed;
  c.sample = [&](Rng& rng, Vec3& w) {
    const float uPick = rng.uniform();
    const Vec2 u(rng.uniform(), rng.uniform());
    w = tracer.sampleDirection(from, uPick, u);
    return true;
  };
  c.pdf = [&](const Vec3& w) { return double(tracer.directionPdf(from, glm::normalize(w))); };
  runDirectional(c);
}

void aliasTableCase(uint64_t seed) {
  constexpr size_t kOutcomes = 2000;
  std::vector<double> weights(kOutcomes);
  for (size_t i = 0; i < kOutcomes; ++i)
    weights[i] = i % 11 == 0 ? 0.0 : std::exp(-double(i % 53) / 4.5) * double(1 + i % 3);
  const double total = std::accumulate(weights.begin(), weights.end(), 0.0);
  const AliasTable table(weights);
  ASSERT_EQ(table.size(), kOutcomes);
  std::vector<double> observed(kOutcomes, 0.0), expected(kOutcomes);
  for (size_t i = 0; i < kOutcomes; ++i) expected[i] = weights[i] / total * double(kSamples);
  Rng rng(seed, 0xa11a5);
  for (long k = 0; k < kSamples; ++k) {
    const size_t i = table.sample(rng.uniform());
    ASSERT_LT(i, kOutcomes);
    observed[i] += 1.0;
  }
  double zeroChosen = 0.0;
  for (size_t i = 0; i < kOutcomes; i += 11) zeroChosen += observed[i];
  EXPECT_EQ(zeroChosen, 0.0) << "an outcome of weight 0 was chosen";
  const Chi2Outcome r = chi2Test(observed, expected, [](size_t i) { return "outcome " + std::to_string(i); });
  report(currentTestName(), r, 1.0, 1.0);
  judge(r, false);
}

// Next-event estimation as the integrator does it: choose a light, then sample it. Directions
// have density sum_i pmf_i pdf_i(w) (the point light contributes no density but takes its
// share of the samples, which then count as "failed" in the sense of carrying no density).
void lightSamplerMixtureCase(uint64_t seed) {
  LightSet set;
  const std::vector<Light*> lights = set.all();
  const LightSampler sampler(lights, LightSet::kSceneRadius);
  const std::vector<double> pmf = set.expectedPmf();
  const Vec3 ref = kLightRef;
  const std::vector<PdfFn> pdfs = {areaLightPdf(set.quad, set.quadLight, ref),
                                   triangleLightPdf(set.mesh, 0, set.triLight, ref),
                                   areaLightPdf(set.sphere, set.sphereLight, ref),
                                   [](const Vec3&) { return 0.0; },  // dark, never chosen
                                   [](const Vec3&) { return 0.0; },  // point light: delta
                                   [&](const Vec3& w) { return double(set.env.pdf(ref, w, w)); }};
  DirectionalCase c;
  c.grid = tiltedGrid();
  c.seed = seed;
  c.sample = [&](Rng& rng, Vec3& w) {
    float p;
    const Light* light = sampler.sample(rng.uniform(), p);
    const Vec2 u(rng.uniform(), rng.uniform());
    LightSample ls;
    if (!light || !light->sample(ref, u, ls) || ls.delta) return false;
    w = ls.wi;
    return true;
  };
  c.pdf = [&](const Vec3& w) {
    double sum = 0.0;
    for (size_t i = 0; i < pdfs.size(); ++i) sum += pmf[i] * pdfs[i](w);
    return sum;
  };
  runDirectional(c);
}

// ---------------------------------------------------------------------------------------------
// The registry of cases: m for the Sidak correction is its size.

struct Chi2Case {
  std::string name;
  std::function<void()> run;
};

const std::vector<Chi2Case>& allCases() {
  static const std::vector<Chi2Case> cases = [] {
    std::vector<Chi2Case> v;
    uint64_t seed = 1000;
    auto add = [&](std::string name, std::function<void(uint64_t)> f) {
      const uint64_t s = seed++;
      v.push_back({std::move(name), [f, s] { f(s); }});
    };

    // Outgoing directions: near the normal, oblique, grazing, and below the surface (two-sided).
    const Vec3 woNormal(0.05f, 0.02f, 1.0f), woOblique(0.6f, -0.3f, 0.74f), woGrazing(0.95f, 0.1f, 0.25f),
        woBelow(-0.3f, 0.5f, -0.8f);

    // Lambertian.
    for (const auto& [name, woBinding] :
         {std::pair{"Normal", woNormal}, std::pair{"Oblique", woOblique}, std::pair{"Below", woBelow}}) {
      const Vec3 wo = woBinding;  // clang 14 cannot capture structured bindings
      add(std::string("Lambertian_wo") + name, [wo](uint64_t s) {
        runMaterial(std::make_shared<Lambertian>(constant(Color(0.7f, 0.5f, 0.3f))), wo, s);
      });
    }

    // Phong: exponents 1, 10, 100; diffuse + glossy, coloured mixes, glossy only; two wo each.
    struct Mix {
      const char* name;
      Color kd, ks;
    };
    const Mix mixes[] = {{"kd50ks40", Color(0.5f), Color(0.4f)},
                         {"coloured", Color(0.1f, 0.3f, 0.05f), Color(0.6f, 0.5f, 0.65f)},
                         {"ks90", Color(0.0f), Color(0.9f)}};
    for (float exponent : {1.0f, 10.0f, 100.0f}) {
      for (const Mix& mix : mixes) {
        for (const auto& [woName, woBinding] :
             {std::pair{"Oblique", woOblique}, std::pair{"Grazing", woGrazing}}) {
          const Vec3 wo = woBinding;  // clang 14 cannot capture structured bindings
          add("Phong_n" + std::to_string(int(exponent)) + "_" + mix.name + "_wo" + woName,
              [mix, exponent, wo](uint64_t s) {
                runMaterial(std::make_shared<Phong>(constant(mix.kd), mix.ks, exponent), wo, s);
              });
        }
      }
    }
    add("Phong_n10_kd50ks40_woBelow", [woBelow](uint64_t s) {
      runMaterial(std::make_shared<Phong>(constant(Color(0.5f)), Color(0.4f), 10.0f), woBelow, s);
    });

    // Mixed: kd + ks only (with absorption), all four parts (only the non-delta part counts),
    // and a sharp glossy lobe at grazing incidence.
    auto mixed = [](Color kd, Color ks, Color kr, Color kt, float exponent) {
      MixedCoefficients c;
      c.kd = constant(kd);
      c.ks = ks;
      c.kr = kr;
      c.kt = kt;
      c.exponent = exponent;
      return std::make_shared<Mixed>(c);
    };
    add("Mixed_kdks_absorbing_woOblique", [=](uint64_t s) {
      runMaterial(mixed(Color(0.3f, 0.2f, 0.1f), Color(0.4f), Color(0.0f), Color(0.0f), 20.0f), woOblique, s);
    });
    add("Mixed_allParts_nonDelta_woOblique", [=](uint64_t s) {
      runMaterial(mixed(Color(0.2f), Color(0.3f), Color(0.2f), Color(0.2f), 5.0f), woOblique, s);
    });
    add("Mixed_ks_n200_woGrazing", [=](uint64_t s) {
      runMaterial(mixed(Color(0.0f), Color(0.8f), Color(0.0f), Color(0.0f), 200.0f), woGrazing, s);
    });
    add("Mixed_allParts_nonDelta_woBelow", [=](uint64_t s) {
      runMaterial(mixed(Color(0.25f), Color(0.25f), Color(0.1f), Color(0.3f), 30.0f), woBelow, s);
    });

    // glTF metallic-roughness (Appendix B + KHR_materials_transmission / _ior): roughness 0.1 to 1
    // (alpha 0.01 to 1) x metallic 0, 0.5, 1, at normal, oblique, grazing and below-the-surface wo
    // (two-sided); thin-walled transmission (the mirrored GGX lobe) and a rough refracting
    // interface from outside and from inside (total internal reflection for part of the visible
    // normals), whose samples cover the whole sphere.
    auto pbr = [](float roughness, float metallic, float transmission, bool thinWalled) {
      GltfPbrInputs in;
      in.baseColor = constant(Color(0.8f, 0.6f, 0.3f));
      in.metallicRoughness = constant(Color(0.0f, roughness, metallic));
      if (transmission > 0.0f) in.transmission = constant(Color(transmission, 0.0f, 0.0f));
      in.thinWalled = thinWalled;
      in.ior = 1.5f;
      return std::make_shared<GltfPbrMaterial>(std::move(in));
    };
    struct PbrCase {
      const char* name;
      float roughness, metallic, transmission;
      bool thinWalled;
      Vec3 wo;
    };
    const PbrCase pbrCases[] = {
        {"GltfPbr_r0p1_m1_woOblique", 0.1f, 1.0f, 0.0f, true, woOblique},
        {"GltfPbr_r0p1_m0_woNormal", 0.1f, 0.0f, 0.0f, true, woNormal},
        {"GltfPbr_r0p3_m0_woOblique", 0.3f, 0.0f, 0.0f, true, woOblique},
        {"GltfPbr_r0p3_m0p5_woGrazing", 0.3f, 0.5f, 0.0f, true, woGrazing},
        {"GltfPbr_r0p3_m1_woGrazing", 0.3f, 1.0f, 0.0f, true, woGrazing},
        {"GltfPbr_r0p7_m0p5_woNormal", 0.7f, 0.5f, 0.0f, true, woNormal},
        {"GltfPbr_r0p7_m0_woBelow", 0.7f, 0.0f, 0.0f, true, woBelow},
        {"GltfPbr_r1_m0_woGrazing", 1.0f, 0.0f, 0.0f, true, woGrazing},
        {"GltfPbr_r1_m1_woOblique", 1.0f, 1.0f, 0.0f, true, woOblique},
        {"GltfPbr_thin_t1_r0p4_woOblique", 0.4f, 0.0f, 1.0f, true, woOblique},
        {"GltfPbr_volume_t0p5_r0p3_woOblique", 0.3f, 0.0f, 0.5f, false, woOblique},
        {"GltfPbr_volume_t0p5_r0p5_m0p2_woBelowInside", 0.5f, 0.2f, 0.5f, false, woBelow},
        {"GltfPbr_volume_t1_r0p2_woGrazingInside", 0.2f, 0.0f, 1.0f, false,
         Vec3(woGrazing.x, woGrazing.y, -woGrazing.z)},
    };
    for (const PbrCase& pc : pbrCases) {
      add(pc.name, [=](uint64_t s) {
        runMaterial(pbr(pc.roughness, pc.metallic, pc.transmission, pc.thinWalled), pc.wo, s);
      });
    }

    // The Khronos layers (KHR_materials_specular, _sheen, _clearcoat) over the base: each lobe
    // alone over a dark base, then all of them together, thin-walled and inside a volume (where the
    // layers of the outer surface do not apply).
    struct Layers {
      Color specularColor{1.0f};
      float specular = 1.0f;
      Color sheen{0.0f};
      float sheenRoughness = 0.5f, coat = 0.0f, coatRoughness = 0.1f;
    };
    auto layered = [](float roughness, float metallic, float transmission, bool thinWalled, Layers l) {
      GltfPbrInputs in;
      in.baseColor = constant(Color(0.3f, 0.2f, 0.1f));
      in.metallicRoughness = constant(Color(0.0f, roughness, metallic));
      if (transmission > 0.0f) in.transmission = constant(Color(transmission, 0.0f, 0.0f));
      in.thinWalled = thinWalled;
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
      return std::make_shared<GltfPbrMaterial>(std::move(in));
    };
    struct LayeredCase {
      const char* name;
      float roughness, metallic, transmission;
      bool thinWalled;
      Layers layers;
      Vec3 wo;
    };
    const LayeredCase layeredCases[] = {
        {"GltfSpecular_colour2_w0p6_r0p3_woOblique",
         0.3f,
         0.0f,
         0.0f,
         true,
         {Color(2.0f, 1.0f, 0.5f), 0.6f},
         woOblique},
        {"GltfSheen_r0p5_woNormal",
         0.6f,
         0.0f,
         0.0f,
         true,
         {Color(1.0f), 1.0f, Color(0.9f, 0.5f, 0.3f), 0.5f},
         woNormal},
        {"GltfSheen_r0p2_woGrazing",
         0.6f,
         0.0f,
         0.0f,
         true,
         {Color(1.0f), 1.0f, Color(1.0f), 0.2f},
         woGrazing},
        {"GltfCoat_c1_r0p05_over_r0p6_woOblique",
         0.6f,
         0.0f,
         0.0f,
         true,
         {Color(1.0f), 1.0f, Color(0.0f), 0.5f, 1.0f, 0.05f},
         woOblique},
        {"GltfCoat_c0p5_r0p4_over_metal_woGrazing",
         0.3f,
         1.0f,
         0.0f,
         true,
         {Color(1.0f), 1.0f, Color(0.0f), 0.5f, 0.5f, 0.4f},
         woGrazing},
        {"GltfLayers_all_thin_t0p5_woBelow",
         0.4f,
         0.2f,
         0.5f,
         true,
         {Color(1.5f, 1.0f, 1.0f), 0.8f, Color(0.5f), 0.4f, 0.7f, 0.2f},
         woBelow},
        {"GltfLayers_all_volume_t0p7_woOblique",
         0.3f,
         0.0f,
         0.7f,
         false,
         {Color(1.0f), 0.9f, Color(0.6f), 0.6f, 0.8f, 0.1f},
         woOblique},
        {"GltfLayers_all_volume_t0p7_woBelowInside",
         0.3f,
         0.0f,
         0.7f,
         false,
         {Color(1.0f), 0.9f, Color(0.6f), 0.6f, 0.8f, 0.1f},
         woBelow},
    };
    // A coat whose normal (a mesh's interpolated normal: the hit's attributes) tilts 35 degrees
    // from the base's: its samples reach under the base's horizon and under its own.
    struct TiltedNormal final : VertexAttributes {
      Vec2 texCoordAt(int, uint32_t, Vec2 b) const override { return b; }
      glm::vec4 colorAt(uint32_t, Vec2) const override { return glm::vec4(1.0f); }
      Vec3 normalAt(uint32_t, Vec2) const override { return glm::normalize(Vec3(0.7f, 0.0f, 1.0f)); }
      glm::vec4 tangentAt(uint32_t, Vec2) const override { return glm::vec4(0.0f); }
    };
    static const TiltedNormal tilted;
    add("GltfCoat_tilted_c1_r0p3_woGrazing", [=](uint64_t s) {
      Layers l;
      l.coat = 1.0f;
      l.coatRoughness = 0.3f;
      runMaterial(layered(0.5f, 0.0f, 0.0f, true, l), Vec3(-0.3f, 0.1f, 0.5f), s, false, &tilted);
    });
    // KHR_materials_anisotropy: a rough metal stretched along a direction 0.9 rad from the
    // tangent, seen obliquely across it (the stretched visible normals of Heitz 2018).
    struct Tangent final : VertexAttributes {
      Vec2 texCoordAt(int, uint32_t, Vec2 b) const override { return b; }
      glm::vec4 colorAt(uint32_t, Vec2) const override { return glm::vec4(1.0f); }
      Vec3 normalAt(uint32_t, Vec2) const override { return Vec3(0.0f, 0.0f, 1.0f); }
      glm::vec4 tangentAt(uint32_t, Vec2) const override { return glm::vec4(1.0f, 0.0f, 0.0f, 1.0f); }
    };
    static const Tangent tangent;
    add("GltfAnisotropy_s0p8_r0p2_m1_woOblique", [=](uint64_t s) {
      GltfPbrInputs in;
      in.baseColor = constant(Color(0.8f, 0.6f, 0.3f));
      in.metallicRoughness = constant(Color(0.0f, 0.2f, 1.0f));
      in.anisotropyStrength = 0.8f;
      in.anisotropyRotation = 0.9f;
      runMaterial(std::make_shared<GltfPbrMaterial>(std::move(in)), woOblique, s, false, &tangent);
    });
    add("GltfAnisotropy_s0p5_r0p4_dielectric_woGrazing", [=](uint64_t s) {
      GltfPbrInputs in;
      in.baseColor = constant(Color(0.5f, 0.3f, 0.2f));
      in.metallicRoughness = constant(Color(0.0f, 0.4f, 0.0f));
      in.anisotropyStrength = 0.5f;
      runMaterial(std::make_shared<GltfPbrMaterial>(std::move(in)), woGrazing, s, false, &tangent);
    });
    for (const LayeredCase& lc : layeredCases) {
      add(lc.name, [=](uint64_t s) {
        runMaterial(layered(lc.roughness, lc.metallic, lc.transmission, lc.thinWalled, lc.layers), lc.wo, s);
      });
    }

    // Sphere: cone sampling from outside (near, far, and the small-angle Taylor branch), area
    // sampling from inside; the flipped sphere both ways.
    add("Sphere_outside_near_cone", [](uint64_t s) { sphereFrom(1.6f, false, s); });
    add("Sphere_outside_far_cone", [](uint64_t s) { sphereFrom(6.0f, false, s); });
    add("Sphere_outside_taylor_cone", [](uint64_t s) { sphereFrom(50.0f, false, s); });
    add("Sphere_inside_area", [](uint64_t s) { sphereFrom(0.6f, false, s); });
    add("FlippedSphere_outside_cone", [](uint64_t s) { sphereFrom(2.5f, true, s); });
    add("FlippedSphere_inside_area", [](uint64_t s) { sphereFrom(0.3f, true, s); });

    // Flat convex shapes, directions from points off their planes (front and back side).
    add("Disc_front", [](uint64_t s) {
      const Vec3 c(0.5f, 0.2f, -0.3f), n = glm::normalize(Vec3(0.2f, -0.4f, 1.0f));
      const Disc disc(c, n, 0.8f);
      const Frame f(n);
      flatShape(disc, {c + 0.8f * f.s, c - 0.8f * f.s, c + 0.8f * f.t, c - 0.8f * f.t},
                c + 1.5f * n + 0.7f * f.s, s);
    });
    add("Disc_back_oblique", [](uint64_t s) {
      const Vec3 c(0.5f, 0.2f, -0.3f), n = glm::normalize(Vec3(0.2f, -0.4f, 1.0f));
      const Disc disc(c, n, 0.8f);
      const Frame f(n);
      flatShape(disc, {c + 0.8f * f.s, c - 0.8f * f.s, c + 0.8f * f.t, c - 0.8f * f.t},
                c - 0.4f * n - 1.2f * f.t, s);
    });
    add("Triangle_front", [](uint64_t s) {
      const auto v = triangleVertices();
      const Triangle tri(v, {Vec2(0, 0), Vec2(1, 0), Vec2(0, 1)});
      const Vec3 n = glm::normalize(glm::cross(v[1] - v[0], v[2] - v[0]));
      flatShape(tri, {v.begin(), v.end()}, (v[0] + v[1] + v[2]) / 3.0f + 0.9f * n + Vec3(0.3f, 0.0f, 0.0f),
                s);
    });
    add("Triangle_back", [](uint64_t s) {
      const auto v = triangleVertices();
      const Triangle tri(v, {Vec2(0, 0), Vec2(1, 0), Vec2(0, 1)});
      const Vec3 n = glm::normalize(glm::cross(v[1] - v[0], v[2] - v[0]));
      flatShape(tri, {v.begin(), v.end()}, v[0] - 0.5f * n, s);
    });
    // Close by, the triangle is sampled in the solid angle it subtends (accel/spherical_triangle.h).
    add("Triangle_near_spherical", [](uint64_t s) {
      const auto v = triangleVertices();
      const Triangle tri(v, {Vec2(0, 0), Vec2(1, 0), Vec2(0, 1)});
      const Vec3 n = glm::normalize(glm::cross(v[1] - v[0], v[2] - v[0]));
      flatShape(tri, {v.begin(), v.end()}, 0.8f * v[1] + 0.2f * (v[0] + v[2]) / 2.0f + 0.03f * n, s);
    });
    add("Quad_front", [](uint64_t s) {
      const auto v = quadVertices();
      const Quad quad(v, kQuadUv);
      flatShape(quad, {v.begin(), v.end()}, placed(kQuadOrigin, 1.0f, 0.6f) + 1.2f * kPlacement.n, s);
    });

    // Rectangular quads are sampled uniformly in the solid angle they subtend (spherical
    // rectangle), down to a minimum solid angle below which they fall back to area sampling.
    auto rectangle = [](uint64_t s, float x, float y, float h) {
      const std::array<Vec3, 4> v = {placed(kQuadOrigin, 0.0f, 0.0f), placed(kQuadOrigin, 2.0f, 0.0f),
                                     placed(kQuadOrigin, 2.0f, 1.2f), placed(kQuadOrigin, 0.0f, 1.2f)};
      const Quad quad(v, kQuadUv);
      EXPECT_TRUE(quad.isRectangle());
      flatShape(quad, {v.begin(), v.end()}, placed(kQuadOrigin, x, y) + h * kPlacement.n, s);
    };
    add("Rectangle_veryClose_sphericalRect", [=](uint64_t s) { rectangle(s, 0.7f, 0.5f, 0.1f); });
    add("Rectangle_front_oblique_sphericalRect", [=](uint64_t s) { rectangle(s, 3.0f, -0.8f, 1.0f); });
    add("Rectangle_back_sphericalRect", [=](uint64_t s) { rectangle(s, 1.2f, 0.9f, -0.6f); });
    add("Rectangle_far_areaFallback", [=](uint64_t s) { rectangle(s, 1.0f, 0.6f, 250.0f); });

    // Closed (and one open) area-sampled shapes, from inside.
    add("Cylinder_capped_inside", [](uint64_t s) {
      const Vec3 p0(0.0f), p1(0.4f, 1.5f, 0.3f);
      const Cylinder cyl(p0, p1, 0.6f, true);
      runShape(cyl, p0 + 0.3f * (p1 - p0) + 0.2f * Frame(glm::normalize(p1 - p0)).s, tiltedGrid(), s);
    });
    add("Cylinder_open_inside", [](uint64_t s) {
      const Vec3 p0(0.0f), p1(0.4f, 1.5f, 0.3f);
      const Cylinder cyl(p0, p1, 0.6f, false);
      runShape(cyl, p0 + 0.6f * (p1 - p0) - 0.3f * Frame(glm::normalize(p1 - p0)).t, tiltedGrid(), s);
    });
    add("Cone_capped_inside", [](uint64_t s) {
      const Vec3 base(0.0f), apex(0.3f, 1.2f, -0.4f);
      const Cone cone(base, apex, 0.7f, true);
      runShape(cone, base + 0.25f * (apex - base) + 0.1f * Frame(glm::normalize(apex - base)).s, tiltedGrid(),
               s);
    });
    add("Box_rotated_inside", [](uint64_t s) {
      const glm::mat3 rot(kPlacement.s, kPlacement.t, kPlacement.n);
      const Vec3 center(0.2f, 0.1f, -0.3f);
      const Box box(center, Vec3(1.0f, 2.0f, 0.6f), rot);
      runShape(box, center + rot * Vec3(0.2f, -0.5f, 0.1f), tiltedGrid(), s);
    });

    // Lights.
    add("TriangleLight_directions", triangleLightCase);
    add("TriangleLight_directions_near", triangleLightNearCase);
    add("AreaLightQuad_directions", quadLightCase);
    add("CausticEmission_overlappingCones", [](uint64_t s) { causticEmissionCase(false, s); });
    add("CausticEmission_insideOneCaster", [](uint64_t s) { causticEmissionCase(true, s); });
    add("AliasTable_manyOutcomes", aliasTableCase);
    add("LightSampler_index_by_power", lightSamplerIndexCase);
    add("LightSampler_nee_mixture", lightSamplerMixtureCase);

    // The test must be able to fail.
    add("WrongPdf_LambertianVsUniformHemisphere_mustReject", [woOblique](uint64_t s) {
      runMaterial(std::make_shared<Lambertian>(constant(Color(0.8f))), woOblique, s, /*wrongPdf=*/true);
    });
    return v;
  }();
  return cases;
}

// ---------------------------------------------------------------------------------------------
// Tests.

TEST(Chi2Setup, SidakCountMatchesRegisteredCases) {
  EXPECT_EQ(allCases().size(), size_t(kNumCases)) << "update kNumCases (m of the Sidak correction)";
}

// The incomplete gamma function against closed forms: Q(1, x) = exp(-x) (chi-square, 2 dof),
// Q(1/2, x) = erfc(sqrt x) (1 dof), and a large-dof value against the Wilson-Hilferty
// approximation (accurate to ~1e-3 there).
TEST(Chi2Setup, IncompleteGammaMatchesClosedForms) {
  for (double x : {0.01, 0.5, 1.0, 2.0, 5.0, 20.0}) {
    EXPECT_NEAR(gammaQ(1.0, x), std::exp(-x), 1e-12 * std::max(1.0, std::exp(-x)));
    EXPECT_NEAR(gammaQ(0.5, x), std::erfc(std::sqrt(x)), 1e-12);
  }
  const int k = 3000;
  for (double chi2 : {2800.0, 3000.0, 3200.0}) {
    const double h = 2.0 / (9.0 * k);
    const double z = (std::cbrt(chi2 / k) - (1.0 - h)) / std::sqrt(h);
    EXPECT_NEAR(chi2Survival(chi2, k), 0.5 * std::erfc(z / std::numbers::sqrt2), 2e-3);
  }
}

class Chi2Sampling : public ::testing::TestWithParam<size_t> {};

TEST_P(Chi2Sampling, FollowsPdf) {
  const Chi2Case& c = allCases()[GetParam()];
  const int before = g_chi2Runs;
  c.run();
  EXPECT_EQ(g_chi2Runs - before, 1) << "each case must run exactly one chi-square test";
}

INSTANTIATE_TEST_SUITE_P(Chi2, Chi2Sampling, ::testing::Range<size_t>(0, allCases().size()),
                         [](const ::testing::TestParamInfo<size_t>& info) {
                           return allCases()[info.param].name;
                         });

}  // namespace
}  // namespace ember
