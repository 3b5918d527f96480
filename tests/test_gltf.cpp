// glTF loading: the Khronos sample models in ../shared/assets/gltf load with the right geometry and
// render non-black images; the deliberately broken files of Debian's assimp-testmodels package, a
// truncated GLB, a missing .bin and a missing file fail cleanly: an InputError naming the file and
// the problem, a non-zero exit code from the command line, and no output file.
#include "cli_runner.h"
#include "gltf_builder.h"
#include "io/gltf_loader.h"
#include "io/input_error.h"
#include "io/scene_loader.h"
#include "test_fixtures.h"
#include "test_paths.h"

#include <gtest/gtest.h>

#include <fstream>

namespace ember {
namespace {

namespace fs = std::filesystem;
using test::TempDir;

std::string sharedModel(const std::string& relative) {
  const std::string dir = test::sharedGltfDir();
  if (!fs::is_directory(dir)) return {};
  return dir + "/" + relative;
}

#define REQUIRE_SHARED_MODEL(var, rel)                                          \
  const std::string var = sharedModel(rel);                                     \
  if (var.empty())                                                              \
    GTEST_SKIP() << "shared glTF models not found at " << test::sharedGltfDir() \
                 << " (set EMBER_SHARED_GLTF); they are not part of the repository";

#define REQUIRE_ASSIMP_MODELS()                 \
  if (!fs::is_directory(test::assimpGltfDir())) \
  GTEST_SKIP() << "Debian package assimp-testmodels is not installed (" << test::assimpGltfDir() << ")"

double meanLuminance(const std::string& path, int width, int height, int spp) {
  Scene scene = loadScene(path);
  scene.settings.width = width;
  scene.settings.height = height;
  scene.build();
  const Image img = test::renderFilm(scene, spp, 0).mean();
  double sum = 0.0;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) sum += luminance(img.at(x, y));
  return sum / (width * height);
}

struct ModelFacts {
  const char* file;
  size_t triangles;
  Vec3 lower, upper;
  bool hasCamera;
};

TEST(Gltf, SharedModelsLoadWithTheirGeometry) {
  REQUIRE_SHARED_MODEL(dir, "");
  const ModelFacts models[] = {
      {"Box/Box.gltf", 12, Vec3(-0.5f), Vec3(0.5f), false},
      {"Duck/Duck.glb", 4212, Vec3(-0.693f, 0.0993f, -0.6133f), Vec3(0.9618f, 1.6397f, 0.5393f), true},
      // One mesh instanced by two nodes, the second translated by +1 in x.
      {"SimpleMeshes/SimpleMeshes.gltf", 2, Vec3(0.0f), Vec3(2.0f, 1.0f, 0.0f), false},
      {"TriangleWithoutIndices/TriangleWithoutIndices.gltf", 1, Vec3(0.0f), Vec3(1.0f, 1.0f, 0.0f), false},
  };
  for (const ModelFacts& m : models) {
    Scene scene;
    const GltfImport imported = importGltf(dir + m.file, scene);
    EXPECT_EQ(imported.triangles, m.triangles) << m.file;
    EXPECT_EQ(imported.camera.has_value(), m.hasCamera) << m.file;
    Bounds b;
    for (const auto& mesh : scene.meshes) b.extend(mesh.worldBounds());
    for (int a = 0; a < 3; ++a) {
      EXPECT_NEAR(b.lower[a], m.lower[a], 1e-3) << m.file << " axis " << a;
      EXPECT_NEAR(b.upper[a], m.upper[a], 1e-3) << m.file << " axis " << a;
    }
  }
}

TEST(Gltf, SharedModelsRenderNonBlack) {
  REQUIRE_SHARED_MODEL(dir, "");
  for (const char* file : {"Box/Box.gltf", "Duck/Duck.glb", "SimpleMeshes/SimpleMeshes.gltf",
                           "TriangleWithoutIndices/TriangleWithoutIndices.gltf"}) {
    const double mean = meanLuminance(dir + file, 48, 36, 4);
    EXPECT_GT(mean, 0.01) << file;
  }
}

TEST(Gltf, TriangleWithoutNormalsIsShadedFlat) {
  REQUIRE_SHARED_MODEL(path, "TriangleWithoutIndices/TriangleWithoutIndices.gltf");
  Scene scene;
  importGltf(path, scene);
  ASSERT_EQ(scene.meshes.size(), 1u);
  EXPECT_TRUE(scene.meshes[0].mesh->normals.empty());
  const auto s = scene.meshes[0].mesh->surfaceAt(0, 0.25f, 0.25f);
  EXPECT_NEAR(std::abs(s.ng.z), 1.0f, 1e-6f);
  EXPECT_EQ(s.ns, s.ng);
}

TEST(Gltf, DuckTextureIsDecodedFromSrgb) {
  REQUIRE_SHARED_MODEL(path, "Duck/Duck.glb");
  Scene scene;
  importGltf(path, scene);
  ASSERT_FALSE(scene.meshes.empty());
  EXPECT_FALSE(scene.meshes[0].mesh->uvs.empty());
}

TEST(Gltf, MeshEntryInJsonSceneAppliesTransform) {
  REQUIRE_ASSIMP_MODELS();
  TempDir dir;
  const std::string model = test::assimpGltfDir() + "/BoxTextured-glTF-Embedded/BoxTextured.gltf";
  const std::string json = R"({"camera": {"origin": [0, 0, 6], "target": [0, 0, 0]},
    "materials": {"grey": {"type": "diffuse", "reflectance": 0.5}},
    "shapes": [{"type": "mesh", "file": ")" +
                           model + R"(", "material": "grey",
                "transform": {"translate": [10, 0, 0], "scale": 2}}]})";
  Scene scene = loadScene(dir.write("s.json", json));
  ASSERT_FALSE(scene.meshes.empty());
  Bounds b;
  for (const auto& m : scene.meshes) {
    b.extend(m.worldBounds());
    EXPECT_EQ(m.material, scene.materials[0].get());  // the override
  }
  EXPECT_NEAR(b.lower.x, 9.0f, 1e-4f);
  EXPECT_NEAR(b.upper.x, 11.0f, 1e-4f);
  EXPECT_NEAR(b.upper.y - b.lower.y, 2.0f, 1e-4f);
}

