// Caustics estimated two ways must agree: the path tracer alone (render.caustic_tracing false)
// against the path tracer plus the light tracer (renderer/caustic_tracer.h), which split path
// space between them. Whole small images, block means z-tested from both films' own per-pixel
// variances (io/image_compare.h), over a planar mirror, a glass sphere (refraction both ways, so
// the radiance scaling the light tracer must undo), a surface that is both a caster and a
// receiver (a mixed material with a mirror lobe), a two-sided light, path-length limits that cut
// the caustics (max depth 3 and 4: the light tracer must count segments as the path tracer does)
// and every strategy. A last case double-counts the caustics on purpose and must be rejected.
#include "io/image_compare.h"
#include "io/scene_loader.h"
#include "packet/wave_integrator.h"
#include "renderer/render.h"

#include <gtest/gtest.h>

#include "cli_runner.h"
#include "gltf_builder.h"
#include "test_fixtures.h"

#include <filesystem>
#include <fstream>
#include <string>

namespace ember {
namespace {

constexpr int kSize = 24;
constexpr int kSpp = 512;
constexpr double kAlpha = 1e-3;  // per comparison; about ten comparisons in this file

// A floor, a back wall and a light 0.8 x 0.8 above them, with `extra` shapes and materials.
std::string sceneJson(const std::string& extraMaterials, const std::string& extraShapes, int maxDepth,
                      bool twoSidedLight = false) {
  return R"({
    "image": {"width": )" +
         std::to_string(kSize) + R"(, "height": )" + std::to_string(kSize) + R"(},
    "camera": {"origin": [0, 1.1, 1.6], "target": [0, 0.5, 0], "up": [0, 1, 0], "fov_y_deg": 90},
    "render": {"max_depth": )" +
         std::to_string(maxDepth) + R"(, "rr_depth": 3},
    "materials": {
      "white": {"type": "diffuse", "reflectance": [0.8, 0.8, 0.8]},
      "black": {"type": "diffuse", "reflectance": [0, 0, 0]})" +
         extraMaterials + R"(
    },
    "shapes": [
      {"type": "quad", "material": "white", "vertices": [[-2, 0, 1.5], [2, 0, 1.5], [2, 0, -1.5], [-2, 0, -1.5]]},
      {"type": "quad", "material": "white", "vertices": [[-2, 0, -1.5], [2, 0, -1.5], [2, 2.5, -1.5], [-2, 2.5, -1.5]]},
      {"type": "quad", "material": "black", "emission": [6, 6, 5], "two_sided": )" +
         std::string(twoSidedLight ? "true" : "false") +
         R"(, "vertices": [[-0.4, 1.8, -0.6], [0.4, 1.8, -0.6], [0.4, 1.8, 0.2], [-0.4, 1.8, 0.2]]})" +
         extraShapes + R"(
    ]
  })";
}

// A mirror standing on the floor to the left, facing the light and the floor.
const std::string kMirrorMaterial = R"(, "mirror": {"type": "mirror", "reflectance": [0.9, 0.9, 0.9]})";
const std::string kMirrorShape =
    R"(, {"type": "quad", "material": "mirror", "vertices": [[-1.2, 0, 0.8], [-1.2, 0, -1.2], [-0.9, 1.4, -1.2], [-0.9, 1.4, 0.8]]})";
const std::string kGlassMaterial =
    R"(, "glass": {"type": "dielectric", "ior_inside": 1.5, "ior_outside": 1.0})";
const std::string kGlassShape =
    R"(, {"type": "sphere", "material": "glass", "center": [0.5, 0.75, -0.2], "radius": 0.4})";

Scene load(const std::string& json, const std::string& name) {
  const std::string path =
      (std::filesystem::temp_directory_path() / ("ember_caustics_" + name + ".json")).string();
  std::ofstream(path) << json;
  Scene scene = loadScene(path);
  std::filesystem::remove(path);
  return scene;
}

