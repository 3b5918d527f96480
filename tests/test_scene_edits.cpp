// Edits of a built scene (Scene::update, replaceShape, replaceMaterial, setMeshTransforms; the
// Python module's Scene.set_*) against a scene loaded with the edit already made and built from
// scratch: the same image, bit for bit, and the BVHs kept wherever the edit allows.
#include "io/json_reader.h"
#include "io/scene_loader.h"
#include "packet/wave_integrator.h"
#include "renderer/render.h"

#include <gtest/gtest.h>
#include <glm/gtc/matrix_transform.hpp>

namespace ember {
namespace {

const std::string kScenes = std::string(EMBER_SOURCE_DIR) + "/scenes/";

nlohmann::json document(const std::string& name) {
  nlohmann::json doc = JsonNode::parseFile(kScenes + name);
  doc["image"] = {{"width", 40}, {"height", 32}};
  return doc;
}

Scene built(const nlohmann::json& doc) {
  Scene scene = loadJsonScene(doc, kScenes + "<test>");
  scene.build();
  return scene;
}

std::vector<float> image(const Scene& scene, Kernel kernel = Kernel::Wave) {
  RenderOptions options;
  options.spp = 4;
  options.seed = 5;
  options.threads = 2;
  options.sampler = scene.settings.sampler;
  Film film(scene.settings.width, scene.settings.height);
  render(scene, *makeIntegrator(scene.settings, kernel), options, film);
  return film.mean().rgb;
}

// The edited scene renders as the scene loaded with the edit, with both kernels.
void expectSameAsLoaded(const Scene& edited, const nlohmann::json& editedDoc) {
  const Scene fresh = built(editedDoc);
  EXPECT_EQ(image(edited), image(fresh));
  EXPECT_EQ(image(edited, Kernel::Scalar), image(fresh, Kernel::Scalar));
}

TEST(SceneEdits, CameraMovedByUpdateKeepsTheBvh) {
  nlohmann::json doc = document("cornell-area.json");
  Scene scene = built(doc);
  const std::vector<float> before = image(scene);
  const EmbreeAccel* accel = &scene.accel();
  doc["camera"]["origin"] = {0.4, 1.2, 3.0};
  doc["camera"]["fov_y_deg"] = 30;
  scene.cameraParams = JsonEntryReader(scene, "test").camera(doc["camera"]);
  scene.update();
  EXPECT_EQ(&scene.accel(), accel);
  EXPECT_NE(image(scene), before);
  expectSameAsLoaded(scene, doc);
}

TEST(SceneEdits, MaterialReplacedEverywhereItIsUsed) {
  nlohmann::json doc = document("cornell-area.json");
  Scene scene = built(doc);
  const EmbreeAccel* accel = &scene.accel();
  doc["materials"]["white"] = {{"type", "diffuse"}, {"reflectance", {0.3, 0.6, 0.9}}};
  doc["materials"]["glass"]["ior_inside"] = 1.9;
  const JsonEntryReader reader(scene, "test");
  for (const char* name : {"white", "glass"}) {
    const size_t i = size_t(std::find(scene.materialNames.begin(), scene.materialNames.end(), name) -
                            scene.materialNames.begin());
    scene.replaceMaterial(i, reader.material(doc["materials"][name], name));
  }
  EXPECT_EQ(&scene.accel(), accel);
  expectSameAsLoaded(scene, doc);
}

TEST(SceneEdits, ShapeMovedAndRetyped) {
  nlohmann::json doc = document("cornell-area.json");
  Scene scene = built(doc);
  const JsonEntryReader reader(scene, "test");
  doc["shapes"][7]["center"] = {0.2, 0.5, 0.1};
  doc["shapes"][7]["radius"] = 0.45;
  scene.replaceShape(7, std::move(reader.shape(doc["shapes"][7], "shapes[7]").shape));
  expectSameAsLoaded(scene, doc);
  // A sphere turned box keeps its mask bit's kind (both convex): still no full build.
  doc["shapes"][6] = {{"type", "box"},
                      {"center", {-0.4, 0.3, -0.3}},
                      {"size", {0.5, 0.6, 0.4}},
                      {"material", "mirror"},
                      {"id", "mirror_box"}};
  const EmbreeAccel* accel = &scene.accel();
  scene.replaceShape(6, std::move(reader.shape(doc["shapes"][6], "shapes[6]").shape));
  EXPECT_EQ(&scene.accel(), accel);
  expectSameAsLoaded(scene, doc);
}

TEST(SceneEdits, EmissionChangedAndSwitchedOff) {
  nlohmann::json doc = document("cornell-area.json");
  Scene scene = built(doc);
  const EmbreeAccel* accel = &scene.accel();
  doc["shapes"][5]["emission"] = {3.0, 6.0, 9.0};
  scene.shapes[5].emission = Color(3.0f, 6.0f, 9.0f);
  scene.update();
  EXPECT_EQ(&scene.accel(), accel);  // a flat emitter stays one: its mask bit stays
  expectSameAsLoaded(scene, doc);
  // Off: the flat emitters' mask bits come first, so they all move: a full build.
  doc["shapes"][5].erase("emission");
  doc["shapes"][5]["material"] = "white";
  scene.shapes[5].emission = Color(0.0f);
  scene.shapes[5].material =
      scene
          .materials[size_t(std::find(scene.materialNames.begin(), scene.materialNames.end(), "white") -
                            scene.materialNames.begin())]
          .get();
  scene.update();
  EXPECT_NE(&scene.accel(), accel);
  expectSameAsLoaded(scene, doc);
}

TEST(SceneEdits, PointLightReplaced) {
  nlohmann::json doc = document("cornell-point.json");
  Scene scene = built(doc);
  doc["lights"][0]["intensity"] = {2.0, 4.0, 8.0};
  doc["lights"][0]["position"] = {0.2, 1.5, 0.1};
  scene.lights[0] = JsonEntryReader(scene, "test").light(doc["lights"][0], "lights[0]");
  scene.update();
  expectSameAsLoaded(scene, doc);
}

TEST(SceneEdits, InstancesPlacedAnewMatchAFreshBuildWithThosePlacements) {
  const nlohmann::json doc = document("gltf-mixed.json");
  JsonSceneIndex index;
  Scene scene = loadJsonScene(doc, kScenes + "<test>", &index);
  scene.build();
  const JsonSceneIndex::Range grid = index.shapes[1];  // sphere-grid.gltf: one mesh, many nodes
  ASSERT_TRUE(grid.mesh);
  ASSERT_GT(grid.count, 1u);
  std::vector<std::pair<size_t, Mat4>> placements;
  for (size_t i = grid.first; i < grid.first + grid.count; ++i) {
    ASSERT_TRUE(scene.meshes[i].toWorld);
    placements.push_back({i, glm::translate(Mat4(1.0f), Vec3(0.1f, 0.3f, 0.0f)) * *scene.meshes[i].toWorld});
  }
  const EmbreeAccel* accel = &scene.accel();
  const std::vector<float> before = image(scene);
  scene.setMeshTransforms(placements);
  EXPECT_EQ(&scene.accel(), accel);
  EXPECT_NE(image(scene), before);
  Scene fresh = loadJsonScene(doc, kScenes + "<test>");
  for (const auto& [i, toWorld] : placements) fresh.meshes[i].toWorld = toWorld;
  fresh.build();
  EXPECT_EQ(image(scene), image(fresh));
}

TEST(SceneEdits, EditedEntriesAreCheckedLikeLoadedOnes) {
  const nlohmann::json doc = document("cornell-area.json");
  Scene scene = built(doc);
  const JsonEntryReader reader(scene, "edited.json");
  nlohmann::json glass = doc["materials"]["glass"];
  glass["ior_inside"] = -2;
  EXPECT_THROW(
      {
        try {
          reader.material(glass, "glass");
        } catch (const InputError& e) {
          EXPECT_STREQ(e.what(), "edited.json: materials.glass.ior_inside: expected a number > 0");
          throw;
        }
      },
      InputError);
  nlohmann::json sphere = doc["shapes"][7];
  sphere["material"] = "gold";
  EXPECT_THROW(reader.shape(sphere, "shapes[7]"), InputError);
  EXPECT_THROW(reader.shape({{"type", "mesh"}, {"file", "x.gltf"}}, "shapes[0]"), InputError);
}

}  // namespace
}  // namespace ember
