// AOV layers (renderer/aov.h, docs/aovs.md): each against a closed form (a Lambertian plane's
// albedo, a sphere's normals and depths, a mirror followed through to what it shows, the
// environment where nothing is hit), the same sums from both drivers, any thread count, any pass
// split and a resume, and the command line's layers, merge and bad input.
#include "checkpoint/checkpoint_file.h"
#include "io/image_io.h"
#include "io/scene_loader.h"
#include "packet/wave_integrator.h"
#include "renderer/render.h"

#include <gtest/gtest.h>

#include "cli_runner.h"
#include "test_paths.h"

#include <cmath>
#include <filesystem>
#include <string>

namespace ember {
namespace {

Film renderAovs(const Scene& scene, AovSet aovs, int spp, Kernel kernel = Kernel::Wave, int threads = 0,
                int passSpp = 4) {
  const std::unique_ptr<Integrator> integrator = makeIntegrator(scene.settings, kernel);
  Film film(scene.settings.width, scene.settings.height, aovs);
  RenderOptions options;
  options.spp = spp;
  options.seed = 7;
  options.threads = threads;
  options.passSpp = passSpp;
  render(scene, *integrator, options, film);
  return film;
}

const ImageLayer& layer(const std::vector<ImageLayer>& layers, const std::string& firstChannel) {
  for (const ImageLayer& l : layers)
    if (l.channels.front() == firstChannel) return l;
  throw std::runtime_error("no layer " + firstChannel);
}

Scene loadText(const test::TempDir& dir, const std::string& json, bool uv = false) {
  Scene scene = loadScene(dir.write("scene.json", json));
  scene.uvOnEveryHit = uv;
  scene.build();
  return scene;
}

const AovSet kAll = *[] {
  std::string error;
  return parseAovs("all", error);
}();

// An orthographic camera 5 units above a Lambertian plane: albedo its reflectance, normal its
// normal, depth 5, coverage 1, and uv within the quad's [0, 1]^2; the colour is unchanged.
TEST(Aovs, ALambertianPlaneGivesItsReflectanceNormalAndDistance) {
  test::TempDir dir;
  const Scene scene = loadText(dir, R"({"image": {"width": 8, "height": 8},
    "camera": {"type": "orthographic", "origin": [0, 0, 5], "target": [0, 0, 0], "up": [0, 1, 0], "half_height": 1},
    "render": {"background": 1},
    "materials": {"grey": {"type": "diffuse", "reflectance": [0.4, 0.5, 0.6]}},
    "shapes": [{"type": "quad", "material": "grey",
                "vertices": [[-2, -2, 0], [2, -2, 0], [2, 2, 0], [-2, 2, 0]]}]})",
                               /*uv=*/true);
  const Film film = renderAovs(scene, kAll, 8);
  const std::vector<ImageLayer> layers = film.aovLayers();
  const ImageLayer &albedo = layer(layers, "albedo.R"), &normal = layer(layers, "N.X"),
                   &z = layer(layers, "Z"), &p = layer(layers, "P.X"), &uv = layer(layers, "uv.U"),
                   &coverage = layer(layers, "coverage"), &spp = layer(layers, "spp");
  for (size_t i = 0; i < film.pixelCount(); ++i) {
    EXPECT_FLOAT_EQ(albedo.pixels[3 * i], 0.4f);
    EXPECT_FLOAT_EQ(albedo.pixels[3 * i + 1], 0.5f);
    EXPECT_FLOAT_EQ(albedo.pixels[3 * i + 2], 0.6f);
    EXPECT_FLOAT_EQ(std::abs(normal.pixels[3 * i + 2]), 1.0f);
    EXPECT_NEAR(z.pixels[i], 5.0f, 1e-5f);
    EXPECT_NEAR(p.pixels[3 * i + 2], 0.0f, 1e-5f);
    EXPECT_EQ(coverage.pixels[i], 1.0f);
    EXPECT_EQ(spp.pixels[i], 8.0f);
    EXPECT_GT(uv.pixels[2 * i], 0.2f);  // the view covers the quad's middle half
    EXPECT_LT(uv.pixels[2 * i], 0.8f);
  }
  // AOVs change nothing in the colour.
  const Film plain = renderAovs(scene, AovSet{}, 8);
  EXPECT_EQ(plain.sums(), film.sums());
  // A path that ends at the surface at the depth limit still gives its albedo (--max-depth 1).
  Scene shallow = loadText(dir, R"({"image": {"width": 4, "height": 4},
    "camera": {"type": "orthographic", "origin": [0, 0, 5], "target": [0, 0, 0], "up": [0, 1, 0], "half_height": 1},
    "render": {"background": 1, "max_depth": 1},
    "materials": {"grey": {"type": "diffuse", "reflectance": [0.4, 0.5, 0.6]}},
    "shapes": [{"type": "quad", "material": "grey",
                "vertices": [[-2, -2, 0], [2, -2, 0], [2, 2, 0], [-2, 2, 0]]}]})");
  const Film limited = renderAovs(shallow, kAll, 4);
  const std::vector<ImageLayer> limitedLayers = limited.aovLayers();
  for (float v : layer(limitedLayers, "albedo.R").pixels) EXPECT_GT(v, 0.39f);
}