Film render(const Scene& scene, const Integrator& integrator, uint64_t seed) {
  Film film(scene.settings.width, scene.settings.height);
  RenderOptions options;
  options.spp = kSpp;
  options.seed = seed;
  options.sampler = scene.settings.sampler;
  options.threads = 0;
  render(scene, integrator, options, film);
  return film;
}

// The path tracer leaves caustics to the light tracer, or does not: the films of both.
struct Pair {
  Film lightTraced, pathOnly;
};

Pair renderBoth(Scene& scene) {
  scene.settings.traceCaustics = true;
  scene.build();
  EXPECT_TRUE(scene.causticTracer().enabled());
  Film traced = render(scene, *makeIntegrator(scene.settings, Kernel::Wave), 11);
  scene.settings.traceCaustics = false;
  Film alone = render(scene, *makeIntegrator(scene.settings, Kernel::Wave), 12);
  return {std::move(traced), std::move(alone)};
}

BlockZTestResult compare(const Film& a, const Film& b) {
  return blockZTest(a.mean(), a.varianceOfMean(), b.mean(), b.varianceOfMean(), 4, kAlpha);
}

void expectAgree(Scene scene, const std::string& what) {
  const Pair p = renderBoth(scene);
  const BlockZTestResult r = compare(p.lightTraced, p.pathOnly);
  EXPECT_TRUE(r.passes()) << what << ": " << r.failures << " of " << r.tests
                          << " block means differ (max |z| " << r.maxAbsZ << ", threshold " << r.threshold
                          << "), image-mean z " << r.meanZ[0] << " " << r.meanZ[1] << " " << r.meanZ[2];
}

TEST(CausticEstimators, PlanarMirrorAgreesWithThePathTracerAlone) {
  expectAgree(load(sceneJson(kMirrorMaterial, kMirrorShape, -1), "mirror"), "mirror");
}

// All the light the floor gets is a caustic: `light` (a shape entry) faces up, into a mirror
// ceiling. Seen through a 100-degree lens, so that the camera's importance (1 / cos^3 per splat) is
// tested far off the axis as well.
std::string mirrorCeilingScene(const std::string& light) {
  return R"({
    "image": {"width": 24, "height": 24},
    "camera": {"origin": [0, 0.9, 1.4], "target": [0, 0.2, -0.2], "up": [0, 1, 0], "fov_y_deg": 100},
    "render": {"max_depth": -1, "rr_depth": 3},
    "materials": {
      "white": {"type": "diffuse", "reflectance": [0.7, 0.7, 0.7]},
      "black": {"type": "diffuse", "reflectance": [0, 0, 0]},
      "mirror": {"type": "mirror", "reflectance": [0.95, 0.95, 0.95]}
    },
    "shapes": [
      {"type": "quad", "material": "white", "vertices": [[-3, 0, 2], [3, 0, 2], [3, 0, -3], [-3, 0, -3]]},
      {"type": "quad", "material": "mirror", "vertices": [[-3, 2, -3], [3, 2, -3], [3, 2, 2], [-3, 2, 2]]},
      )" +
         light + R"(
    ]
  })";
}

TEST(CausticEstimators, LightOnlyThroughAMirrorAgreesAcrossAWideView) {
  const std::string quad = R"({"type": "quad", "material": "black", "emission": [5, 5, 5],
       "vertices": [[-0.5, 1.2, 0.3], [0.5, 1.2, 0.3], [0.5, 1.2, -0.7], [-0.5, 1.2, -0.7]]})";
  expectAgree(load(mirrorCeilingScene(quad), "mirror-only"), "light only through a mirror");
}

TEST(CausticEstimators, GlassSphereAgreesWithThePathTracerAlone) {
  expectAgree(load(sceneJson(kGlassMaterial, kGlassShape, -1), "glass"), "glass");
}

TEST(CausticEstimators, TwoSidedLightAndBothCastersAgree) {
  expectAgree(load(sceneJson(kMirrorMaterial + kGlassMaterial, kMirrorShape + kGlassShape, -1, true), "both"),
              "two-sided light, mirror and glass");
}

