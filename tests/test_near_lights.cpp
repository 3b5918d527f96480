// Direct light right next to emitters, where next-event estimation is fragile: shadow rays that
// end on a curved emitter must not report the emitter itself as the blocker, and huge densities
// (d^2 / cos) must not overflow the MIS weights. The receiver is a Lambertian ceiling (albedo
// rho, facing down) with emitters of radiance 1 below it, direct light only (max depth 2).
//  - Closed forms, at one point seen through a tiny orthographic footprint: a sphere on its axis
//    (E = pi L sin^2 theta_max), a disc on its axis (pi L R^2 / (h^2 + R^2)), polygons and boxes by
//    Lambert's contour integral (clipped to the horizon), point and spot lights (I / h^2), and a
//    uniform sky behind a black sphere (pi L (1 - sin^2 theta_max)). Each strategy must match.
//  - The three strategies against each other where there is no closed form, and over whole images
//    of the ceiling around every emitter type (every distance and angle at once), by z-tests from
//    the images' own per-pixel variances (io/image_compare.h).
// Gaps are 0.5%-5% of the emitter's size, emitters pierce the ceiling's plane (partly below the
// horizon) or light it at grazing incidence, and sizes range from 1e-3 to 100.
#include "accel/box.h"
#include "accel/cone.h"
#include "accel/cylinder.h"
#include "accel/disc.h"
#include "accel/sphere.h"
#include "accel/triangle.h"
#include "gltf_builder.h"
#include "io/gltf_loader.h"
#include "io/image_compare.h"
#include "materials/lambertian.h"
#include "test_fixtures.h"

#include <glm/gtc/matrix_transform.hpp>

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <functional>
#include <optional>
#include <vector>

namespace ember {
namespace {

constexpr float kRho = 0.5f;
constexpr Strategy kStrategies[] = {Strategy::Mis, Strategy::Bsdf, Strategy::Light};

std::shared_ptr<const Texture> grey(float v) {
  return std::make_shared<ConstantTexture>(Color(v));
}

// The receiver: a 20 x 20 Lambertian quad in the plane y = 0 facing down (-y).
Scene ceilingScene() {
  Scene s;
  s.settings.maxDepth = 2;
  const Material* m = s.addMaterial("ceiling", std::make_unique<Lambertian>(grey(kRho)));
  s.shapes.push_back(
      {"ceiling",
       std::make_unique<Quad>(
           std::array<Vec3, 4>{Vec3(-10, 0, -10), Vec3(10, 0, -10), Vec3(10, 0, 10), Vec3(-10, 0, 10)},
           std::array<Vec2, 4>{Vec2(0, 0), Vec2(1, 0), Vec2(1, 1), Vec2(0, 1)}),
       m, Color(0.0f)});
  return s;
}

const Material* blackMaterial(Scene& s) {
  return s.addMaterial("black", std::make_unique<Lambertian>(grey(0.0f)));
}

void addEmitter(Scene& s, std::unique_ptr<Shape> shape, bool twoSided = false) {
  s.shapes.push_back({"emitter", std::move(shape), blackMaterial(s), Color(1.0f), twoSided});
}

// An emissive glTF mesh (tests/gltf_builder.h) placed by `transform`.
void addGltfEmitter(Scene& s, const std::function<void(test::GltfBuilder&, int material)>& build,
                    const Mat4& transform, bool doubleSided, bool textured = false,
                    const std::function<void(test::GltfBuilder&, tinygltf::Material&)>& tweak = {}) {
  test::GltfBuilder b;
  tinygltf::Material m;
  m.name = "glow";
  m.pbrMetallicRoughness.baseColorFactor = {0.0, 0.0, 0.0, 1.0};
  m.emissiveFactor = {1.0, 1.0, 1.0};
  m.doubleSided = doubleSided;
  if (textured) {  // a 2 x 2 sRGB checker of 255 and 64: linear 1 and ~0.05
    m.emissiveTexture.index = b.addTexture(2, 2, 3, {255, 255, 255, 64, 64, 64, 64, 64, 64, 255, 255, 255},
                                           TINYGLTF_TEXTURE_WRAP_REPEAT, TINYGLTF_TEXTURE_WRAP_REPEAT,
                                           TINYGLTF_TEXTURE_FILTER_NEAREST);
  }
  if (tweak) tweak(b, m);
  build(b, b.addMaterial(m));
  static int counter = 0;
  const std::string path =
      (std::filesystem::temp_directory_path() /
       ("ember_near_" + std::to_string(::getpid()) + "_" + std::to_string(counter++) + ".gltf"))
          .string();
  ASSERT_TRUE(b.write(path));
  GltfImportOptions options;
  options.transform = transform;
  importGltf(path, s, options);
  std::filesystem::remove(path);
}

// The unit quad of GltfBuilder::addQuad (z = 0, facing +z) turned to face -y... or +y.
Mat4 horizontal(const Vec3& center, float facingY) {
  return glm::rotate(glm::translate(Mat4(1.0f), center), glm::radians(facingY > 0 ? -90.0f : 90.0f),
                     Vec3(1, 0, 0));
}

struct Estimate {
  double mean = 0.0, stderr_ = 0.0;
};

// Mean over all pixels of channel 0, with its standard error from the per-pixel variances.
Estimate pooled(const Film& film) {
  const Image mean = film.mean(), var = film.varianceOfMean();
  double m = 0.0, v = 0.0;
  const double n = double(mean.width) * double(mean.height);
  for (size_t i = 0; i < mean.rgb.size(); i += 3) {
    m += mean.rgb[i];
    v += var.rgb[i];
  }
  return {m / n, std::sqrt(v) / n};
}

// Radiance reflected at the ceiling point `at`, estimated by `strategy` from 64 x 64 pixels x spp
// paths whose first segment starts `distance` from `at` (below it, at grazing incidence, so that
// it passes beside the emitters) and hits it: a point probe with no footprint. The hit point's rounding
// error, and so the offset of the rays leaving it, grows with that distance: 1e-6 is a camera right at the
// surface, 3 one across the room.
class PointProbe final : public Integrator {
 public:
  PointProbe(const Scene& scene, const Vec3& at, float distance)
      : path_(scene.settings), ray_{at - distance * kDir, kDir} {}
  Color Li(const Scene& scene, Ray, Sampler& sampler, PathStats& stats) const override {
    return path_.Li(scene, ray_, sampler, stats);
  }