// A unit sphere seen orthographically: each pixel's normal and depth are the sphere's at the
// pixel's centre to within the pixel's curvature; outside it, nothing is hit: no normal, infinite
// depth, and the environment's radiance (clamped to 1) as albedo.
TEST(Aovs, ASphereGivesItsNormalsAndDepthsAndTheEnvironmentElsewhere) {
  test::TempDir dir;
  const int size = 24;
  const Scene scene = loadText(dir, R"({"image": {"width": 24, "height": 24},
    "camera": {"type": "orthographic", "origin": [0, 0, 5], "target": [0, 0, 0], "up": [0, 1, 0], "half_height": 1.2},
    "render": {"background": [0.25, 3, 0.5]},
    "materials": {"grey": {"type": "diffuse", "reflectance": 0.5}},
    "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "grey"}]})");
  const Film film = renderAovs(scene, kAll, 32);
  const std::vector<ImageLayer> layers = film.aovLayers();
  const ImageLayer &albedo = layer(layers, "albedo.R"), &normal = layer(layers, "N.X"),
                   &z = layer(layers, "Z"), &coverage = layer(layers, "coverage");
  int inside = 0, outside = 0;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const size_t i = size_t(y) * size + size_t(x);
      const float sx = (2.0f * (float(x) + 0.5f) / size - 1.0f) * 1.2f,
                  sy = (1.0f - 2.0f * (float(y) + 0.5f) / size) * 1.2f;
      const float r2 = sx * sx + sy * sy;
      if (r2 < 0.8f * 0.8f) {
        ++inside;
        const float nz = std::sqrt(1.0f - r2);
        EXPECT_NEAR(normal.pixels[3 * i], sx, 0.02f) << x << "," << y;
        EXPECT_NEAR(normal.pixels[3 * i + 1], sy, 0.02f) << x << "," << y;
        EXPECT_NEAR(normal.pixels[3 * i + 2], nz, 0.02f) << x << "," << y;
        EXPECT_NEAR(z.pixels[i], 5.0f - nz, 0.02f) << x << "," << y;
        EXPECT_FLOAT_EQ(albedo.pixels[3 * i], 0.5f);
        EXPECT_EQ(coverage.pixels[i], 1.0f);
      } else if (r2 > 1.2f * 1.2f) {
        ++outside;
        EXPECT_EQ(coverage.pixels[i], 0.0f);
        EXPECT_TRUE(std::isinf(z.pixels[i]));
        EXPECT_EQ(normal.pixels[3 * i], 0.0f);
        EXPECT_EQ(normal.pixels[3 * i + 2], 0.0f);
        EXPECT_FLOAT_EQ(albedo.pixels[3 * i], 0.25f);
        EXPECT_FLOAT_EQ(albedo.pixels[3 * i + 1], 1.0f);  // 3, clamped
        EXPECT_FLOAT_EQ(albedo.pixels[3 * i + 2], 0.5f);
      }
    }
  EXPECT_GT(inside, 100);
  EXPECT_GT(outside, 50);
}

