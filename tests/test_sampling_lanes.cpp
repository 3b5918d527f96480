// Light sampling over lanes (accel/sampling_lanes.h, Light::sampleLanes) must give each lane
// exactly what a single call gives, whatever its neighbours: the wavefront samples the lights of a
// whole bounce together and the scalar reference one vertex at a time, and their images must stay
// equal bit for bit. The quad's kernel (SIMD inverse trigonometry) must also agree with the scalar
// spherical-rectangle and area-sampling formulas it replaces, to float precision; its
// distribution is checked by the chi-square tests of tests/test_chi2.cpp.
#include "accel/cylinder.h"
#include "accel/disc.h"
#include "accel/flipped_shape.h"
#include "accel/sphere.h"
#include "accel/spherical_rectangle.h"
#include "accel/triangle.h"
#include "accel/triangle_mesh.h"
#include "core/rng.h"
#include "core/sampling.h"
#include "core/warp_lanes.h"
#include "materials/lambertian.h"
#include "renderer/light.h"
#include "renderer/sampler_lanes.h"
#include "simd_targets.h"

#include <gtest/gtest.h>

#include <array>
#include <bit>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace ember {
namespace {

Vec2 next2(Rng& rng) {
  const float x = rng.uniform();
  return {x, rng.uniform()};
}

struct QuadCase {
  std::string name;
  std::array<Vec3, 4> v;
};

// Rectangles and general quads, tiny, huge, far from the origin and turned.
std::vector<QuadCase> quadCases() {
  const std::array<Vec2, 4> unit = {Vec2(0, 0), Vec2(1, 0), Vec2(1, 1), Vec2(0, 1)};
  auto placed = [&](const Vec3& origin, const Vec3& ex, const Vec3& ey) {
    std::array<Vec3, 4> v;
    for (int i = 0; i < 4; ++i) v[size_t(i)] = origin + unit[size_t(i)].x * ex + unit[size_t(i)].y * ey;
    return v;
  };
  const Vec3 tx = glm::normalize(Vec3(1.0f, 0.3f, -0.2f));
  const Vec3 ty = glm::normalize(glm::cross(Vec3(0.1f, 0.2f, 1.0f), tx));
  std::vector<QuadCase> cases = {
      {"ceiling", placed(Vec3(-0.25f, 1.98f, -0.25f), Vec3(0.5f, 0, 0), Vec3(0, 0, 0.5f))},
      {"turned", placed(Vec3(0.2f, 0.4f, -0.1f), 2.0f * tx, 1.2f * ty)},
      {"tiny", placed(Vec3(0.3f, -0.2f, 0.1f), 1e-3f * tx, 2e-3f * ty)},
      {"huge", placed(Vec3(-500.0f, 10.0f, -500.0f), Vec3(1000.0f, 0, 0), Vec3(0, 0, 1000.0f))},
      {"far", placed(Vec3(1e4f, 2e4f, -1e4f), 3.0f * tx, 2.0f * ty)},
      {"general",
       {Vec3(0.2f, 0.4f, -0.1f), Vec3(2.2f, 0.4f, -0.1f), Vec3(2.7f, 1.9f, -0.1f), Vec3(-0.1f, 1.4f, -0.1f)}},
  };
  return cases;
}

// Reference points all around a quad: close (the spherical-rectangle regime), far (area
// sampling), grazing its plane, in its plane, and right above its edges.
std::vector<Vec3> referencePoints(const std::array<Vec3, 4>& v, Rng& rng) {
  const Vec3 c = 0.25f * (v[0] + v[1] + v[2] + v[3]);
  const float size = glm::length(v[2] - v[0]);
  const Vec3 n = glm::normalize(glm::cross(v[1] - v[0], v[2] - v[0]));
  std::vector<Vec3> refs;
  for (int i = 0; i < 200; ++i) {
    const Vec3 dir = sampleUniformSphere(next2(rng));
    const float dist = size * std::pow(10.0f, -2.0f + 3.0f * rng.uniform());
    refs.push_back(c + dist * dir);
  }
  for (int i = 0; i < 40; ++i) {
    const Vec2 b = next2(rng);
    const Vec3 onQuad = v[0] + b.x * (v[1] - v[0]) + b.y * (v[3] - v[0]);
    const float h = size * std::pow(10.0f, -5.0f + 4.0f * rng.uniform());
    refs.push_back(onQuad + (i % 2 ? h : -h) * n);                                 // just above or below
    refs.push_back(c + (3.0f + rng.uniform()) * (onQuad - c) + 1e-4f * size * n);  // grazing
  }
  refs.push_back(c);                        // in the plane
  refs.push_back(v[1] + 1e-3f * size * n);  // over a corner
  return refs;
}

// True if the lane had a sample (a test that only saw failed samples would prove little).
bool expectSameSample(const Shape& shape, const SolidAngleLanes& lanes, unsigned i,
                      const std::string& where) {
  ShapeSample s;
  float pdf = 0.0f;
  const Vec3 ref(lanes.ref[0][i], lanes.ref[1][i], lanes.ref[2][i]);
  const bool ok = shape.sampleSolidAngle(ref, Vec2(lanes.u[0][i], lanes.u[1][i]), s, pdf);
  EXPECT_EQ(ok, lanes.pdf[i] > 0.0f) << where;
  if (!ok || !(lanes.pdf[i] > 0.0f)) return false;
  EXPECT_EQ(pdf, lanes.pdf[i]) << where;
  for (int c = 0; c < 3; ++c) {
    EXPECT_EQ(s.p[c], lanes.p[c][i]) << where << " component " << c;
    EXPECT_EQ(s.n[c], lanes.normal[c][i]) << where << " component " << c;
  }
  return true;
}

TEST(SamplingLanes, EveryLaneOfAQuadEqualsItsSingleCall) {
  Rng rng(7, 1);
  const std::array<Vec2, 4> uv = {Vec2(0, 0), Vec2(1, 0), Vec2(1, 1), Vec2(0, 1)};
  size_t sampled = 0;
  for (const QuadCase& qc : quadCases()) {
    const Quad quad(qc.v, uv);
    const FlippedShape flipped(std::make_unique<Quad>(qc.v, uv));
    const std::vector<Vec3> refs = referencePoints(qc.v, rng);
    for (const Shape* shape : {static_cast<const Shape*>(&quad), static_cast<const Shape*>(&flipped)}) {
      // Each reference point lands in another lane next to other neighbours on every pass.
      for (size_t first = 0; first < refs.size(); first += 11) {
        SolidAngleLanes lanes;
        lanes.n = unsigned(std::min<size_t>(SolidAngleLanes::kMaxLanes, refs.size() - first));
        for (unsigned i = 0; i < lanes.n; ++i) lanes.set(i, refs[first + i], next2(rng));
        lanes.padFrom(lanes.n);
        shape->sampleSolidAngleLanes(lanes);
        for (unsigned i = 0; i < lanes.n; ++i)
          sampled += expectSameSample(*shape, lanes, i, qc.name + " ref " + std::to_string(first + i));
      }
    }
  }
  EXPECT_GT(sampled, 3000u);
}

// The solid angle of the quad (v0, v1, v2, v3) seen from ref, in double: Van Oosterom and
// Strackee's formula (1983, IEEE Trans. Biomed. Eng. 30(2)) for each half, accurate however
// small the angle.
double exactSolidAngle(const std::array<Vec3, 4>& v, const Vec3& ref) {
  auto triangle = [&](const Vec3& pa, const Vec3& pb, const Vec3& pc) {
    const glm::dvec3 r(ref), a = glm::dvec3(pa) - r, b = glm::dvec3(pb) - r, c = glm::dvec3(pc) - r;
    const double la = glm::length(a), lb = glm::length(b), lc = glm::length(c);
    const double num = glm::dot(a, glm::cross(b, c));
    const double den = la * lb * lc + glm::dot(a, b) * lc + glm::dot(a, c) * lb + glm::dot(b, c) * la;
    return 2.0 * std::abs(std::atan2(num, den));
  };
  return triangle(v[0], v[1], v[2]) + triangle(v[0], v[2], v[3]);
}

// The solid angle both spherical-rectangle implementations divide by, against the exact value,
// from everywhere around the light, and most of all from near its plane, where the paper's acos
// form of the angles was wrong by up to 16 times.
TEST(SamplingLanes, RectangleSolidAngleIsAccurateEvenNearItsPlane) {
  Rng rng(17, 4);
  const std::array<Vec2, 4> uv = {Vec2(0, 0), Vec2(1, 0), Vec2(1, 1), Vec2(0, 1)};
  size_t nearPlane = 0;
  for (const QuadCase& qc : quadCases()) {
    const Quad quad(qc.v, uv);
    const Vec3 center = 0.5f * (qc.v[0] + qc.v[2]);
    // Where the corners' own float rounding is not small against the size (tiny or far-off
    // rectangles), the solid angle seen from near the plane is not defined by the input to 0.5%:
    // the four rounded corners are not coplanar to that precision.
    if (!quad.isRectangle() || maxAbsComponent(center) > 10.0f * glm::length(qc.v[2] - qc.v[0])) continue;
    const Vec3 n = glm::normalize(glm::cross(qc.v[1] - qc.v[0], qc.v[3] - qc.v[0]));
    for (int i = 0; i < 4000; ++i) {
      // Half the points within 1e-2 of the plane's direction, down to 1e-6.
      Vec3 dir = sampleUniformSphere(next2(rng));
      if (i % 2) {
        dir = glm::normalize(dir - glm::dot(dir, n) * n);
        dir = glm::normalize(dir + (rng.uniform() < 0.5f ? 1.0f : -1.0f) *
                                       std::pow(10.0f, -6.0f + 4.0f * rng.uniform()) * n);
        ++nearPlane;
      }
      const Vec3 ref = center + std::sqrt(quad.area()) * (0.2f + 1.7f * rng.uniform()) * dir;
      const double exact = exactSolidAngle(qc.v, ref);
      const SphericalRectangle sr(qc.v[0], qc.v[1] - qc.v[0], qc.v[3] - qc.v[0], ref);
      const std::string where = qc.name + " ref (" + std::to_string(ref.x) + ", " + std::to_string(ref.y) +
                                ", " + std::to_string(ref.z) + ")";
      EXPECT_NEAR(sr.solidAngle(), exact, 5e-3 * exact + 2e-6) << where;
      ShapeSample s;
      float pdf = 0.0f;
      const Vec3 d = ref - center;
      const bool close = glm::dot(d, d) < 4.0f * quad.area();
      if (close && quad.sampleSolidAngle(ref, next2(rng), s, pdf) &&
          exact > 1.1 * QuadSampling::kMinSphericalRectangle) {
        EXPECT_NEAR(1.0 / pdf, exact, 5e-3 * exact + 2e-6) << where;
      }
    }
  }
  EXPECT_GT(nearPlane, 4000u);
}

// The kernel against the scalar formulas: accel/spherical_rectangle.cpp where the rectangle is
// close and subtends enough solid angle, area sampling (PBRT4 eq. A.5.4 and 4.9) elsewhere.
TEST(SamplingLanes, QuadKernelAgreesWithTheScalarFormulas) {
  Rng rng(11, 2);
  const std::array<Vec2, 4> uv = {Vec2(0, 0), Vec2(1, 0), Vec2(1, 1), Vec2(0, 1)};
  size_t spherical = 0, byArea = 0;
  for (const QuadCase& qc : quadCases()) {
    const Quad quad(qc.v, uv);
    const float size = glm::length(qc.v[2] - qc.v[0]);
    const Vec3 center = 0.5f * (qc.v[0] + qc.v[2]);
    for (const Vec3& ref : referencePoints(qc.v, rng)) {
      const Vec2 u = next2(rng);
      ShapeSample s;
      float pdf = 0.0f;
      if (!quad.sampleSolidAngle(ref, u, s, pdf)) continue;
      const SphericalRectangle sr(qc.v[0], qc.v[1] - qc.v[0], qc.v[3] - qc.v[0], ref);
      const Vec3 d = ref - center;
      const bool close = quad.isRectangle() && glm::dot(d, d) < 4.0f * quad.area();
      // Near the regime's solid-angle threshold the two float evaluations may choose differently.
      if (close && std::abs(sr.solidAngle() / QuadSampling::kMinSphericalRectangle - 1.0f) < 1e-2f) continue;
      const std::string where = qc.name + " ref (" + std::to_string(ref.x) + ", " + std::to_string(ref.y) +
                                ", " + std::to_string(ref.z) + ")";
      if (close && sr.solidAngle() > QuadSampling::kMinSphericalRectangle) {
        ++spherical;
        EXPECT_NEAR(pdf, 1.0f / sr.solidAngle(), 1e-2f * pdf) << where;
        // The inversion amplifies the arguments' rounding where the rectangle is seen edge-on.
        const float cosPlane = std::abs(glm::dot(glm::normalize(ref - center), quad.sampleArea(u).n));
        if (cosPlane > 1e-2f && sr.solidAngle() > 1e-2f) {
          EXPECT_LE(glm::length(s.p - sr.sample(u)), 1e-3f * size) << where;
        }
      } else {
        ++byArea;
        const ShapeSample a = quad.sampleArea(u);
        EXPECT_LE(glm::length(s.p - a.p), 1e-6f * (size + maxAbsComponent(center))) << where;
        // d^2 / cos: the sampled point's rounding (a few ulps of the coordinates) relative to
        // the distance, and the cosine's cancellation (eps / cos) bound the two evaluations' gap.
        const Vec3 toLight = a.p - ref;
        const float dist = glm::length(toLight);
        const float cosLight = std::abs(glm::dot(a.n, toLight)) / dist;
        const float pointError = 4.0f * 0x1p-24f * (maxAbsComponent(center) + size) / dist;
        const float tolerance = 1e-5f + pointError * (4.0f + 2.0f / cosLight) + 1e-6f / cosLight;
        EXPECT_NEAR(pdf, areaToSolidAnglePdf(1.0f / quad.area(), ref, a.p, a.n), tolerance * pdf) << where;
      }
    }
  }
  EXPECT_GT(spherical, 300u);
  EXPECT_GT(byArea, 300u);
}

TEST(SamplingLanes, AreaLightLanesEqualSingleSamples) {
  Rng rng(13, 3);
  const std::array<Vec2, 4> uv = {Vec2(0, 0), Vec2(1, 0), Vec2(1, 1), Vec2(0, 1)};
  const QuadCase ceiling = quadCases()[0];
  const Quad quad(ceiling.v, uv);
  const Sphere sphere(Vec3(0.3f, 1.0f, -0.2f), 0.25f);
  const AreaLight lights[] = {AreaLight(&quad, Color(4.0f, 3.0f, 2.0f)),
                              AreaLight(&quad, Color(1.0f), /*twoSided=*/true),
                              AreaLight(&sphere, Color(2.0f))};
  std::vector<Vec3> refs = referencePoints(ceiling.v, rng);
  size_t sampledLights = 0;
  for (const AreaLight& light : lights) {
    // 37 points: two full blocks of 16 and a partial one.
    for (size_t first = 0; first + 37 <= refs.size(); first += 37) {
      std::vector<Vec2> us(37);
      for (Vec2& u : us) u = next2(rng);
      std::vector<LightSample> out(37);
      bool ok[37];
      light.sampleLanes(&refs[first], us.data(), 37, out.data(), ok);
      for (size_t i = 0; i < 37; ++i) {
        LightSample single;
        ASSERT_EQ(light.sample(refs[first + i], us[i], single), ok[i]) << i;
        if (!ok[i]) continue;
        ++sampledLights;
        EXPECT_EQ(single.pdf, out[i].pdf);
        EXPECT_EQ(single.dist, out[i].dist);
        EXPECT_EQ(single.pError, out[i].pError);
        for (int c = 0; c < 3; ++c) {
          EXPECT_EQ(single.wi[c], out[i].wi[c]);
          EXPECT_EQ(single.p[c], out[i].p[c]);
          EXPECT_EQ(single.n[c], out[i].n[c]);
          EXPECT_EQ(single.Li[c], out[i].Li[c]);
        }
      }
    }
  }
  EXPECT_GT(sampledLights, 500u);
}

// AreaLight::sampleRows (the packet integrator's light samples for vertices held in rows) must
// write each row exactly what sample() gives, and leave the rows of a reference without a sample
// (behind a one-sided flat light, or none drawn) as they were. Checked on every SIMD target for
// one- and two-sided quads, a flipped quad, a disc, and spheres and a cylinder with references
// inside them (whose samples face away: Li black), from rows at offsets of whole blocks.
void expectAreaLightRowsEqualSingleSamples() {
  Rng rng(41, 7);
  const std::array<Vec2, 4> uv = {Vec2(0, 0), Vec2(1, 0), Vec2(1, 1), Vec2(0, 1)};
  const QuadCase ceiling = quadCases()[0];
  const Quad quad(ceiling.v, uv);
  const FlippedShape flipped(std::make_unique<Quad>(ceiling.v, uv));
  const Disc disc(Vec3(0.1f, 1.9f, 0.0f), Vec3(0.0f, -1.0f, 0.0f), 0.3f);
  const Sphere sphere(Vec3(0.3f, 1.0f, -0.2f), 0.25f);
  const Cylinder cylinder(Vec3(0.3f, 1.0f, -0.2f), Vec3(0.3f, 1.6f, -0.2f), 0.4f, /*caps=*/true);
  const AreaLight lights[] = {AreaLight(&quad, Color(4.0f, 3.0f, 2.0f)),
                              AreaLight(&quad, Color(1.0f), true),
                              AreaLight(&flipped, Color(2.0f, 1.0f, 0.5f)),
                              AreaLight(&disc, Color(3.0f)),
                              AreaLight(&sphere, Color(2.0f)),
                              AreaLight(&sphere, Color(2.0f), true),
                              AreaLight(&cylinder, Color(0.5f, 1.0f, 2.0f))};
  std::vector<Vec3> refs = referencePoints(ceiling.v, rng);
  for (int i = 0; i < 40; ++i)  // inside the sphere and the cylinder
    refs.push_back(Vec3(0.3f, 1.0f + 0.5f * rng.uniform(), -0.2f) + 0.2f * sampleUniformSphere(next2(rng)));
  // So far away that the distance overflows, and not a point at all (its samples have a NaN
  // distance: the rows' infinite flag).
  for (const Vec3& far : {Vec3(3e38f, 1.0f, 0.0f), Vec3(0.0f, -1e30f, 2e30f), Vec3(-3e38f, -3e38f, 3e38f),
                          Vec3(std::numeric_limits<float>::quiet_NaN(), 1.0f, 0.0f)})
    refs.push_back(far);
  // The queries start at an offset that is no multiple of the block, as a wave's runs do.
  constexpr size_t kBlock = SolidAngleLanes::kMaxLanes, kOffset = 5;
  const size_t n = (refs.size() + kBlock - 1) / kBlock * kBlock, rowSize = kOffset + n;
  refs.resize(n, refs.front());
  std::vector<Vec2> us(rowSize);
  std::vector<float> refRow[3];
  for (int c = 0; c < 3; ++c) refRow[c].assign(rowSize, 0.0f);
  for (size_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) refRow[c][kOffset + i] = refs[i][c];
  constexpr float kUntouched = -123.0f;
  constexpr int32_t kUntouchedInt = 7;
  const auto bits = [](float x) { return std::bit_cast<uint32_t>(x); };
  // Bit for bit, signed zeros included; a NaN equals any NaN (a NaN reference point's sample is
  // NaN either way, and which NaN an operation on NaNs leaves is up to its instructions).
  const auto same = [&](float a, float b) { return bits(a) == bits(b) || (std::isnan(a) && std::isnan(b)); };
  size_t sampled = 0, black = 0, infinite = 0;
  for (const AreaLight& light : lights) {
    for (Vec2& u : us) u = next2(rng);
    std::vector<float> rowData[14];
    for (auto& row : rowData) row.assign(rowSize, kUntouched);
    std::vector<int32_t> deltaRow(rowSize, kUntouchedInt), infiniteRow(rowSize, kUntouchedInt),
        pointRow(rowSize, kUntouchedInt);
    auto at = [&](int k) { return rowData[k].data(); };
    const LightSampleRows rows{{at(0), at(1), at(2)},
                               {at(3), at(4), at(5)},
                               {at(6), at(7), at(8)},
                               {at(9), at(10), at(11)},
                               at(12),
                               at(13),
                               deltaRow.data(),
                               infiniteRow.data(),
                               pointRow.data()};
    const float* const refRows[3] = {refRow[0].data(), refRow[1].data(), refRow[2].data()};
    for (size_t first = kOffset; first < rowSize; first += kBlock)
      light.sampleRows(refRows, us.data(), first, rows);
    for (size_t i = 0; i < kOffset; ++i) ASSERT_EQ(bits(rowData[13][i]), bits(kUntouched));
    for (size_t i = 0; i < n; ++i) {
      const size_t r = kOffset + i;
      LightSample single;
      if (!light.sample(refs[i], us[r], single)) {
        for (int k = 0; k < 14; ++k) ASSERT_EQ(bits(rowData[k][r]), bits(kUntouched)) << i;
        ASSERT_EQ(deltaRow[r], kUntouchedInt);
        ASSERT_EQ(infiniteRow[r], kUntouchedInt);
        continue;
      }
      ++sampled;
      black += isBlack(single.Li);
      infinite += !std::isfinite(single.dist);
      for (int c = 0; c < 3; ++c) {
        EXPECT_PRED2(same, single.p[c], rowData[0 + c][r]) << i;
        EXPECT_PRED2(same, single.n[c], rowData[3 + c][r]) << i;
        EXPECT_PRED2(same, single.wi[c], rowData[6 + c][r]) << i;
        EXPECT_PRED2(same, single.Li[c], rowData[9 + c][r]) << i;
      }
      EXPECT_PRED2(same, single.pError, rowData[12][r]) << i;
      EXPECT_PRED2(same, single.pdf, rowData[13][r]) << i;
      EXPECT_EQ(deltaRow[r], 0);
      EXPECT_EQ(infiniteRow[r], std::isfinite(single.dist) ? 0 : -1) << i;
    }
  }
  EXPECT_GT(sampled, 1500u);
  EXPECT_GT(black, 40u);    // facing away: the one-sided lights seen from inside
  EXPECT_GT(infinite, 0u);  // the NaN reference's samples: the rows' infinite flag
}

TEST(SamplingLanes, AreaLightRowsEqualSingleSamplesOnEveryTarget) {
  forEachSimdTarget(expectAreaLightRowsEqualSingleSamples);
}

// A one-sided flat emitter skips the references behind it (AreaLight::seesOnlyBack) without sampling
// them: that is only right where every sample of the shape would face away from the reference, so
// that the skipped sample's Li would have been black. Checked for quads (a rectangle, a tilted
// one, flipped ones), a disc, a triangle and an emissive mesh's triangle (TriangleLight), at three
// scales and offsets from the origin, for references at random and at signed distances from the
// plane down to 1e-7 of the scale, with the facing test of AreaLight::fromShapeSample on samples
// the shape itself draws (for the mesh's triangle, on points all over it).
TEST(SamplingLanes, OneSidedFlatLightsSkipOnlyReferencesNoSampleFaces) {
  Rng rng(29, 5);
  size_t skipped = 0, sampledBehind = 0, flatShapes = 0, triangleSkips = 0;
  for (const float scale : {1e-3f, 1.0f, 1e3f})
    for (const Vec3 offset : {Vec3(0.0f), Vec3(3.0f, -2.0f, 5.0f) * scale, Vec3(1e4f, 0.0f, -1e4f)}) {
      const Vec3 a = offset + scale * Vec3(-0.5f, 0.2f, -0.4f), b = offset + scale * Vec3(0.6f, 0.3f, -0.3f),
                 c = offset + scale * Vec3(0.5f, 0.4f, 0.7f);
      const Vec3 d = a + (c - b);  // a parallelogram a, b, c, d
      const Vec3 n = glm::normalize(glm::cross(b - a, d - a));
      const std::array<Vec2, 4> uv4 = {Vec2(0, 0), Vec2(1, 0), Vec2(1, 1), Vec2(0, 1)};
      std::vector<std::unique_ptr<Shape>> shapes;
      shapes.push_back(std::make_unique<Quad>(std::array<Vec3, 4>{a, b, c, d}, uv4));
      shapes.push_back(std::make_unique<Disc>(0.5f * (a + c), n, 0.4f * scale));
      shapes.push_back(std::make_unique<Triangle>(std::array<Vec3, 3>{a, b, c},
                                                  std::array<Vec2, 3>{Vec2(0, 0), Vec2(1, 0), Vec2(1, 1)}));
      shapes.push_back(
          std::make_unique<FlippedShape>(std::make_unique<Quad>(std::array<Vec3, 4>{a, b, c, d}, uv4)));
      const float y = offset.y + 0.3f * scale;  // an axis-aligned rectangle, as a ceiling light
      const std::array<Vec3, 4> rectangle = {Vec3(a.x, y, a.z), Vec3(a.x, y, c.z), Vec3(c.x, y, c.z),
                                             Vec3(c.x, y, a.z)};
      shapes.push_back(std::make_unique<Quad>(rectangle, uv4));
      shapes.push_back(std::make_unique<FlippedShape>(std::make_unique<Quad>(rectangle, uv4)));
      for (const auto& shape : shapes) {
        if (!shape->flat()) continue;  // a parallelogram whose halves' planes round apart
        ++flatShapes;
        const AreaLight light(shape.get(), Color(1.0f));
        const Vec3 normal = shape->sampleArea(Vec2(0.5f)).n;
        std::vector<Vec3> refs;
        for (int i = 0; i < 64; ++i) {
          // In the plane, within the shape and around it.
          const Vec3 p1 = shape->sampleArea(next2(rng)).p, p2 = shape->sampleArea(next2(rng)).p;
          const Vec3 onPlane = p1 + next2(rng).x * (p1 - p2);
          const float distance = scale * std::pow(10.0f, -7.0f + 7.0f * next2(rng).x);
          refs.push_back(onPlane + (i % 2 ? distance : -distance) * normal);
          refs.push_back(offset + scale * 3.0f * (Vec3(next2(rng), next2(rng).x) - Vec3(0.5f)));
        }
        std::vector<Vec2> us(refs.size());
        for (Vec2& u : us) u = next2(rng);
        std::vector<LightSample> out(refs.size());
        std::unique_ptr<bool[]> ok(new bool[refs.size()]);
        light.sampleLanes(refs.data(), us.data(), refs.size(), out.data(), ok.get());
        for (size_t i = 0; i < refs.size(); ++i) {
          if (!light.seesOnlyBack(refs[i])) continue;
          EXPECT_FALSE(ok[i]) << i;
          bool anySample = false;
          for (int k = 0; k < 16; ++k) {
            ShapeSample s;
            float pdf = 0.0f;
            if (!shape->sampleSolidAngle(refs[i], next2(rng), s, pdf) || !(pdf > 0.0f)) continue;
            const Vec3 toLight = s.p - refs[i];
            const float dist = glm::length(toLight);
            if (dist == 0.0f) continue;
            anySample = true;
            EXPECT_FALSE(glm::dot(-(toLight / dist), s.n) > 0.0f)
                << shape->typeName() << " scale " << scale << ": ref " << i
                << " skipped, but a sample faces it";
          }
          if (anySample) ++skipped;
        }
        for (size_t i = 0; i < refs.size(); ++i)
          if (!light.seesOnlyBack(refs[i]) &&
              glm::dot(refs[i] - shape->sampleArea(Vec2(0.5f)).p, normal) < 0.0f)
            ++sampledBehind;
      }
      // An emissive mesh's triangle (TriangleLight), against points all over it.
      TriangleMesh mesh;
      mesh.positions = {a, b, c};
      mesh.indices = {glm::uvec3(0, 1, 2)};
      const TriangleLight triangle(&mesh, 0, Color(1.0f));
      const Vec3 ng = mesh.surfaceAt(0, 0.0f, 0.0f).ng;
      for (int i = 0; i < 128; ++i) {
        const Vec3 p1 = mesh.pointAt(0, next2(rng).x * 0.5f, next2(rng).x * 0.5f);
        const float distance = scale * std::pow(10.0f, -7.0f + 7.0f * next2(rng).x);
        const Vec3 ref = p1 + 2.0f * (p1 - a) * next2(rng).x + (i % 2 ? distance : -distance) * ng;
        if (!triangle.seesOnlyBack(ref)) continue;
        ++triangleSkips;
        LightSample out;
        EXPECT_FALSE(triangle.sample(ref, next2(rng), out));
        for (int k = 0; k < 16; ++k) {
          const Vec2 u = next2(rng);
          const Vec3 p = mesh.pointAt(0, u.x * (1.0f - u.y), u.y);
          const float dist = glm::length(p - ref);
          if (dist > 0.0f) {
            EXPECT_FALSE(glm::dot(-(p - ref) / dist, ng) > 0.0f) << "triangle scale " << scale;
          }
        }
      }
    }
  EXPECT_GT(triangleSkips, 200u);
  EXPECT_GE(flatShapes, 36u);     // the disc, the triangle and the rectangles in every case
  EXPECT_GT(skipped, 1000u);      // the skip is exercised
  EXPECT_GT(sampledBehind, 50u);  // and references within the margin behind are still sampled
}

// The cosine kernel against the scalar warp (core/sampling.h) and frame (core/math.h): the same
// directions to float precision (SIMD sin and cos are within a few ulps of libm's), unit length,
// in the normal's hemisphere, with pdf cos / pi, for normals along every axis and sign (the
// frame's branch) and u at the square's centre, edges and diagonals (the concentric map's).
TEST(SamplingLanes, CosineKernelAgreesWithTheScalarWarp) {
  Rng rng(19, 5);
  std::vector<Vec3> normals = {Vec3(0, 0, 1), Vec3(0, 0, -1), Vec3(1, 0, 0), Vec3(0, -1, 0),
                               glm::normalize(Vec3(1e-7f, 0.0f, -1.0f))};
  for (int i = 0; i < 200; ++i) normals.push_back(sampleUniformSphere(next2(rng)));
  std::vector<Vec2> us = {Vec2(0.5f),         Vec2(0.0f),         Vec2(0.99999994f),      Vec2(0.5f, 0.0f),
                          Vec2(0.25f, 0.75f), Vec2(0.75f, 0.75f), Vec2(0.5f, 0.99999994f)};
  for (int i = 0; i < 400; ++i) us.push_back(next2(rng));
  CosineLanes lanes;
  for (size_t k = 0; k < normals.size() * 4; k += CosineLanes::kMaxLanes) {
    for (unsigned i = 0; i < CosineLanes::kMaxLanes; ++i)
      lanes.set(i, normals[(k + i) % normals.size()], us[(k + 7 * i) % us.size()]);
    sampleCosineLanes(lanes);
    for (unsigned i = 0; i < CosineLanes::kMaxLanes; ++i) {
      const Vec3 n = normals[(k + i) % normals.size()];
      const Vec3 local = sampleCosineHemisphere(us[(k + 7 * i) % us.size()]);
      const Vec3 expected = Frame(n).toWorld(local);
      const Vec3 wi = lanes.direction(i);
      // z = sqrt(1 - x^2 - y^2) cancels at the disc's rim: grazing directions carry eps / z.
      const float tolerance = 2e-6f + 4e-7f / std::max(local.z, 1e-6f);
      EXPECT_LE(glm::length(wi - expected), tolerance) << "lane " << i << " of block " << k;
      EXPECT_NEAR(glm::length(wi), 1.0f, 2e-6f);
      EXPECT_GE(glm::dot(wi, n), -1e-6f);
      EXPECT_NEAR(lanes.pdf[i], cosineHemispherePdf(local.z), tolerance * kInvPi);
      EXPECT_NEAR(lanes.pdf[i], std::max(0.0f, glm::dot(wi, n)) * kInvPi, 2e-6f);
    }
  }
}

TEST(SamplingLanes, LambertianLanesEqualSingleSamples) {
  Rng rng(23, 6);
  const Lambertian material(std::make_shared<ConstantTexture>(Color(0.7f, 0.5f, 0.3f)));
  std::vector<SurfaceHit> hits(37);
  std::vector<const SurfaceHit*> hitOf;
  std::vector<Vec3> wo;
  std::vector<Vec2> u;
  std::vector<float> uLobe;
  for (SurfaceHit& hit : hits) {
    hit.p = Vec3(rng.uniform(), rng.uniform(), rng.uniform());
    hit.ng = sampleUniformSphere(next2(rng));
    // Shading normals tilted off the geometric one: some samples dip below the surface.
    hit.ns = glm::normalize(hit.ng + 0.6f * sampleUniformSphere(next2(rng)));
    if (glm::dot(hit.ns, hit.ng) < 0.0f) hit.ns = -hit.ns;
    hitOf.push_back(&hit);
    wo.push_back(sampleUniformSphere(next2(rng)));  // either side
    u.push_back(next2(rng));
    uLobe.push_back(rng.uniform());
  }
  std::vector<BsdfSample> out(hits.size());
  bool ok[37];
  material.sampleLanes(hitOf.data(), wo.data(), u.data(), uLobe.data(), hits.size(), out.data(), ok);
  size_t absorbed = 0;
  for (size_t i = 0; i < hits.size(); ++i) {
    BsdfSample single;
    ASSERT_EQ(material.sample(hits[i], wo[i], u[i], uLobe[i], single), ok[i]) << i;
    if (!ok[i]) {
      ++absorbed;
      continue;
    }
    EXPECT_EQ(single.pdf, out[i].pdf);
    for (int c = 0; c < 3; ++c) {
      EXPECT_EQ(single.wi[c], out[i].wi[c]);
      EXPECT_EQ(single.weight[c], out[i].weight[c]);
    }
  }
  EXPECT_GT(absorbed, 0u);
  EXPECT_LT(absorbed, hits.size() / 2);
}

// The Sobol kernel is integer arithmetic: equal to the scalar sampler bit for bit, for samplers at
// every dimension (below, at and past the Sobol ones), both sampler types, any pixel and index,
// and any run length (partial blocks, blocks interrupted by PCG32 lanes).
void expectSamplerLanesEqualTheScalarSampler() {
  Rng rng(29, 7);
  for (const SamplerType type : {SamplerType::Sobol, SamplerType::Independent}) {
    std::vector<Sampler> lanes, reference;
    for (int i = 0; i < 53; ++i) {
      const uint64_t pixel = uint64_t(rng.nextU32()) * (i % 3 == 0 ? 1u : 977u);
      const uint64_t index = i % 5 == 0 ? uint64_t(i) : uint64_t(rng.nextU32());
      lanes.emplace_back(type, 1234 + uint64_t(i % 2), pixel, index);
      reference.emplace_back(type, 1234 + uint64_t(i % 2), pixel, index);
      // Lanes start at different dimensions, as a bounce's paths do.
      for (int k = 0; k < i % 11; ++k) {
        lanes.back().get1D();
        reference.back().get1D();
      }
    }
    const std::vector<Sampler> initial = lanes;  // for the skipped requests below
    std::vector<Sampler*> pointers;
    for (Sampler& s : lanes) pointers.push_back(&s);
    for (int request = 0; request < 16; ++request) {
      const size_t n = request % 4 == 3 ? 17 : lanes.size();  // some requests for a prefix only
      if (request % 8 == 6 || request % 8 == 7) {             // 7 and 15: a prefix of 17 samplers
        // Two requests per sampler in one pass, in either order.
        std::vector<float> one(n);
        std::vector<Vec2> two(n);
        const bool oneFirst = request % 8 == 6;
        if (oneFirst) {
          draw1DThen2DLanes(pointers.data(), n, one.data(), two.data());
        } else {
          draw2DThen1DLanes(pointers.data(), n, two.data(), one.data());
        }
        for (size_t i = 0; i < n; ++i) {
          float expectedOne = 0.0f;
          if (oneFirst) expectedOne = reference[i].get1D();
          const Vec2 expectedTwo = reference[i].get2D();
          if (!oneFirst) expectedOne = reference[i].get1D();
          EXPECT_EQ(expectedOne, one[i]) << "request " << request << " lane " << i;
          EXPECT_EQ(expectedTwo.x, two[i].x) << "request " << request << " lane " << i;
          EXPECT_EQ(expectedTwo.y, two[i].y) << "request " << request << " lane " << i;
        }
      } else if (request % 2 == 0) {
        std::vector<Vec2> out(n);
        draw2DLanes(pointers.data(), n, out.data());
        for (size_t i = 0; i < n; ++i) {
          const Vec2 expected = reference[i].get2D();
          EXPECT_EQ(expected.x, out[i].x) << "request " << request << " lane " << i;
          EXPECT_EQ(expected.y, out[i].y) << "request " << request << " lane " << i;
        }
      } else {
        std::vector<float> out(n);
        draw1DLanes(pointers.data(), n, out.data());
        for (size_t i = 0; i < n; ++i)
          EXPECT_EQ(reference[i].get1D(), out[i]) << "request " << request << " lane " << i;
      }
    }
    // Requests no one reads (RequestUse) are passed over: the read ones equal the scalar draws,
    // the others are 0.5, and the samplers' later numbers are what the full draws leave. The
    // samplers start afresh (at dimensions 0 to 10), so that the rounds take each one that starts
    // below kMaxSobolDimensions through its last Sobol dimensions into its PCG32 stream.
    lanes = initial;
    reference = initial;
    for (size_t i = 0; i < lanes.size(); ++i) pointers[i] = &lanes[i];
    const size_t n = lanes.size();
    for (int round = 0; round < 12; ++round) {
      std::vector<float> one(n);
      std::vector<Vec2> two(n);
      std::vector<RequestUse> use(n);
      for (size_t i = 0; i < n; ++i)
        use[i] = {(i + size_t(round)) % 2 == 0, (i / 2 + size_t(round)) % 2 == 0};
      const bool oneFirst = round % 2 == 0;
      const RequestUse uniform = use[size_t(round) % 4];  // the same for every sampler
      if (oneFirst)
        draw1DThen2DLanes(pointers.data(), n, one.data(), two.data(), uniform);
      else
        draw2DThen1DLanes(pointers.data(), n, two.data(), one.data(), use.data());
      for (size_t i = 0; i < n; ++i) {
        const RequestUse u = oneFirst ? uniform : use[i];
        const bool readsOne = oneFirst ? u.first : u.second, readsTwo = oneFirst ? u.second : u.first;
        float expectedOne = 0.0f;
        if (oneFirst) expectedOne = reference[i].get1D();
        const Vec2 expectedTwo = reference[i].get2D();
        if (!oneFirst) expectedOne = reference[i].get1D();
        EXPECT_EQ(readsOne ? expectedOne : 0.5f, one[i]) << "round " << round << " lane " << i;
        EXPECT_EQ(readsTwo ? expectedTwo.x : 0.5f, two[i].x) << "round " << round << " lane " << i;
        EXPECT_EQ(readsTwo ? expectedTwo.y : 0.5f, two[i].y) << "round " << round << " lane " << i;
      }
    }
  }
}

// On every SIMD target this CPU runs and the build compiled, not only the one dispatch picks: the
// kernel's bit reversal is written differently for one-lane targets and for byte shuffles.
TEST(SamplingLanes, SamplerLanesEqualTheScalarSamplerOnEveryTarget) {
  forEachSimdTarget(expectSamplerLanesEqualTheScalarSampler);
}

}  // namespace
}  // namespace ember
