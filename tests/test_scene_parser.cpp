// Bad scene input must give an InputError naming the file and the JSON path, and the command line
// must exit non-zero without writing any output.
#include "cli_runner.h"
#include "io/input_error.h"
#include "io/scene_loader.h"
#include "test_paths.h"

#include <gtest/gtest.h>

namespace ember {
namespace {

using test::TempDir;

const char* kValidScene = R"({
  "image": {"width": 8, "height": 8},
  "camera": {"origin": [0, 0, 5], "target": [0, 0, 0], "fov_y_deg": 40},
  "render": {"spp": 2},
  "materials": {"white": {"type": "diffuse", "reflectance": [0.5, 0.5, 0.5]}},
  "shapes": [
    {"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "white"},
    {"type": "quad", "vertices": [[-1, 2, -1], [1, 2, -1], [1, 2, 1], [-1, 2, 1]], "emission": [1, 1, 1]},
    {"type": "disc", "center": [0, -1, 0], "normal": [0, 1, 0], "radius": 2, "material": "white"},
    {"type": "sphere", "center": [2, 0, 0], "radius": 0.5, "material": "white"}
  ],
  "lights": [{"type": "point", "position": [0, 3, 0], "intensity": [1, 1, 1]}]
})";

// Replaces the first occurrence of `from` in the valid scene by `to`.
std::string variant(const std::string& from, const std::string& to) {
  std::string s = kValidScene;
  const size_t at = s.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return s.replace(at, from.size(), to);
}

std::string loadError(const std::string& path) {
  try {
    loadScene(path);
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(SceneParser, ValidSceneLoads) {
  TempDir dir;
  const Scene scene = loadScene(dir.write("ok.json", kValidScene));
  EXPECT_EQ(scene.shapes.size(), 4u);
  EXPECT_EQ(scene.lights.size(), 1u);
  EXPECT_EQ(scene.settings.spp, 2);
}

struct BadCase {
  const char* name;
  std::string json;
  const char* expected;  // must appear in the message, after "<file>: "
};

TEST(SceneParser, BadInputNamesFileAndPath) {
  const BadCase cases[] = {
      {"negative radius", variant("\"radius\": 0.5", "\"radius\": -0.5"),
       "shapes[3].radius: expected a number > 0"},
      {"radius as string", variant("\"radius\": 0.5", "\"radius\": \"big\""),
       "shapes[3].radius: expected a number > 0"},
      {"unknown shape key", variant("\"radius\": 0.5", "\"radius\": 0.5, \"colour\": 1"),
       "shapes[3].colour: unknown key; valid keys for this shape are: type, id, name, material, emission, "
       "flip_normals, two_sided, center, radius"},
      {"unknown strategy", variant("\"spp\": 2", "\"spp\": 2, \"strategy\": \"bidir\""),
       "render.strategy: unknown strategy 'bidir'; valid: mis, bsdf, light"},
      {"strategy not a string", variant("\"spp\": 2", "\"spp\": 2, \"strategy\": 1"), "render.strategy"},
      {"caustic tracing not a boolean", variant("\"spp\": 2", "\"spp\": 2, \"caustic_tracing\": \"yes\""),
       "render.caustic_tracing"},
      {"negative caustic paths", variant("\"spp\": 2", "\"spp\": 2, \"caustic_paths_per_pixel\": -1"),
       "render.caustic_paths_per_pixel"},
      {"too many caustic paths", variant("\"spp\": 2", "\"spp\": 2, \"caustic_paths_per_pixel\": 65"),
       "render.caustic_paths_per_pixel: must be at most 64"},
      {"unknown top-level key", variant("\"render\"", "\"rendr\""),
       "rendr: unknown key; valid keys here are: image, camera, render"},
      {"unknown material", variant("\"material\": \"white\"}", "\"material\": \"snow\"}"),
       "shapes[0].material: unknown material 'snow'; defined materials are: white"},
      {"unknown shape type", variant("\"type\": \"sphere\"", "\"type\": \"torus\""),
       "shapes[0].type: unknown shape type 'torus'"},
      {"unknown material type", variant("\"type\": \"diffuse\"", "\"type\": \"velvet\""),
       "materials.white.type: unknown material type 'velvet'"},
      {"missing camera", variant("\"camera\"", "\"camera_\""), "camera_: unknown key"},
      {"vector of two", variant("\"center\": [0, 0, 0]", "\"center\": [0, 0]"),
       "shapes[0].center: expected an array of 3 numbers"},
      {"negative emission", variant("\"emission\": [1, 1, 1]", "\"emission\": [1, -1, 1]"),
       "shapes[1].emission[1]: expected a number >= 0"},
      {"zero normal", variant("\"normal\": [0, 1, 0]", "\"normal\": [0, 0, 0]"),
       "shapes[2].normal: expected a non-zero direction"},
      {"non-integer spp", variant("\"spp\": 2", "\"spp\": 2.5"), "render.spp: expected an integer in [1, "},
      {"huge number", variant("\"radius\": 0.5", "\"radius\": 1e39"),
       "shapes[3].radius: expected a finite number"},
      {"phong energy",
       variant("\"type\": \"diffuse\", \"reflectance\": [0.5, 0.5, 0.5]",
               "\"type\": \"phong\", \"kd\": 0.6, \"ks\": 0.6"),
       "materials.white: kd + ks must be <= 1"},
      {"missing texture",
       variant("\"reflectance\": [0.5, 0.5, 0.5]", "\"reflectance\": {\"texture\": \"nope.png\"}"),
       "materials.white.reflectance.texture: "},
      {"missing mesh file",
       variant("\"type\": \"sphere\", \"center\": [2, 0, 0], \"radius\": 0.5,",
               "\"type\": \"mesh\", \"file\": \"nope.glb\","),
       "shapes[3].file: "},
      {"syntax error", variant("\"spp\": 2}", "\"spp\": 2"), "invalid JSON"},
  };
  for (const BadCase& c : cases) {
    TempDir dir;
    const std::string path = dir.write("bad.json", c.json);
    const std::string message = loadError(path);
    EXPECT_EQ(message.rfind(path + ": ", 0), 0u)
        << c.name << ": message does not start with the file: " << message;
    EXPECT_NE(message.find(c.expected), std::string::npos) << c.name << ": got \"" << message << "\"";
  }
}

TEST(SceneParser, MissingFileIsReported) {
  EXPECT_EQ(loadError("/nonexistent/scene.json"), "/nonexistent/scene.json: no such file");
}

TEST(SceneParser, SharedSceneVersionsLoad) {
  for (const char* name : {"cornell-area", "cornell-point", "shapes", "textured", "demo", "gltf-mixed",
                           "courtyard", "terrace"}) {
    const Scene scene = loadScene(test::sourcePath(std::string("scenes/") + name + ".json"));
    EXPECT_FALSE(scene.shapes.empty()) << name;
  }
}

TEST(CommandLine, BadSceneExitsNonZeroAndWritesNothing) {
  TempDir dir;
  const std::string scene = dir.write("bad.json", variant("\"radius\": 0.5", "\"radius\": -0.5"));
  const std::string out = dir.file("out.exr");
  const auto r =
      test::runEmber("render '" + scene + "' -o '" + out + "' --png '" + dir.file("out.png") + "' -q");
  EXPECT_NE(r.exitCode, 0);
  EXPECT_NE(r.output.find("shapes[3].radius: expected a number > 0"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(out));
  EXPECT_FALSE(std::filesystem::exists(dir.file("out.png")));
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path), {}), 1);  // only bad.json
}

TEST(CommandLine, RenderWritesExrAndPngAndInfoDescribesScene) {
  TempDir dir;
  const std::string scene = dir.write("ok.json", kValidScene);
  const auto r = test::runEmber("render '" + scene + "' -o '" + dir.file("a.exr") + "' --png '" +
                                dir.file("a.png") + "' --spp 4 --threads 1");
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_TRUE(std::filesystem::exists(dir.file("a.exr")));
  EXPECT_TRUE(std::filesystem::exists(dir.file("a.png")));
  EXPECT_NE(r.output.find("8x8, 4 spp, 1 threads"), std::string::npos) << r.output;

  const auto info = test::runEmber("info '" + scene + "'");
  ASSERT_EQ(info.exitCode, 0) << info.output;
  EXPECT_NE(info.output.find("shapes:     4  disc 1  quad 1  sphere 2"), std::string::npos) << info.output;
  EXPECT_NE(info.output.find("1 punctual, 1 area (0 two-sided), 0 emissive triangles (0 two-sided)"),
            std::string::npos)
      << info.output;

  const auto tm =
      test::runEmber("tonemap '" + dir.file("a.exr") + "' -o '" + dir.file("b.png") + "' --key 0.3");
  EXPECT_EQ(tm.exitCode, 0) << tm.output;
  EXPECT_TRUE(std::filesystem::exists(dir.file("b.png")));
}

TEST(CommandLine, BadArgumentsExitNonZero) {
  TempDir dir;
  const std::string scene = dir.write("ok.json", kValidScene);
  EXPECT_NE(test::runEmber("render '" + scene + "' -o '" + dir.file("x.png") + "'").exitCode, 0);
  EXPECT_NE(test::runEmber("render '" + scene + "' -o '" + dir.file("no/such/dir/x.exr") + "'").exitCode, 0);
  EXPECT_NE(test::runEmber("render '" + scene + "' -o '" + dir.file("x.exr") + "' --spp 0").exitCode, 0);
  EXPECT_NE(test::runEmber("render '" + scene + "' -o '" + dir.file("x.exr") + "' --spp -3").exitCode, 0);
  EXPECT_NE(test::runEmber("frobnicate").exitCode, 0);
  EXPECT_NE(
      test::runEmber("tonemap '" + dir.file("missing.exr") + "' -o '" + dir.file("m.png") + "'").exitCode, 0);
  EXPECT_FALSE(std::filesystem::exists(dir.file("x.exr")));
  EXPECT_FALSE(std::filesystem::exists(dir.file("m.png")));
  EXPECT_NE(test::runEmber("render '" + scene + "' -o '" + dir.file("x.exr") + "' --strategy bidir").exitCode,
            0);
  EXPECT_NE(
      test::runEmber("render '" + scene + "' -o '" + dir.file("x.exr") + "' --caustics photons").exitCode, 0);
  EXPECT_FALSE(std::filesystem::exists(dir.file("x.exr")));
  const auto help = test::runEmber("render --help");
  EXPECT_EQ(help.exitCode, 0);
  EXPECT_NE(help.output.find("--first-sample"), std::string::npos);
  EXPECT_NE(help.output.find("--strategy"), std::string::npos);
  EXPECT_NE(help.output.find("--caustics"), std::string::npos);
}

// ember info says how caustics are estimated, and why not by light tracing when it is not.
TEST(CommandLine, InfoSaysHowCausticsAreEstimated) {
  const auto area = test::runEmber("info '" + test::sourcePath("scenes/cornell-area.json") + "'");
  EXPECT_NE(area.output.find("caustics:   light-traced, 2 specular object(s)"), std::string::npos)
      << area.output;
  const auto point = test::runEmber("info '" + test::sourcePath("scenes/cornell-point.json") + "'");
  EXPECT_NE(point.output.find("caustics:   light-traced, 2 specular object(s)"), std::string::npos)
      << point.output;
  const auto shapes = test::runEmber("info '" + test::sourcePath("scenes/shapes.json") + "'");
  EXPECT_NE(shapes.output.find("caustics:   path-traced (no mirror or glass)"), std::string::npos)
      << shapes.output;
}

// --strategy bsdf cannot reach the scene's point light, and says so; the others are silent.
TEST(CommandLine, BsdfStrategyWarnsAboutUnreachableDeltaLights) {
  TempDir dir;
  const std::string scene = dir.write("ok.json", kValidScene);
  const auto bsdf =
      test::runEmber("render '" + scene + "' -o '" + dir.file("b.exr") + "' --spp 1 -q --strategy bsdf");
  ASSERT_EQ(bsdf.exitCode, 0) << bsdf.output;
  EXPECT_NE(bsdf.output.find("cannot reach the scene's 1 point, spot or directional light"),
            std::string::npos)
      << bsdf.output;
  const auto light =
      test::runEmber("render '" + scene + "' -o '" + dir.file("l.exr") + "' --spp 1 -q --strategy light");
  ASSERT_EQ(light.exitCode, 0) << light.output;
  EXPECT_EQ(light.output.find("warning"), std::string::npos) << light.output;
  const auto info = test::runEmber(
      "info '" + dir.write("s.json", variant("\"spp\": 2", "\"spp\": 2, \"strategy\": \"light\"")) + "'");
  EXPECT_NE(info.output.find("strategy:   light"), std::string::npos) << info.output;
}

}  // namespace
}  // namespace ember