// The floor reflects through a mirror lobe as well as diffusely: one surface is caster and
// receiver, and a light path may bounce between its two lobes.
TEST(CausticEstimators, MixedMaterialCasterAndReceiverAgrees) {
  const std::string mixed =
      R"(, "shiny": {"type": "mixed", "kd": [0.4, 0.4, 0.4], "kr": [0.35, 0.35, 0.35]})";
  const std::string shinyBox =
      R"(, {"type": "box", "material": "shiny", "center": [-0.5, 0.3, -0.4], "size": [0.6, 0.6, 0.6], "rotate_y_deg": 25})";
  expectAgree(load(sceneJson(mixed + kMirrorMaterial, shinyBox + kMirrorShape, -1), "mixed"), "mixed");
}

TEST(CausticEstimators, PathLengthLimitsCutBothAlike) {
  for (int depth : {3, 4}) {
    expectAgree(load(sceneJson(kMirrorMaterial + kGlassMaterial, kMirrorShape + kGlassShape, depth),
                     "depth" + std::to_string(depth)),
                "max depth " + std::to_string(depth));
  }
}

TEST(CausticEstimators, EveryStrategyAgrees) {
  for (Strategy strategy : {Strategy::Bsdf, Strategy::Light}) {
    Scene scene = load(sceneJson(kMirrorMaterial, kMirrorShape, -1), "strategy");
    scene.settings.strategy = strategy;
    expectAgree(std::move(scene), std::string(strategyName(strategy)));
  }
}

// Light tracing with a path tracer that does not leave it the caustics counts them twice: the
// comparison must see it (so it can fail), and the caustic must be a large share of the image.
class DoubleCounting final : public test::ForwardingIntegrator {
 public:
  explicit DoubleCounting(const Integrator& inner) : ForwardingIntegrator(inner) {}
  bool tracesCaustics() const override { return true; }
};

TEST(CausticEstimators, DoubleCountedCausticsAreRejected) {
  Scene scene = load(sceneJson(kMirrorMaterial + kGlassMaterial, kMirrorShape + kGlassShape, -1), "double");
  scene.settings.traceCaustics = false;  // the inner path tracer keeps every path
  scene.build();
  const std::unique_ptr<Integrator> pathOnly = makeIntegrator(scene.settings, Kernel::Wave);
  const Film twice = render(scene, DoubleCounting(*pathOnly), 11);
  const Film alone = render(scene, *makeIntegrator(scene.settings, Kernel::Wave), 12);
  const BlockZTestResult r = compare(twice, alone);
  EXPECT_FALSE(r.passes());
  EXPECT_GT(r.failures, r.tests / 10) << "caustics should be visible in many blocks";
}

// An emissive glTF mesh (a one-sided square of TriangleLights) in place of that quad light, so
// that all the floor's light is a caustic: the light tracer starts paths on its triangles
// (Light::sampleEmission), and the path tracer leaves it the caustics of those lights.
TEST(CausticEstimators, EmissiveMeshLightAgreesWithThePathTracerAlone) {
  const test::TempDir dir;
  test::GltfBuilder b;
  tinygltf::Material m;
  m.emissiveFactor = {1.0, 1.0, 1.0};
  tinygltf::Value::Object strength{{"emissiveStrength", tinygltf::Value(5.0)}};
  m.extensions["KHR_materials_emissive_strength"] = tinygltf::Value(strength);
  b.model().extensionsUsed.push_back("KHR_materials_emissive_strength");
  const std::vector<test::GltfBuilder::Vertex> v = {{{-0.5f, 1.2f, 0.3f}, {0, 1, 0}, {0, 0}, {1, 0, 0, 1}},
                                                    {{0.5f, 1.2f, 0.3f}, {0, 1, 0}, {1, 0}, {1, 0, 0, 1}},
                                                    {{0.5f, 1.2f, -0.7f}, {0, 1, 0}, {1, 1}, {1, 0, 0, 1}},
                                                    {{-0.5f, 1.2f, -0.7f}, {0, 1, 0}, {0, 1}, {1, 0, 0, 1}}};
  b.addMesh(v, {0, 1, 2, 0, 2, 3}, b.addMaterial(m));
  const std::string light = dir.file("light.gltf");
  ASSERT_TRUE(b.write(light));
  const std::string json = mirrorCeilingScene(R"({"type": "mesh", "file": ")" + light + R"("})");
  Scene scene = load(json, "mesh-light");
  scene.build();
  size_t traced = 0;
  for (const auto& l : scene.lights) traced += l->causticTraced ? 1 : 0;
  EXPECT_EQ(traced, 2u);  // the mesh's two triangles
  expectAgree(std::move(scene), "emissive mesh light");
}