struct BrokenFile {
  std::string path;
  const char* expected;
};

void expectCleanFailure(const BrokenFile& f) {
  try {
    Scene scene;
    importGltf(f.path, scene);
    ADD_FAILURE() << f.path << ": loaded without error";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.rfind(f.path, 0), 0u) << "message should start with the file: " << msg;
    EXPECT_NE(msg.find(f.expected), std::string::npos) << f.path << ": got \"" << msg << "\"";
  }
  TempDir dir;
  const std::string out = dir.file("out.exr");
  const auto r =
      test::runEmber("render '" + f.path + "' -o '" + out + "' --png '" + dir.file("o.png") + "' -q --spp 1");
  EXPECT_NE(r.exitCode, 0) << f.path;
  EXPECT_LT(r.exitCode, 128) << f.path << " crashed: " << r.output;
  EXPECT_NE(r.output.find(f.expected), std::string::npos) << r.output;
  EXPECT_TRUE(fs::is_empty(dir.path)) << f.path << " left an output file";
}

TEST(Gltf, BrokenAssimpFilesFailCleanly) {
  REQUIRE_ASSIMP_MODELS();
  const std::string d = test::assimpGltfDir() + "/";
  const BrokenFile files[] = {
      {d + "IndexOutOfRange/IndexOutOfRange.gltf", "indices: index 255 out of range (24 vertices)"},
      {d + "IndexOutOfRange/AllIndicesOutOfRange.gltf", "out of range"},
      {d + "MissingBin/BoxTextured.gltf", "BoxTextured0.bin"},
      {d + "RecursiveNodes/RecursiveNodes.gltf", "cycle"},
      {d + "BoxWithInfinites-glTF-Binary/BoxWithInfinites.glb", "POSITION: contains NaN or infinite values"},
      {d + "SchemaFailures/sceneWrongType.gltf", "cannot load glTF"},
      {d + "TestNoRootNode/SceneWithoutNodes.gltf", "contains nothing to render"},
      {d + "wrongTypes/badArray.gltf", "meshes[0].primitives: must be an array of primitives, not object"},
  };
  for (const BrokenFile& f : files) {
    if (f.expected == std::string("contains nothing to render")) {
      // Valid but empty: the importer accepts it; rendering it directly is refused.
      const auto r = test::runEmber("render '" + f.path + "' -o /tmp/ember_never.exr -q");
      EXPECT_NE(r.exitCode, 0);
      EXPECT_NE(r.output.find(f.expected), std::string::npos) << r.output;
      EXPECT_FALSE(fs::exists("/tmp/ember_never.exr"));
      continue;
    }
    expectCleanFailure(f);
  }
}

