// glTF emission as Blender and the glTF viewers show it: a doubleSided emissive material emits on
// both faces (the back face is shaded with the reversed normal, glTF 2.0 section 3.9.5), a
// single-sided one on the front only, for rays that hit it and for light sampling alike; and a
// file lit only by emissive materials gets no default sky (which is for files with no light at
// all, and is announced on stderr).
#include "cli_runner.h"
#include "gltf_builder.h"
#include "io/scene_loader.h"

#include <gtest/gtest.h>

namespace ember {
namespace {

using test::TempDir;

// One emissive quad (z = 0, facing +z, strength 10 as Blender exports it) and, optionally, a grey
// quad beside it that does not emit.
std::string writeEmissiveQuad(const TempDir& dir, const std::string& name, bool doubleSided,
                              bool emissive = true, double emissiveStrength = 10.0) {
  test::GltfBuilder b;
  tinygltf::Material m;
  m.name = "glow";
  m.doubleSided = doubleSided;
  if (emissive) {
    m.emissiveFactor = {1.0, 1.0, 1.0};
    tinygltf::Value::Object strength{{"emissiveStrength", tinygltf::Value(emissiveStrength)}};
    m.extensions["KHR_materials_emissive_strength"] = tinygltf::Value(strength);
    b.model().extensionsUsed.push_back("KHR_materials_emissive_strength");
  }
  b.addQuad(0.5f, b.addMaterial(m));
  const std::string path = dir.file(name);
  EXPECT_TRUE(b.write(path));
  return path;
}

SurfaceHit hitFrom(const Scene& scene, float z) {
  SurfaceHit hit;
  EXPECT_TRUE(scene.intersect(Ray{Vec3(0.1f, 0.1f, z), Vec3(0.0f, 0.0f, z > 0 ? -1.0f : 1.0f)}, hit));
  return hit;
}

TEST(GltfEmission, DoubleSidedEmitsOnBothFacesSingleSidedOnTheFront) {
  const TempDir dir;
  for (const bool doubleSided : {false, true}) {
    Scene scene = loadScene(writeEmissiveQuad(dir, "quad.gltf", doubleSided));
    scene.build();
    ASSERT_EQ(scene.meshes.size(), 1u);
    EXPECT_EQ(scene.meshes[0].twoSidedEmission, doubleSided);
    const Vec3 toFront(0, 0, 1), toBack(0, 0, -1);
    EXPECT_EQ(hitFrom(scene, 1.0f).emitted(toFront), Color(10.0f));
    EXPECT_EQ(hitFrom(scene, -1.0f).emitted(toBack), doubleSided ? Color(10.0f) : Color(0.0f));

    // Light sampling from either side: the back sees the same radiance only when double-sided,
    // with the same density (the light is chosen and sampled by area alike). Behind a
    // single-sided emitter there is no sample (TriangleLight::seesOnlyBack): it would carry none.
    const LightSampler& lights = scene.lightSampler();
    ASSERT_FALSE(lights.empty());
    for (const float z : {1.0f, -1.0f}) {
      float pick;
      const Light* light = lights.sample(0.3f, pick);
      LightSample ls;
      const bool sampled = light->sample(Vec3(0.05f, -0.1f, z), Vec2(0.3f, 0.6f), ls);
      if (z < 0.0f && !doubleSided) {
        EXPECT_FALSE(sampled);
        continue;
      }
      ASSERT_TRUE(sampled);
      EXPECT_GT(ls.pdf, 0.0f);
      EXPECT_EQ(ls.Li, z > 0 || doubleSided ? Color(10.0f) : Color(0.0f)) << "z " << z;
      EXPECT_NEAR(light->pdf(Vec3(0.05f, -0.1f, z), ls.p, ls.n), ls.pdf, 1e-4f * ls.pdf);
    }
  }
}

// Light-giving emission (above 1: KHR_materials_emissive_strength > 1, as Blender exports it)
// lights a file alone; a file without it, a glowing screen of emissive factor 1 included, gets the
// white environment of glTF viewers. stderr says which, and --env overrides either way.
TEST(GltfEmission, DefaultSkyUnlessTheFileHasLightGivingEmission) {
  const TempDir dir;
  const std::string lit = writeEmissiveQuad(dir, "lit.gltf", true);
  const std::string dark = writeEmissiveQuad(dir, "dark.gltf", true, false);
  const std::string screen = writeEmissiveQuad(dir, "screen.gltf", true, true, 1.0);
  for (const auto& [path, sky] : {std::pair{lit, false}, std::pair{dark, true}, std::pair{screen, true}}) {
    Scene scene = loadScene(path);
    scene.build();
    EXPECT_EQ(scene.environment() != nullptr, sky) << path;
  }
  const auto render = [&](const std::string& path, const std::string& extra) {
    return test::runEmber("render '" + path + "' -o '" + dir.file("a.exr") +
                          "' --spp 1 --width 8 --height 8 -q " + extra);
  };
  auto r = render(lit, "");
  EXPECT_EQ(r.exitCode, 0) << r.output;
  EXPECT_NE(r.output.find("environment: none (" + lit + " is lit by its own emission"), std::string::npos)
      << r.output;
  for (const std::string& path : {dark, screen}) {
    r = render(path, "");
    EXPECT_NE(r.output.find("environment: white, radiance 1 (" + path + " has no light-giving emission"),
              std::string::npos)
        << r.output;
  }
  r = render(screen, "--env none");
  EXPECT_NE(r.output.find("environment: none, black (--env)"), std::string::npos) << r.output;
  r = render(lit, "--env white --env-strength 0.5");
  EXPECT_NE(r.output.find("environment: white, radiance 0.5"), std::string::npos) << r.output;
  r = render(lit, "--env-strength 2");
  EXPECT_EQ(r.exitCode, 1) << r.output;
  EXPECT_NE(r.output.find("--env-strength scales the --env light"), std::string::npos) << r.output;
}

TEST(GltfEmission, InfoCountsDoubleSidedEmitters) {
  const TempDir dir;
  const test::CliResult two = test::runEmber("info '" + writeEmissiveQuad(dir, "two.gltf", true) + "'");
  EXPECT_EQ(two.exitCode, 0) << two.output;
  EXPECT_NE(two.output.find("2 emissive triangles (2 two-sided)"), std::string::npos) << two.output;
  const test::CliResult one = test::runEmber("info '" + writeEmissiveQuad(dir, "one.gltf", false) + "'");
  EXPECT_NE(one.output.find("2 emissive triangles (0 two-sided)"), std::string::npos) << one.output;
}

TEST(GltfEmission, JsonTwoSidedKeyMakesAnAnalyticEmitterTwoSided) {
  const TempDir dir;
  const std::string scene = dir.write("s.json", R"({
    "camera": {"origin": [0, 0, 3], "target": [0, 0, 0]},
    "shapes": [{"type": "disc", "center": [0, 0, 0], "normal": [0, 0, 1], "radius": 1,
                "emission": [2, 2, 2], "two_sided": true}]})");
  Scene s = loadScene(scene);
  s.build();
  EXPECT_EQ(hitFrom(s, -1.0f).emitted(Vec3(0, 0, -1)), Color(2.0f));
  const test::CliResult bad = test::runEmber("info '" + dir.write("bad.json", R"({
    "camera": {"origin": [0, 0, 3], "target": [0, 0, 0]},
    "shapes": [{"type": "disc", "center": [0, 0, 0], "normal": [0, 0, 1], "radius": 1, "emission": 1, "two_sided": 3}]})") +
                                             "'");
  EXPECT_EQ(bad.exitCode, 1) << bad.output;
  EXPECT_NE(bad.output.find("shapes[0].two_sided"), std::string::npos) << bad.output;
}

}  // namespace
}  // namespace ember