// A mirror of reflectance 0.5 at 45 degrees shows a wall of reflectance 0.3: albedo 0.15 and the
// wall's normal (OIDN's rule for Dirac surfaces), while depth and position stay the mirror's.
TEST(Aovs, MirrorsAreFollowedToWhatTheyShow) {
  test::TempDir dir;
  const Scene scene = loadText(dir, R"({"image": {"width": 8, "height": 8},
    "camera": {"type": "orthographic", "origin": [0, 0, 5], "target": [0, 0, 0], "up": [0, 1, 0], "half_height": 0.5},
    "render": {"background": 1},
    "materials": {"mirror": {"type": "mirror", "reflectance": 0.5},
                  "wall": {"type": "diffuse", "reflectance": 0.3}},
    "shapes": [{"type": "quad", "material": "mirror", "vertices": [[-2, -2, 2], [2, -2, 2], [2, 2, -2], [-2, 2, -2]]},
               {"type": "quad", "material": "wall", "vertices": [[-5, 3, -5], [5, 3, -5], [5, 3, 5], [-5, 3, 5]]}]})");
  const Film film = renderAovs(scene, kAll, 8);
  const std::vector<ImageLayer> layers = film.aovLayers();
  const ImageLayer &albedo = layer(layers, "albedo.R"), &normal = layer(layers, "N.X"),
                   &z = layer(layers, "Z");
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) {
      const size_t i = size_t(y) * 8 + size_t(x);
      EXPECT_FLOAT_EQ(albedo.pixels[3 * i + 1], 0.15f);
      EXPECT_FLOAT_EQ(normal.pixels[3 * i + 1], -1.0f);
      const float sy = (1.0f - 2.0f * (float(y) + 0.5f) / 8.0f) * 0.5f;
      EXPECT_NEAR(z.pixels[i], 5.0f + sy, 0.07f);  // the mirror's hit at z = -y
    }
}

// Rough and layered materials: every sample's albedo is clamped to [0, 1], so the means are too.
TEST(Aovs, AlbedoStaysWithinZeroAndOneOnEveryMaterial) {
  const std::string gltf =
      test::sharedGltfDir() + "/MetalRoughSpheresNoTextures/glTF/MetalRoughSpheresNoTextures.gltf";
  Scene scene = loadScene(std::filesystem::exists(gltf) ? gltf : test::sourcePath("scenes/gltf-mixed.json"));
  scene.settings.width = 48;
  scene.settings.height = 32;
  scene.build();
  const Film film = renderAovs(scene, kAll, 4);
  const std::vector<ImageLayer> layers = film.aovLayers();
  double sum = 0.0;
  for (float v : layer(layers, "albedo.R").pixels) {
    EXPECT_GE(v, 0.0f);
    EXPECT_LE(v, 1.0f);
    sum += v;
  }
  EXPECT_GT(sum, 0.0);
  for (float v : layer(layers, "N.X").pixels) EXPECT_LE(std::abs(v), 1.0f + 1e-6f);
}

// The layers are sums in the film beside the colour's: the same bit for bit from the scalar
// reference and the wave driver, for any thread count and pass size, and for a render resumed
// from its film after some passes. glTF materials, analytic glass and mirrors, an environment map.
TEST(Aovs, SameSumsFromBothDriversAnyThreadsPassesAndResume) {
  Scene scene = loadScene(test::sourcePath("scenes/gltf-mixed.json"));
  scene.settings.width = 40;
  scene.settings.height = 24;
  scene.uvOnEveryHit = true;
  scene.build();
  const Film wave = renderAovs(scene, kAll, 8, Kernel::Wave, 2, 4);
  const Film scalar = renderAovs(scene, kAll, 8, Kernel::Scalar, 1, 4);
  const Film oneThreadPassesOf3 = renderAovs(scene, kAll, 8, Kernel::Wave, 1, 3);
  EXPECT_EQ(wave.sums(), scalar.sums());
  EXPECT_EQ(wave.aovSums(), scalar.aovSums());
  EXPECT_EQ(wave.aovSums(), oneThreadPassesOf3.aovSums());

  // Two passes, then the rest from that film.
  const std::unique_ptr<Integrator> integrator = makeIntegrator(scene.settings, Kernel::Wave);
  Film resumed(scene.settings.width, scene.settings.height, kAll);
  RenderOptions options;
  options.spp = 4;
  options.seed = 7;
  render(scene, *integrator, options, resumed);
  options.spp = 8;
  options.passesDone = 1;
  render(scene, *integrator, options, resumed);
  EXPECT_EQ(wave.aovSums(), resumed.aovSums());
  bool anyDifferent = false;  // the comparison can fail: a different seed gives other sums
  const Film other = [&] {
    Film f(scene.settings.width, scene.settings.height, kAll);
    RenderOptions o;
    o.spp = 8;
    o.seed = 8;
    render(scene, *integrator, o, f);
    return f;
  }();
  anyDifferent = other.aovSums() != wave.aovSums();
  EXPECT_TRUE(anyDifferent);
}