// glTF 1.0 (dictionaries keyed by id, another material model) is not read as an empty 2.0 file:
// the error names the version, with or without the file's asset object, and so does a file that
// needs a reader newer than 2.0. A 2.0 file declaring minVersion 2.0 loads.
TEST(Gltf, OtherGltfVersionsAreRefusedByName) {
  TempDir files;
  const auto write = [&](const std::string& name, const std::string& json) {
    std::ofstream(files.file(name)) << json;
    return files.file(name);
  };
  const std::string v1 = R"({"asset": {"version": "1.0"}, "scene": "s", "scenes": {"s": {"nodes": []}}})";
  expectCleanFailure({write("v1.gltf", v1), "asset.version: the file is glTF 1.0; Ember reads glTF 2.0"});
  expectCleanFailure({write("v1-no-asset.gltf", R"({"accessors": {"a": {"count": 3}}, "meshes": {}})"),
                      "accessors: an object keyed by id, as in glTF 1.0"});
  expectCleanFailure({write("v3.gltf", R"({"asset": {"version": "3.0"}, "meshes": []})"),
                      "asset.version: the file is glTF 3.0"});
  expectCleanFailure({write("min.gltf", R"({"asset": {"version": "2.1", "minVersion": "2.1"}})"),
                      "asset.minVersion: the file needs a glTF 2.1 reader"});
  expectCleanFailure(
      {write("bad.gltf", R"({"asset": {"version": "two"}})"), "asset.version: 'two' is not a glTF version"});

  test::GltfBuilder b;
  tinygltf::Material m;
  m.pbrMetallicRoughness.baseColorFactor = {0.5, 0.5, 0.5, 1.0};
  b.addQuad(1.0f, b.addMaterial(m));
  b.model().asset.minVersion = "2.0";
  ASSERT_TRUE(b.write(files.file("min20.gltf")));
  Scene scene;
  importGltf(files.file("min20.gltf"), scene);
  EXPECT_EQ(scene.meshes.size(), 1u);
}

// The glTF 1.0 files of assimp-testmodels (models/glTF): each is refused as glTF 1.0.
TEST(Gltf, AssimpGltf1FilesAreRefusedAsGltf1) {
  const fs::path root = fs::path(test::assimpGltfDir()).parent_path() / "glTF";
  if (!fs::is_directory(root)) GTEST_SKIP() << root << " not found (Debian package assimp-testmodels)";
  int refused = 0;
  for (const auto& entry : fs::recursive_directory_iterator(root)) {
    const std::string ext = entry.path().extension().string();
    if (ext != ".gltf" && ext != ".glb") continue;
    expectCleanFailure({entry.path().string(), "glTF 1.0"});
    ++refused;
  }
  EXPECT_GE(refused, 6);  // Debian 12's assimp-testmodels 5.2.5 has 7
}

// Files of assimp-testmodels that are broken on purpose, or need an extension Ember cannot do
// without (KHR_technique_webgl): they must fail with an InputError.
bool expectedToFail(const std::string& relative) {
  for (const char* broken : {"IndexOutOfRange/", "MissingBin/", "RecursiveNodes/", "BoxWithInfinites",
                             "SchemaFailures/", "TestNoRootNode/", "wrongTypes/badArray", "techniqueWebGL/"})
    if (relative.find(broken) != std::string::npos) return true;
  return false;
}

