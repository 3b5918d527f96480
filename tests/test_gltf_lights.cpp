// KHR_lights_punctual in the documented units: a glTF written by the test itself (tinygltf's
// writer) holds a grey plane and one light; a narrow camera looks straight down at a point of the
// plane, and the rendered radiance must equal the analytic direct lighting, with intensities
// converted photometric -> radiometric by 1/683 (docs/gltf.md).
#include "cli_runner.h"
#include "io/scene_loader.h"
#include "renderer/path_integrator.h"
#include "renderer/render.h"

#include "packet/wave_integrator.h"

#include <gtest/gtest.h>
#include <tiny_gltf.h>

#include <cstring>

namespace ember {
namespace {

using test::TempDir;

constexpr float kAlbedo = 0.5f;

// A 10 x 10 grey quad at y = 0 facing +y, and one KHR_lights_punctual light on its own node.
std::string writeGltf(const TempDir& dir, const tinygltf::Light& light,
                      const std::vector<double>& translation, const std::vector<double>& rotation) {
  tinygltf::Model m;
  const float pos[] = {-5, 0, 5, 5, 0, 5, 5, 0, -5, -5, 0, -5};
  const uint32_t idx[] = {0, 1, 2, 0, 2, 3};
  tinygltf::Buffer buffer;
  buffer.data.resize(sizeof pos + sizeof idx);
  std::memcpy(buffer.data.data(), pos, sizeof pos);
  std::memcpy(buffer.data.data() + sizeof pos, idx, sizeof idx);
  m.buffers.push_back(buffer);
  tinygltf::BufferView vp, vi;
  vp.buffer = vi.buffer = 0;
  vp.byteLength = sizeof pos;
  vi.byteOffset = sizeof pos;
  vi.byteLength = sizeof idx;
  m.bufferViews = {vp, vi};
  tinygltf::Accessor ap, ai;
  ap.bufferView = 0;
  ap.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
  ap.type = TINYGLTF_TYPE_VEC3;
  ap.count = 4;
  ap.minValues = {-5, 0, -5};
  ap.maxValues = {5, 0, 5};
  ai.bufferView = 1;
  ai.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
  ai.type = TINYGLTF_TYPE_SCALAR;
  ai.count = 6;
  m.accessors = {ap, ai};
  tinygltf::Material mat;
  mat.name = "plane";  // replaced by an Ember Lambertian of albedo kAlbedo in the scene
  mat.pbrMetallicRoughness.baseColorFactor = {kAlbedo, kAlbedo, kAlbedo, 1.0};
  m.materials.push_back(mat);
  tinygltf::Primitive prim;
  prim.attributes["POSITION"] = 0;
  prim.indices = 1;
  prim.material = 0;
  prim.mode = TINYGLTF_MODE_TRIANGLES;
  tinygltf::Mesh mesh;
  mesh.primitives.push_back(prim);
  m.meshes.push_back(mesh);
  m.lights.push_back(light);
  tinygltf::Node plane, lamp;
  plane.mesh = 0;
  lamp.translation = translation;
  lamp.rotation = rotation;
  lamp.extensions["KHR_lights_punctual"] =
      tinygltf::Value(tinygltf::Value::Object{{"light", tinygltf::Value(0)}});
  m.nodes = {plane, lamp};
  tinygltf::Scene scene;
  scene.nodes = {0, 1};
  m.scenes.push_back(scene);
  m.defaultScene = 0;
  m.extensionsUsed = {"KHR_lights_punctual"};
  m.asset.version = "2.0";
  const std::string path = dir.file("lit.gltf");
  tinygltf::TinyGLTF writer;
  EXPECT_TRUE(writer.WriteGltfSceneToFile(&m, path, true, true, true, false));
  return path;
}

// Radiance seen straight down at `target` on the plane (direct light only), by the reference
// integrator or, with `lanes`, by the kernel `ember render` uses by default.
float renderAt(const TempDir& dir, const std::string& gltf, const Vec3& target, bool lanes = false) {
  const std::string json = R"({"image": {"width": 1, "height": 1},
    "camera": {"origin": [)" +
                           std::to_string(target.x) + ", 1, " + std::to_string(target.z) +
                           R"(], "target": [)" + std::to_string(target.x) + ", 0, " +
                           std::to_string(target.z) + R"(], "up": [0, 0, -1], "fov_y_deg": 0.05},
    "render": {"max_depth": 2, "sampler": "independent"},
    "materials": {"grey": {"type": "diffuse", "reflectance": )" +
                           std::to_string(kAlbedo) + R"(}},
    "shapes": [{"type": "mesh", "file": ")" +
                           gltf + R"(", "materials": {"plane": "grey"}}]})";
  Scene scene = loadScene(dir.write("s.json", json));
  scene.build();
  const PathIntegrator reference(2, 5);
  const std::unique_ptr<Integrator> kernel = makeIntegrator(scene.settings, Kernel::Wave);
  Film film(1, 1);
  RenderOptions options;
  options.spp = 16;
  render(scene, lanes ? *kernel : static_cast<const Integrator&>(reference), options, film);
  return film.mean().at(0, 0).x;
}

TEST(GltfLights, PointLightInCandelaMatchesTheInverseSquareLaw) {
  TempDir dir;
  tinygltf::Light light;
  light.type = "point";
  light.intensity = 683.0 * 2.0;  // 2 W/sr
  light.color = {1.0, 1.0, 1.0};
  const std::string gltf = writeGltf(dir, light, {0.5, 2.0, -0.3}, {});
  const Vec3 p(0.0f), l(0.5f, 2.0f, -0.3f);
  const float r2 = glm::dot(l - p, l - p);
  const float expected = kAlbedo / kPi * 2.0f * (l.y / std::sqrt(r2)) / r2;
  EXPECT_NEAR(renderAt(dir, gltf, p), expected, 2e-4f * expected);
}

// KHR_lights_punctual's range: the inverse-square law times the recommended window
// max(min(1 - (d / range)^4, 1), 0), exactly nothing at and past the range; in the reference
// integrator and in the default kernel (which samples ranged point lights one by one).
TEST(GltfLights, PointLightRangeFollowsTheRecommendedWindow) {
  TempDir dir;
  tinygltf::Light light;
  light.type = "point";
  light.intensity = 683.0 * 2.0;  // 2 W/sr
  light.range = 3.0;
  const std::string gltf = writeGltf(dir, light, {0.5, 2.0, -0.3}, {});
  const Vec3 l(0.5f, 2.0f, -0.3f);
  for (float x : {0.0f, 1.5f, 2.4f, 3.0f}) {
    const Vec3 p(x, 0.0f, 0.0f);
    const float r2 = glm::dot(l - p, l - p), d = std::sqrt(r2);
    const float window = std::clamp(1.0f - std::pow(d / 3.0f, 4.0f), 0.0f, 1.0f);
    const float expected = kAlbedo / kPi * 2.0f * (l.y / d) / r2 * window;
    for (const bool lanes : {false, true})
      EXPECT_NEAR(renderAt(dir, gltf, p, lanes), expected, 2e-4f * expected + 1e-7f)
          << "x = " << x << (lanes ? ", lanes kernel" : ", reference");
  }
}

TEST(GltfLights, SpotLightFollowsTheSpecFalloff) {
  TempDir dir;
  tinygltf::Light light;
  light.type = "spot";
  light.intensity = 683.0;  // 1 W/sr on the axis
  light.spot.innerConeAngle = 0.2;
  light.spot.outerConeAngle = 0.6;
  // The node's -z points straight down: rotate -90 degrees about x (quaternion x, y, z, w).
  const double h = std::sqrt(0.5);
  const std::string gltf = writeGltf(dir, light, {0.0, 2.0, 0.0}, {-h, 0.0, 0.0, h});
  for (float x : {0.0f, 0.5f, 0.8f, 1.5f}) {
    const Vec3 p(x, 0.0f, 0.0f), l(0.0f, 2.0f, 0.0f);
    const float r2 = glm::dot(l - p, l - p);
    const float cosAxis = 2.0f / std::sqrt(r2);
    const float t = std::clamp((cosAxis - std::cos(0.6f)) / (std::cos(0.2f) - std::cos(0.6f)), 0.0f, 1.0f);
    const float expected = kAlbedo / kPi * t * t * cosAxis / r2;
    EXPECT_NEAR(renderAt(dir, gltf, p), expected, 2e-3f * expected + 1e-6f) << "x = " << x;
  }
}

TEST(GltfLights, DirectionalLightInLuxGivesItsIrradiance) {
  TempDir dir;
  tinygltf::Light light;
  light.type = "directional";
  light.intensity = 683.0 * 3.0;  // 3 W/m^2
  // Rotate -60 degrees about x: the light travels down and towards -z... at 30 degrees from vertical.
  const double a = -glm::radians(60.0) / 2.0;
  const std::string gltf = writeGltf(dir, light, {}, {std::sin(a), 0.0, 0.0, std::cos(a)});
  const float expected = kAlbedo / kPi * 3.0f * std::cos(glm::radians(30.0f));
  EXPECT_NEAR(renderAt(dir, gltf, Vec3(0.0f)), expected, 1e-4f * expected);
}

TEST(GltfLights, AFileWithLightsGetsNoDefaultEnvironment) {
  TempDir dir;
  tinygltf::Light light;
  light.type = "point";
  const std::string gltf = writeGltf(dir, light, {0.0, 1.0, 0.0}, {});
  const Scene scene = loadScene(gltf);
  EXPECT_EQ(scene.lights.size(), 1u);
  EXPECT_EQ(scene.background, Color(0.0f));
}

}  // namespace
}  // namespace ember