TEST(Aovs, NamesParseAndPrintBack) {
  std::string error;
  const std::optional<AovSet> set = parseAovs("normal,albedo,spp", error);
  ASSERT_TRUE(set);
  EXPECT_EQ(aovList(*set), "albedo,normal,spp");
  EXPECT_EQ(aovList(kAll), "albedo,normal,depth,position,uv,variance,spp");
  EXPECT_EQ(*parseAovs(aovList(kAll), error), kAll);
  EXPECT_TRUE(parseAovs("none", error)->empty());
  EXPECT_FALSE(parseAovs("albedo,nromal", error));
  EXPECT_NE(error.find("unknown AOV 'nromal'"), std::string::npos) << error;
  EXPECT_FALSE(parseAovs("albedo,", error));
  EXPECT_FALSE(parseAovs("", error));
  // Layout: only what the set asks for.
  const AovLayout layout(*parseAovs("normal,depth", error));
  EXPECT_EQ(layout.channels, 5);  // normal 3, coverage 1, depth 1
  EXPECT_EQ(layout.albedo, -1);
}

// A checkpoint keeps the AOV sums exactly.
TEST(Aovs, CheckpointsKeepTheSums) {
  test::TempDir dir;
  Scene scene = loadScene(test::sourcePath("scenes/cornell-area.json"));
  scene.settings.width = 16;
  scene.settings.height = 12;
  scene.build();
  Checkpoint c;
  c.identity = identityOf(scene, test::sourcePath("scenes/cornell-area.json"), -1, "", "");
  c.spp = 4;
  c.passSpp = 4;
  c.passes = 1;
  c.emberVersion = "test";
  c.film = renderAovs(scene, kAll, 4);
  writeCheckpoint(dir.file("a.ckpt"), c);
  const Checkpoint back = readCheckpoint(dir.file("a.ckpt"));
  EXPECT_EQ(back.film.aovs(), kAll);
  EXPECT_EQ(back.film.aovSums(), c.film.aovSums());
  EXPECT_EQ(back.film.sums(), c.film.sums());
}

const std::string kCornell = test::sourcePath("scenes/cornell-area.json");
const std::string kSmall = " --width 24 --height 16 -q";

std::string quoted(const std::string& s) {
  return "'" + s + "'";
}