TEST(Gltf, EveryValidAssimpFileLoadsAndRendersAndTheOthersFailCleanly) {
  REQUIRE_ASSIMP_MODELS();
  const std::string root = test::assimpGltfDir();
  int rendered = 0, refused = 0;
  for (const auto& entry : fs::recursive_directory_iterator(root)) {
    const std::string ext = entry.path().extension().string();
    if (ext != ".gltf" && ext != ".glb") continue;
    const std::string relative = fs::relative(entry.path(), root).string();
    try {
      const double mean = meanLuminance(entry.path().string(), 12, 9, 1);
      EXPECT_FALSE(expectedToFail(relative)) << relative << " should have been refused";
      EXPECT_TRUE(std::isfinite(mean)) << relative;
      ++rendered;
    } catch (const InputError& e) {
      EXPECT_TRUE(expectedToFail(relative)) << relative << ": " << e.what();
      ++refused;
    }
  }
  // Debian 12 assimp-testmodels 5.2.5: 46 glTF files; 36 render (the Draco engine too) and 10 are refused.
  EXPECT_GE(rendered, 36);
  EXPECT_GE(refused, 10);
  RecordProperty("rendered", rendered);
}

TEST(Gltf, PointsAndLinesRenderAsSpheresAndCylinders) {
  REQUIRE_ASSIMP_MODELS();
  const std::string dir = test::assimpGltfDir() + "/glTF-Asset-Generator/Mesh_PrimitiveMode/";
  // Mode 0 = POINTS, 1 = LINES, 2 = LINE_LOOP, 3 = LINE_STRIP (the Asset Generator's README).
  const std::pair<const char*, const char*> cases[] = {{"Mesh_PrimitiveMode_00.gltf", "sphere"},
                                                       {"Mesh_PrimitiveMode_01.gltf", "cylinder"},
                                                       {"Mesh_PrimitiveMode_02.gltf", "cylinder"},
                                                       {"Mesh_PrimitiveMode_03.gltf", "cylinder"}};
  for (const auto& [file, type] : cases) {
    const Scene scene = loadScene(dir + file);
    ASSERT_FALSE(scene.shapes.empty()) << file;
    for (const auto& s : scene.shapes) EXPECT_EQ(s.shape->typeName(), std::string_view(type)) << file;
    EXPECT_GT(meanLuminance(dir + file, 32, 24, 4), 0.0) << file;
  }
}

TEST(Gltf, TruncatedGlbFailsCleanly) {
  REQUIRE_ASSIMP_MODELS();
  std::ifstream in(test::assimpGltfDir() + "/BoxTextured-glTF-Binary/BoxTextured.glb", std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), {});
  ASSERT_GT(bytes.size(), 1000u);
  TempDir dir;
  for (size_t keep : {size_t(0), size_t(11), size_t(20), bytes.size() / 2, bytes.size() - 1}) {
    const std::string path = dir.write("cut" + std::to_string(keep) + ".glb", bytes.substr(0, keep));
    expectCleanFailure({path, "cannot load glTF"});
    fs::remove(path);
  }
}

TEST(Gltf, MissingBinFailsCleanly) {
  REQUIRE_ASSIMP_MODELS();
  TempDir src;  // the .gltf and its texture, without the .bin it references
  fs::copy_file(test::assimpGltfDir() + "/BoxTextured-glTF/BoxTextured.gltf", src.file("BoxTextured.gltf"));
  fs::copy_file(test::assimpGltfDir() + "/BoxTextured-glTF/CesiumLogoFlat.png",
                src.file("CesiumLogoFlat.png"));
  expectCleanFailure({src.file("BoxTextured.gltf"), "BoxTextured0.bin"});
}

TEST(Gltf, MissingFileFailsCleanly) {
  expectCleanFailure({"/nonexistent/model.glb", "no such file"});
}

}  // namespace
}  // namespace ember