// glTF glass (KHR_materials_transmission and _volume at roughness 0: a Dirac refraction, so the
// mesh is a caster; with a clearcoat and a sheen) and a glTF polished metal plate (metallic 1, roughness 0),
// both with a colour, under the quad light: the light tracer follows their Dirac lobes from the light, and
// the path tracer must agree.
TEST(CausticEstimators, GltfGlassAndPolishedMetalAgreeWithThePathTracerAlone) {
  const test::TempDir dir;
  test::GltfBuilder b;
  using V = tinygltf::Value;
  tinygltf::Material glass;
  glass.pbrMetallicRoughness.baseColorFactor = {1.0, 0.9, 0.8, 1.0};
  glass.pbrMetallicRoughness.metallicFactor = 0.0;
  glass.pbrMetallicRoughness.roughnessFactor = 0.0;
  glass.extensions["KHR_materials_transmission"] = V(V::Object{{"transmissionFactor", V(1.0)}});
  glass.extensions["KHR_materials_volume"] = V(V::Object{{"thicknessFactor", V(0.8)}});
  // A clearcoat and a sheen, whose weights depend on the direction outside: the two tracers meet
  // each refraction from opposite sides and must weigh it alike.
  glass.extensions["KHR_materials_clearcoat"] = V(V::Object{{"clearcoatFactor", V(1.0)}});
  glass.extensions["KHR_materials_sheen"] = V(
      V::Object{{"sheenColorFactor", V(V::Array{V(1.0), V(1.0), V(1.0)})}, {"sheenRoughnessFactor", V(0.5)}});
  tinygltf::Material metal;
  metal.pbrMetallicRoughness.baseColorFactor = {0.9, 0.8, 0.6, 1.0};
  metal.pbrMetallicRoughness.metallicFactor = 1.0;
  metal.pbrMetallicRoughness.roughnessFactor = 0.0;
  b.model().extensionsUsed = {"KHR_materials_transmission", "KHR_materials_volume",
                              "KHR_materials_clearcoat"};
  const float center[3] = {0.5f, 0.75f, -0.2f};
  b.addSphere(center, 0.4f, b.addMaterial(glass), 32, 64);
  const std::vector<test::GltfBuilder::Vertex> plate = {
      {{-1.2f, 0.0f, 0.8f}, {0.9778f, -0.2095f, 0}, {0, 0}, {0, 0, -1, 1}},
      {{-1.2f, 0.0f, -1.2f}, {0.9778f, -0.2095f, 0}, {1, 0}, {0, 0, -1, 1}},
      {{-0.9f, 1.4f, -1.2f}, {0.9778f, -0.2095f, 0}, {1, 1}, {0, 0, -1, 1}},
      {{-0.9f, 1.4f, 0.8f}, {0.9778f, -0.2095f, 0}, {0, 1}, {0, 0, -1, 1}}};
  b.addMesh(plate, {0, 1, 2, 0, 2, 3}, b.addMaterial(metal));
  const std::string file = dir.file("casters.gltf");
  ASSERT_TRUE(b.write(file));
  Scene scene = load(sceneJson("", R"(, {"type": "mesh", "file": ")" + file + R"("})", -1), "gltf-casters");
  scene.build();
  EXPECT_EQ(scene.causticTracer().casters().size(), 2u);
  expectAgree(std::move(scene), "glTF glass and polished metal");
}