// `ember render --aov`: the layers under their names; merge of two sample ranges equals the
// render of their union, layer by layer; a checkpoint resumed keeps them bit for bit.
TEST(AovCli, LayersMergeAndResume) {
  test::TempDir dir;
  const std::string full = dir.file("full.exr"), a = dir.file("a.exr"), b = dir.file("b.exr"),
                    merged = dir.file("m.exr");
  ASSERT_EQ(
      test::runEmber("render " + quoted(kCornell) + " -o " + quoted(full) + kSmall + " --spp 8 --aov all")
          .exitCode,
      0);
  ASSERT_EQ(test::runEmber("render " + quoted(kCornell) + " -o " + quoted(a) + kSmall + " --spp 4 --aov all")
                .exitCode,
            0);
  ASSERT_EQ(test::runEmber("render " + quoted(kCornell) + " -o " + quoted(b) + kSmall +
                           " --spp 4 --first-sample 4 --aov all")
                .exitCode,
            0);
  const test::CliResult m = test::runEmber("merge " + quoted(a) + " " + quoted(b) + " -o " + quoted(merged));
  ASSERT_EQ(m.exitCode, 0) << m.output;
  const ExrChannels one = readExrChannels(full), two = readExrChannels(merged);
  for (const char* name : {"R", "G", "B", "albedo.R", "albedo.G", "albedo.B", "N.X", "N.Y", "N.Z", "Z", "P.X",
                           "P.Y", "P.Z", "uv.U", "uv.V", "coverage", "variance.R", "spp"}) {
    ASSERT_TRUE(one.has(name)) << name;
    ASSERT_TRUE(two.has(name)) << name;
    const std::vector<float>&x = one.channels.at(name), &y = two.channels.at(name);
    const double tolerance = std::string(name).rfind("variance", 0) == 0 ? 1e-4 : 1e-6;
    for (size_t i = 0; i < x.size(); ++i) {
      if (std::isinf(x[i])) {
        EXPECT_EQ(x[i], y[i]) << name;
        continue;
      }
      ASSERT_NEAR(y[i], x[i], tolerance * std::max(1.0f, std::abs(x[i]))) << name << " pixel " << i;
    }
  }
  std::string aovs;
  for (const auto& [k, v] : two.metadata)
    if (k == "ember:aovs") aovs = v;
  EXPECT_EQ(aovs, "albedo,normal,depth,position,uv,variance,spp");

  // Merging an image with AOVs and one without is refused.
  const std::string plain = dir.file("plain.exr");
  ASSERT_EQ(test::runEmber("render " + quoted(kCornell) + " -o " + quoted(plain) + kSmall +
                           " --spp 4 --first-sample 4")
                .exitCode,
            0);
  const test::CliResult mixed =
      test::runEmber("merge " + quoted(a) + " " + quoted(plain) + " -o " + quoted(dir.file("x.exr")));
  EXPECT_EQ(mixed.exitCode, 1);
  EXPECT_NE(mixed.output.find("ember:aovs"), std::string::npos) << mixed.output;

  // Checkpointed at 4 spp, resumed to 8: the same file as the render run through.
  const std::string ckpt = dir.file("r.ckpt"), resumed = dir.file("r.exr");
  ASSERT_EQ(test::runEmber("render " + quoted(kCornell) + " -o " + quoted(resumed) + kSmall +
                           " --spp 4 --aov all --checkpoint " + quoted(ckpt))
                .exitCode,
            0);
  ASSERT_EQ(test::runEmber("render --resume " + quoted(ckpt) + " --spp 8 -q").exitCode, 0);
  const ExrChannels again = readExrChannels(resumed);
  for (const auto& [name, values] : one.channels) {
    ASSERT_TRUE(again.has(name)) << name;
    EXPECT_EQ(again.channels.at(name), values) << name;
  }
}

TEST(AovCli, BadNamesAndResumeWithAovsAreRefused) {
  test::TempDir dir;
  const std::string out = dir.file("o.exr");
  const test::CliResult bad =
      test::runEmber("render " + quoted(kCornell) + " -o " + quoted(out) + kSmall + " --aov albedo,nromal");
  EXPECT_EQ(bad.exitCode, 2) << bad.output;  // CLI11's validation error
  EXPECT_NE(bad.output.find("unknown AOV 'nromal'"), std::string::npos) << bad.output;
  EXPECT_FALSE(std::filesystem::exists(out));
  const std::string ckpt = dir.file("c.ckpt");
  ASSERT_EQ(test::runEmber("render " + quoted(kCornell) + " -o " + quoted(out) + kSmall +
                           " --spp 4 --checkpoint " + quoted(ckpt))
                .exitCode,
            0);
  std::filesystem::remove(out);
  const test::CliResult resume = test::runEmber("render --resume " + quoted(ckpt) + " --aov albedo -q");
  EXPECT_EQ(resume.exitCode, 1) << resume.output;
  EXPECT_NE(resume.output.find("--aov"), std::string::npos) << resume.output;
  EXPECT_FALSE(std::filesystem::exists(out));
}

}  // namespace
}  // namespace ember