  static constexpr Vec3 kDir{0.99980003f, 0.019998f, 0.0f};  // 1.15 degrees above the horizon

 private:
  PathIntegrator path_;
  Ray ray_;
};

Estimate estimateAt(Scene& scene, Strategy strategy, int spp, float distance = 1e-6f,
                    const Vec3& at = Vec3(0.0f)) {
  scene.settings.width = scene.settings.height = 64;
  scene.settings.strategy = strategy;
  scene.build();
  const PointProbe probe(scene, at, distance);
  Film film(scene.settings.width, scene.settings.height);
  RenderOptions options;
  options.spp = spp;
  options.seed = 17;
  const RenderStats stats = render(scene, probe, options, film);
  EXPECT_EQ(stats.nonFinite, 0u);
  return pooled(film);
}

std::string name(Strategy s) {
  return std::string(strategyName(s));
}

// Every strategy (delta lights: mis and light) against the exact value where there is one, and
// each pair against each other. Each estimate must be precise enough to mean something: mis (the
// default) to 0.3%, bsdf to 1%, and light sampling alone to 20%: discs, cylinders, cones, boxes and
// triangles are sampled by area, whose variance grows as 1 / gap^2 right next to them.
void expectAllStrategiesMatch(const std::function<Scene()>& make, std::optional<double> expected,
                              const std::string& what, bool deltaLights = false, int spp = 256,
                              float probeDistance = 1e-6f) {
  std::vector<std::pair<Strategy, Estimate>> results;
  for (Strategy s : kStrategies) {
    if (deltaLights && s == Strategy::Bsdf) continue;
    Scene scene = make();
    const Estimate e = estimateAt(scene, s, spp, probeDistance);
    const double reference = expected.value_or(e.mean);
    std::printf("[ %s ] %-5s %.6f +- %.6f", what.c_str(), name(s).c_str(), e.mean, e.stderr_);
    if (expected) std::printf(" (exact %.6f, %+.3f%%)", *expected, 100.0 * (e.mean / *expected - 1.0));
    std::printf("\n");
    // 1e-4 relative: what the variance cannot see (the footprint, float rounding of the exact value).
    if (expected) {
      EXPECT_NEAR(e.mean, *expected, 5.0 * e.stderr_ + 1e-4 * *expected) << what << ", strategy " << name(s);
    }
    const double precision = s == Strategy::Mis ? 0.003 : s == Strategy::Bsdf ? 0.01 : 0.2;
    EXPECT_LT(e.stderr_, precision * reference) << what << ", strategy " << name(s) << ": too noisy to tell";
    results.emplace_back(s, e);
  }
  for (size_t i = 0; i < results.size(); ++i)
    for (size_t j = i + 1; j < results.size(); ++j) {
      const Estimate a = results[i].second, b = results[j].second;
      EXPECT_NEAR(a.mean, b.mean, 5.0 * std::hypot(a.stderr_, b.stderr_))
          << what << ": " << name(results[i].first) << " vs " << name(results[j].first);
    }
}

// --- closed forms ------------------------------------------------------------------------------

// Irradiance at the origin (receiver normal -y) from a polygon of radiance 1 facing it, by
// Lambert's contour integral E = 1/2 sum_i Theta_i (n . Gamma_i) (Arvo 1994, eq. 5) over the
// polygon clipped to the receiver's hemisphere y < 0 (Sutherland-Hodgman).
double polygonIrradiance(const std::vector<glm::dvec3>& polygon) {
  std::vector<glm::dvec3> clipped;
  for (size_t i = 0; i < polygon.size(); ++i) {
    const glm::dvec3 a = polygon[i], b = polygon[(i + 1) % polygon.size()];
    if (a.y < 0.0) clipped.push_back(a);
    if ((a.y < 0.0) != (b.y < 0.0)) clipped.push_back(a + (b - a) * (a.y / (a.y - b.y)));
  }
  double sum = 0.0;
  const glm::dvec3 n(0.0, -1.0, 0.0);
  for (size_t i = 0; i < clipped.size(); ++i) {
    const glm::dvec3 a = glm::normalize(clipped[i]), b = glm::normalize(clipped[(i + 1) % clipped.size()]);
    const glm::dvec3 c = glm::cross(a, b);
    const double len = glm::length(c);
    if (len == 0.0) continue;
    sum += std::atan2(len, glm::dot(a, b)) * glm::dot(n, c / len);
  }
  return 0.5 * std::abs(sum);
}

std::vector<glm::dvec3> toDouble(std::initializer_list<Vec3> v) {
  return std::vector<glm::dvec3>(v.begin(), v.end());
}

TEST(NearLights, SphereOnItsAxisMatchesTheClosedForm) {
  struct Case {
    float radius, gap;
  };
  // The measurements (gaps 0.05 and 0.02 lost 34% and 53%), 0.5%-5% of the diameter, tiny,
  // huge, and one far away.
  // Seen from a camera 3 away (the set-up) and from right at the surface: the hit point is
  // rebuilt on the surface (Shape::projectToSurface), so rays leave it just as close to the surface
  // when it was found from afar, even next to the tiny sphere 2e-5 away.
  for (const Case c : {Case{0.15f, 0.05f}, Case{0.1f, 0.02f}, Case{0.1f, 0.001f}, Case{0.1f, 0.01f},
                       Case{0.15f, 0.35f}, Case{1e-3f, 2e-5f}, Case{100.0f, 1.0f}})
    for (const float probeDistance : {3.0f, 1e-6f}) {
      const double d = double(c.radius) + double(c.gap);
      const double sin2 = double(c.radius) * c.radius / (d * d);
      expectAllStrategiesMatch(
          [&] {
            Scene s = ceilingScene();
            addEmitter(s, std::make_unique<Sphere>(Vec3(0.0f, -float(d), 0.0f), c.radius));
            return s;
          },
          kRho * sin2,
          "sphere r " + std::to_string(c.radius) + " gap " + std::to_string(c.gap) + ", seen from " +
              std::to_string(probeDistance),
          false, 256, probeDistance);
    }
}

TEST(NearLights, DiscOnItsAxisMatchesTheClosedForm) {
  for (const float h : {0.002f, 0.01f, 0.3f}) {
    constexpr float kR = 0.2f;
    expectAllStrategiesMatch(
        [&] {
          Scene s = ceilingScene();
          addEmitter(s, std::make_unique<Disc>(Vec3(0.0f, -h, 0.0f), Vec3(0, 1, 0), kR));
          return s;
        },
        kRho * kR * kR / (double(h) * h + double(kR) * kR), "disc gap " + std::to_string(h));
  }
}

TEST(NearLights, PolygonsMatchLambertsContourIntegral) {
  // A vertical quad 0.05 to the side, facing the point: light arrives at grazing incidence, its
  // top edge 0.002 below the ceiling.
  const std::array<Vec3, 4> grazing{Vec3(0.05f, -0.002f, -0.2f), Vec3(0.05f, -0.3f, -0.2f),
                                    Vec3(0.05f, -0.3f, 0.2f), Vec3(0.05f, -0.002f, 0.2f)};
  // A tilted quad piercing the ceiling's plane: part of it is behind the horizon.
  const std::array<Vec3, 4> piercing{Vec3(-0.1f, 0.05f, -0.15f), Vec3(-0.1f, 0.05f, 0.15f),
                                     Vec3(0.08f, -0.1f, 0.15f), Vec3(0.08f, -0.1f, -0.15f)};
  const std::array<Vec3, 3> nearTriangle{Vec3(-0.1f, -0.001f, -0.1f), Vec3(0.15f, -0.001f, 0.0f),
                                         Vec3(-0.05f, -0.004f, 0.12f)};
  const auto uv4 = std::array<Vec2, 4>{Vec2(0, 0), Vec2(1, 0), Vec2(1, 1), Vec2(0, 1)};
  const auto uv3 = std::array<Vec2, 3>{Vec2(0, 0), Vec2(1, 0), Vec2(0, 1)};

  for (const auto& labelled : {std::pair{"grazing quad", grazing}, std::pair{"piercing quad", piercing}}) {
    // Named copies, not structured bindings: C++20 lets a lambda capture those, clang 14 does not.
    const char* const label = labelled.first;
    const auto& quad = labelled.second;
    // Emitting towards the origin: the normal cross(v1 - v0, v2 - v0) must face it.
    const Vec3 n = glm::cross(quad[1] - quad[0], quad[2] - quad[0]);
    ASSERT_LT(glm::dot(n, quad[0]), 0.0f) << label;
    expectAllStrategiesMatch(
        [&] {
          Scene s = ceilingScene();
          addEmitter(s, std::make_unique<Quad>(quad, uv4));
          return s;
        },
        kRho / kPi * polygonIrradiance(toDouble({quad[0], quad[1], quad[2], quad[3]})), label);
  }
  // A triangle 0.001-0.004 below the ceiling, facing it (two-sided: the winding does not matter).
  expectAllStrategiesMatch(
      [&] {
        Scene s = ceilingScene();
        addEmitter(s, std::make_unique<Triangle>(nearTriangle, uv3), true);
        return s;
      },
      kRho / kPi * polygonIrradiance(toDouble({nearTriangle[0], nearTriangle[1], nearTriangle[2]})),
      "near triangle");
  // The same square as emissive glTF triangles 0.003 below: facing the ceiling, or facing away
  // with doubleSided (glTF section 3.9.5: the back face is lit, and emits, as the front).
  constexpr float h = 0.15f, gap = 0.003f;
  const double square = kRho / kPi *
                        polygonIrradiance(toDouble({Vec3(0.02f - h, -gap, -h), Vec3(0.02f + h, -gap, -h),
                                                    Vec3(0.02f + h, -gap, h), Vec3(0.02f - h, -gap, h)}));
  const auto glTFSquare = [&](float facingY, bool doubleSided) {
    return [=] {
      Scene s = ceilingScene();
      addGltfEmitter(
          s, [&](test::GltfBuilder& b, int m) { b.addQuad(h, m); },
          horizontal(Vec3(0.02f, -gap, 0.0f), facingY), doubleSided);
      return s;
    };
  };
  expectAllStrategiesMatch(glTFSquare(1.0f, false), square, "glTF quad facing the ceiling");
  expectAllStrategiesMatch(glTFSquare(-1.0f, true), square, "doubleSided glTF quad facing away");
  // Single-sided and facing away: no light at all, whichever strategy looks for it.
  for (Strategy strategy : kStrategies) {
    Scene s = glTFSquare(-1.0f, false)();
    EXPECT_EQ(estimateAt(s, strategy, 16).mean, 0.0) << name(strategy);
  }
}

TEST(NearLights, BoxMatchesLambertsContourIntegralOverItsVisibleFaces) {
  const Vec3 center(0.03f, -0.105f, -0.02f), size(0.3f, 0.2f, 0.25f);
  const glm::mat3 rotation(glm::rotate(Mat4(1.0f), 0.4f, glm::normalize(Vec3(0.3f, 1.0f, 0.2f))));
  // Faces that face the origin, each clipped to the horizon: the box's top is 0.005 below the
  // ceiling at its highest corner or pierces it.
  double irradiance = 0.0;
  const Vec3 half = 0.5f * size;
  for (int axis = 0; axis < 3; ++axis)
    for (const float sign : {-1.0f, 1.0f}) {
      const int a = (axis + 1) % 3, b = (axis + 2) % 3;
      Vec3 nLocal(0.0f);
      nLocal[axis] = sign;
      std::vector<glm::dvec3> face;
      for (const auto& [sa, sb] : {std::pair{-1, -1}, std::pair{1, -1}, std::pair{1, 1}, std::pair{-1, 1}}) {
        Vec3 local(0.0f);
        local[axis] = sign * half[axis];
        local[a] = float(sa) * half[a];
        local[b] = float(sb) * half[b];
        face.push_back(glm::dvec3(center + rotation * local));
      }
      const glm::dvec3 n(rotation * nLocal);
      if (glm::dot(n, -face[0]) > 0.0) irradiance += polygonIrradiance(face);
    }
  expectAllStrategiesMatch(
      [&] {
        Scene s = ceilingScene();
        addEmitter(s, std::make_unique<Box>(center, size, rotation));
        return s;
      },
      kRho / kPi * irradiance, "box");
}

TEST(NearLights, PointAndSpotLightsMatchTheInverseSquareLaw) {
  for (const float h : {0.001f, 0.05f}) {
    constexpr float kIntensity = 2.0f;
    const double expected = kRho / kPi * kIntensity / (double(h) * h);
    expectAllStrategiesMatch(
        [&] {
          Scene s = ceilingScene();
          s.lights.push_back(std::make_unique<PointLight>(Vec3(0.0f, -h, 0.0f), Color(kIntensity)));
          return s;
        },
        expected, "point light " + std::to_string(h), true, 16);
    expectAllStrategiesMatch(
        [&] {
          Scene s = ceilingScene();
          s.lights.push_back(std::make_unique<SpotLight>(Vec3(0.0f, -h, 0.0f), Vec3(0, 1, 0),
                                                         Color(kIntensity), 0.3f, 0.5f));
          return s;
        },
        expected, "spot light " + std::to_string(h), true, 16);
  }
}

TEST(NearLights, UniformSkyBehindABlackSphereMatchesTheClosedForm) {
  constexpr float kR = 0.1f, kGap = 0.002f;
  const double d = double(kR) + kGap;
  expectAllStrategiesMatch(
      [&] {
        Scene s = ceilingScene();
        s.shapes.push_back({"occluder", std::make_unique<Sphere>(Vec3(0.0f, -float(d), 0.0f), kR),
                            blackMaterial(s), Color(0.0f)});
        s.background = Color(1.0f);
        return s;
      },
      kRho * (1.0 - kR * kR / (d * d)), "sky behind a sphere");
}

// --- the strategies against each other ---------------------------------------------------------

struct EmitterCase {
  std::string label;
  std::function<void(Scene&)> add;
  bool deltaLights = false;
  // Sampled by area (renderer/light.h: discs, cylinders, cones, boxes, and triangles seen from
  // farther than their size): right next to such an emitter, light sampling alone has a variance
  // of order area / gap^2, carried by rare huge samples, so that its sample variance is no basis
  // for a z-test at any affordable count. Triangles close by are sampled by solid angle.
  bool areaSampled = false;
  float brightest = 1.0f;  // the largest radiance a path can find
};

// One of every emitter type, near the ceiling and awkwardly placed.
std::vector<EmitterCase> emitterCases() {
  const auto uv4 = std::array<Vec2, 4>{Vec2(0, 0), Vec2(1, 0), Vec2(1, 1), Vec2(0, 1)};
  const auto uv3 = std::array<Vec2, 3>{Vec2(0, 0), Vec2(1, 0), Vec2(0, 1)};
  return {
      {"sphere, gap 0.002",
       [](Scene& s) { addEmitter(s, std::make_unique<Sphere>(Vec3(0.02f, -0.102f, 0.0f), 0.1f)); }},
      {"sphere piercing the ceiling",
       [](Scene& s) { addEmitter(s, std::make_unique<Sphere>(Vec3(0.12f, -0.05f, 0.0f), 0.1f)); }},
      {"tilted disc, gap 0.002",
       [](Scene& s) {
         addEmitter(s, std::make_unique<Disc>(Vec3(0.0f, -0.1f, 0.0f), glm::normalize(Vec3(0.2f, 1.0f, 0.0f)),
                                              0.098f));
       },
       false, true},
      {"vertical quad beside, grazing",
       [uv4](Scene& s) {
         addEmitter(s, std::make_unique<Quad>(
                           std::array<Vec3, 4>{Vec3(0.05f, -0.002f, -0.2f), Vec3(0.05f, -0.3f, -0.2f),
                                               Vec3(0.05f, -0.3f, 0.2f), Vec3(0.05f, -0.002f, 0.2f)},
                           uv4));
       }},
      {"two-sided triangle, gap 0.001",
       [uv3](Scene& s) {
         addEmitter(s,
                    std::make_unique<Triangle>(
                        std::array<Vec3, 3>{Vec3(-0.1f, -0.001f, -0.1f), Vec3(0.15f, -0.001f, 0.0f),
                                            Vec3(-0.05f, -0.004f, 0.12f)},
                        uv3),
                    true);
       },
       false, false},
      {"horizontal capped cylinder, gap 0.002",
       [](Scene& s) {
         addEmitter(s, std::make_unique<Cylinder>(Vec3(-0.2f, -0.102f, 0.05f), Vec3(0.2f, -0.102f, -0.05f),
                                                  0.1f, true));
       },
       false, true},
      {"vertical cylinder below, gap 0.001",
       [](Scene& s) {
         addEmitter(
             s, std::make_unique<Cylinder>(Vec3(0.0f, -0.4f, 0.0f), Vec3(0.0f, -0.001f, 0.0f), 0.1f, true));
       },
       false, true},
      {"cone, apex 0.001 below",
       [](Scene& s) {
         addEmitter(s,
                    std::make_unique<Cone>(Vec3(0.05f, -0.2f, 0.0f), Vec3(0.0f, -0.001f, 0.0f), 0.15f, true));
       },
       false, true},
      {"cone lying on its side, gap 0.003",
       [](Scene& s) {
         addEmitter(
             s, std::make_unique<Cone>(Vec3(-0.2f, -0.103f, 0.0f), Vec3(0.2f, -0.003f, 0.0f), 0.1f, true));
       },
       false, true},
      {"rotated box, gap 0.003",
       [](Scene& s) {
         const glm::mat3 r(glm::rotate(Mat4(1.0f), 0.6f, glm::normalize(Vec3(0.0f, 1.0f, 1.0f))));
         addEmitter(s, std::make_unique<Box>(Vec3(0.0f, -0.13f, 0.0f), Vec3(0.2f, 0.2f, 0.2f), r));
       },
       false, true},
      {"glTF sphere, gap 0.002",
       [](Scene& s) {
         const float c[3] = {0.0f, 0.0f, 0.0f};
         addGltfEmitter(
             s, [&](test::GltfBuilder& b, int m) { b.addSphere(c, 0.1f, m, 12, 24); },
             glm::translate(Mat4(1.0f), Vec3(0.01f, -0.102f, 0.0f)), false);
       },
       false, true},
      {"doubleSided glTF quad, tilted, piercing the ceiling",
       [](Scene& s) {
         const Mat4 t = glm::rotate(horizontal(Vec3(0.0f, -0.02f, 0.0f), 1.0f), 0.3f, Vec3(0, 1, 0));
         addGltfEmitter(
             s, [&](test::GltfBuilder& b, int m) { b.addQuad(0.1f, m); }, t, true);
       },
       false, false},
      {"textured glTF quad, gap 0.002",
       [](Scene& s) {
         addGltfEmitter(
             s, [&](test::GltfBuilder& b, int m) { b.addQuad(0.1f, m); },
             horizontal(Vec3(0.03f, -0.002f, 0.0f), 1.0f), false, true);
       },
       false, false},
      {"alpha-masked glTF quad (cut-out checker), gap 0.002",
       [](Scene& s) {
         addGltfEmitter(
             s, [&](test::GltfBuilder& b, int m) { b.addQuad(0.1f, m); },
             horizontal(Vec3(0.02f, -0.002f, 0.0f), 1.0f), false, false,
             [](test::GltfBuilder& b, tinygltf::Material& m) {
               m.alphaMode = "MASK";
               m.pbrMetallicRoughness.baseColorTexture.index =
                   b.addTexture(2, 2, 4, {0, 0, 0, 255, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 255},
                                TINYGLTF_TEXTURE_WRAP_REPEAT, TINYGLTF_TEXTURE_WRAP_REPEAT,
                                TINYGLTF_TEXTURE_FILTER_NEAREST);
             });
       },
       false, false},
      {"alpha-blended glTF quad (alpha 0.4), gap 0.002",
       [](Scene& s) {
         addGltfEmitter(
             s, [&](test::GltfBuilder& b, int m) { b.addQuad(0.1f, m); },
             horizontal(Vec3(0.02f, -0.002f, 0.0f), 1.0f), true, false,
             [](test::GltfBuilder&, tinygltf::Material& m) {
               m.alphaMode = "BLEND";
               m.pbrMetallicRoughness.baseColorFactor = {0.0, 0.0, 0.0, 0.4};
             });
       },
       false, false},
      {"environment map behind a sphere, gap 0.002",
       [](Scene& s) {
         std::vector<Color> texels(32 * 16, Color(0.2f, 0.3f, 0.4f));
         for (int y = 10; y < 14; ++y)
           for (int x = 4; x < 9; ++x) texels[size_t(y * 32 + x)] = Color(20.0f, 15.0f, 10.0f);  // a low sun
         s.environmentMap = std::make_shared<ImageTexture>(32, 16, std::move(texels), TextureFilter::Bilinear,
                                                           TextureWrap::Repeat, Color(1.0f));
         s.shapes.push_back({"occluder", std::make_unique<Sphere>(Vec3(0.08f, -0.052f, 0.0f), 0.05f),
                             blackMaterial(s), Color(0.0f)});
       },
       false, false, 20.0f},
      {"point light 0.002 below",
       [](Scene& s) {
         s.lights.push_back(std::make_unique<PointLight>(Vec3(0.01f, -0.002f, 0.0f), Color(0.01f)));
       },
       true},
      {"spot light 0.002 below, tilted",
       [](Scene& s) {
         s.lights.push_back(std::make_unique<SpotLight>(
             Vec3(0.0f, -0.002f, 0.01f), glm::normalize(Vec3(0.0f, 1.0f, -1.0f)), Color(0.01f), 0.4f, 0.9f));
       },
       true},
  };
}

// At the ceiling point above each emitter.
TEST(NearLights, StrategiesAgreeAtAPointNextToEveryEmitterType) {
  for (const EmitterCase& c : emitterCases())
    expectAllStrategiesMatch(
        [&] {
          Scene s = ceilingScene();
          c.add(s);
          return s;
        },
        std::nullopt, c.label, c.deltaLights);
}

struct BlockComparison {
  int blocks = 0, failures = 0;
  double threshold = 0.0, maxAbsZ = 0.0, meanZ = 0.0;
  bool passes() const { return failures == 0 && std::abs(meanZ) <= threshold; }
  std::string describe() const {
    char buf[160];
    std::snprintf(buf, sizeof buf, "%d/%d blocks beyond |z| > %.2f, max |z| %.2f, image-mean z %.2f",
                  failures, blocks, threshold, maxAbsZ, meanZ);
    return buf;
  }
};

// Block means of channel 0 z-tested from the per-pixel variances of both films (as blockZTest in
// io/image_compare.h), Sidak-corrected over the blocks and the image mean. A difference within
// `resolution` per sample does not count: an estimator that found no light in a block has a
// sample variance of zero, yet it cannot resolve a mean below about 3 w / N (the "rule of three"
// for N samples that could each have contributed w), e.g. the grazing light far beside a flat
// emitter that BSDF sampling hits once in 1e5 samples.
BlockComparison compareBlocks(const Film& a, const Film& b, int block, int spp, double w) {
  const Image ma = a.mean(), va = a.varianceOfMean(), mb = b.mean(), vb = b.varianceOfMean();
  const int bx = (ma.width + block - 1) / block, by = (ma.height + block - 1) / block;
  BlockComparison r;
  r.blocks = bx * by;
  r.threshold = twoSidedNormalQuantile(sidakLevel(0.01, r.blocks + 1));
  // In units of d (a sum of n pixel means over n spp samples each), that resolution is 3 w / spp.
  auto z = [&](double d, double v) {
    const double excess = std::max(0.0, std::abs(d) - 3.0 * w / double(spp));
    return excess == 0.0 ? 0.0 : v > 0.0 ? excess / std::sqrt(v) : INFINITY;
  };
  double dAll = 0.0, vAll = 0.0;
  for (int j = 0; j < by; ++j)
    for (int i = 0; i < bx; ++i) {
      double d = 0.0, v = 0.0;
      for (int y = j * block; y < std::min(ma.height, (j + 1) * block); ++y)
        for (int x = i * block; x < std::min(ma.width, (i + 1) * block); ++x) {
          d += double(ma.at(x, y).x) - double(mb.at(x, y).x);
          v += double(va.at(x, y).x) + double(vb.at(x, y).x);
        }
      // d and v are sums over n pixels: the block mean difference d / n has variance v / n^2.
      const double zb = z(d, v);
      r.maxAbsZ = std::max(r.maxAbsZ, zb);
      r.failures += zb > r.threshold;
      dAll += d;
      vAll += v;
    }
  r.meanZ = std::copysign(z(dAll, vAll), dAll);
  return r;
}

// Over a whole image of the ceiling around each emitter, seen from below: every distance and
// angle to it at once. Block means (8 x 8 pixels) and the image mean of mis are z-tested against
// bsdf and light from the images' own variances at a family-wise level of 1%. Blocks pool many
// pixels, and bsdf gets four times the samples, because BSDF sampling finds light at grazing
// incidence so rarely that a single pixel may have no hit at all, and so a variance of zero.
// Light sampling alone is compared where its variance is a fair basis (EmitterCase::areaSampled);
// next to area-sampled emitters the point tests above compare it at a 20% precision.
TEST(NearLights, StrategiesAgreeOverTheCeilingAroundEveryEmitterType) {
  for (const EmitterCase& c : emitterCases()) {
    std::vector<std::pair<Strategy, Film>> films;
    for (Strategy strategy : kStrategies) {
      if (c.deltaLights && strategy == Strategy::Bsdf) continue;
      Scene s = ceilingScene();
      c.add(s);
      s.settings.width = s.settings.height = 32;
      s.settings.strategy = strategy;
      s.cameraParams = CameraParams{Vec3(0.05f, -0.7f, 0.2f), Vec3(0.0f), Vec3(0, 0, -1), 30.0f};
      s.build();
      RenderStats stats;
      films.emplace_back(strategy, test::renderFilm(s, strategy == Strategy::Bsdf ? 1024 : 256, 23, &stats));
      EXPECT_EQ(stats.nonFinite, 0u) << c.label;
    }
    for (size_t j = 1; j < films.size(); ++j) {
      if (films[j].first == Strategy::Light && c.areaSampled) continue;
      // The largest sample a path can carry here: rho times the brightest radiance it can reach.
      const BlockComparison r = compareBlocks(films[0].second, films[j].second, 8, 256, kRho * c.brightest);
      const std::string what = c.label + ": " + name(films[0].first) + " vs " + name(films[j].first);
      std::printf("[ %s ] %s\n", what.c_str(), r.describe().c_str());
      EXPECT_TRUE(r.passes()) << what << ": " << r.describe();
    }
  }
}

}  // namespace
}  // namespace ember