// A spot light just above a mirror floor, pointing down at it, under a white diffuse ceiling: the
// ceiling gets no direct light, only the caustic of the spot's mirror image, R I / d'^2 at distance
// d' from it. No path tracer reaches that light; the light tracer must give it exactly. The pixel
// at the image centre sees the ceiling straight above the light, d' = 3 h: L = rho / pi R I / (3 h)^2.
// Most light paths land outside the camera's view, hence many of them per pixel.
TEST(CausticEstimators, SpotLightThroughAMirrorGivesItsMirrorImage) {
  const float intensity = 2.0f, rho = 0.8f, reflectance = 0.9f, h = 1.0f;
  const std::string json = R"({
    "image": {"width": 15, "height": 15},
    "camera": {"origin": [0, 1.0001, 0.02], "target": [0, 2, 0.02], "up": [0, 0, -1], "fov_y_deg": 60},
    "render": {"max_depth": -1, "rr_depth": 10, "caustic_paths_per_pixel": 64},
    "materials": {
      "white": {"type": "diffuse", "reflectance": [0.8, 0.8, 0.8]},
      "mirror": {"type": "mirror", "reflectance": [0.9, 0.9, 0.9]}
    },
    "lights": [{"type": "spot", "position": [0, 1, 0], "direction": [0, -1, 0], "intensity": [2, 2, 2],
                "inner_deg": 40, "outer_deg": 45}],
    "shapes": [
      {"type": "quad", "material": "mirror", "vertices": [[-4, 0, 4], [4, 0, 4], [4, 0, -4], [-4, 0, -4]]},
      {"type": "quad", "material": "white", "vertices": [[-4, 2, -4], [4, 2, -4], [4, 2, 4], [-4, 2, 4]]}
    ]
  })";
  Scene scene = load(json, "spot-mirror");
  scene.settings.traceCaustics = true;
  scene.build();
  ASSERT_TRUE(scene.causticTracer().enabled());
  // One bounce: the ceiling's light that reaches the mirror again and comes back is the path
  // tracer's, and depth 3 leaves it out.
  scene.settings.maxDepth = 3;
  const Film film = render(scene, *makeIntegrator(scene.settings, Kernel::Wave), 5);
  const Image mean = film.mean(), variance = film.varianceOfMean();
  // The 3 x 3 pixels at the centre, each against the closed form at the point its centre sees.
  double got = 0.0, expected = 0.0, var = 0.0;
  for (int y = 6; y <= 8; ++y)
    for (int x = 6; x <= 8; ++x) {
      const Ray ray = scene.camera().generateRay(float(x) + 0.5f, float(y) + 0.5f);
      const Vec3 q = ray.origin + ((2.0f * h - ray.origin.y) / ray.dir.y) * ray.dir;
      const Vec3 r = q - Vec3(0.0f, -h, 0.0f);  // from the mirror image of the light
      const double d2 = double(glm::dot(r, r)), cosine = double(r.y) / std::sqrt(d2);
      expected += double(rho) / double(kPi) * double(reflectance * intensity) * cosine / d2;
      got += mean.at(x, y).x;
      var += variance.at(x, y).x;
    }
  const double z = (got - expected) / std::sqrt(var);
  EXPECT_LT(std::abs(z), 4.0) << got / 9.0 << " against " << expected / 9.0 << " (z " << z << ")";
  // Without the light tracer the ceiling stays black.
  scene.settings.traceCaustics = false;
  const Film path = render(scene, *makeIntegrator(scene.settings, Kernel::Wave), 6);
  EXPECT_EQ(path.mean().at(7, 7), Color(0.0f));
}

}  // namespace
}  // namespace ember
