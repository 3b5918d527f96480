// Filtered textures ("filter": "trilinear", io/filtered_texture.h): with no footprint the lookup is
// the bilinear one; MIP level k is the 2^k x 2^k box average of the image; a footprint as wide as
// the image gives its mean; the camera's footprint grows with distance and obliquity; scenes ask
// for the filter by name, and a wrong name is an error naming the key.
#include "cli_runner.h"
#include "io/filtered_texture.h"
#include "io/input_error.h"
#include "io/scene_loader.h"
#include "renderer/camera.h"

#include <gtest/gtest.h>

#include <random>

namespace ember {
namespace {

using test::TempDir;

std::vector<Color> randomTexels(int width, int height, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::vector<Color> t(size_t(width) * size_t(height));
  for (Color& c : t) c = Color(u(rng), u(rng), u(rng));
  return t;
}

#define REQUIRE_PLUGIN(p)               \
  const ImagePlugin* p = imagePlugin(); \
  if (!p) GTEST_SKIP() << "no OpenImageIO plugin: " << imagePluginError();

void expectNear(const Color& a, const Color& b, float tol, const std::string& what) {
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[c], b[c], tol) << what << " channel " << c;
}

TEST(FilteredTexture, WithoutAFootprintItIsTheBilinearLookup) {
  REQUIRE_PLUGIN(plugin);
  const int w = 16, h = 8;
  const std::vector<Color> texels = randomTexels(w, h, 1);
  for (TextureWrap wrap : {TextureWrap::Repeat, TextureWrap::Clamp, TextureWrap::Mirror}) {
    const FilteredImageTexture filtered(*plugin, "test", w, h, texels, wrap, Color(1.0f));
    const ImageTexture bilinear(w, h, texels, TextureFilter::Bilinear, wrap);
    std::mt19937 rng(2);
    std::uniform_real_distribution<float> u(-0.5f, 1.5f);
    for (int i = 0; i < 200; ++i) {
      const Vec2 uv(u(rng), u(rng));
      expectNear(filtered.eval(uv), bilinear.eval(uv), 2e-5f,
                 "uv (" + std::to_string(uv.x) + ", " + std::to_string(uv.y) + ")");
    }
  }
}

// Level k of a 32 x 32 image is its 2^k x 2^k block means: a footprint exactly one level-k texel
// wide, at the centre of such a texel, reads that mean.
TEST(FilteredTexture, MipLevelsAreBoxFilteredBlocks) {
  REQUIRE_PLUGIN(plugin);
  const int n = 32;
  const std::vector<Color> texels = randomTexels(n, n, 3);
  const FilteredImageTexture filtered(*plugin, "test", n, n, texels, TextureWrap::Repeat, Color(1.0f));
  for (int k = 1; k <= 3; ++k) {
    const int block = 1 << k, cells = n / block;
    for (int by = 0; by < cells; by += 3)
      for (int bx = 0; bx < cells; bx += 3) {
        Color mean(0.0f);
        for (int y = 0; y < block; ++y)
          for (int x = 0; x < block; ++x) mean += texels[size_t((by * block + y) * n + bx * block + x)];
        mean /= float(block * block);
        SurfaceHit hit;
        hit.uv = Vec2((float(bx) + 0.5f) / float(cells), (float(by) + 0.5f) / float(cells));
        hit.uvFootprint = float(block) / float(n);
        expectNear(filtered.evalFresh(hit), mean, 2e-3f, "level " + std::to_string(k));
      }
  }
}

TEST(FilteredTexture, AFootprintAsWideAsTheImageGivesItsMean) {
  REQUIRE_PLUGIN(plugin);
  const int n = 64;
  const std::vector<Color> texels = randomTexels(n, n, 4);
  const FilteredImageTexture filtered(*plugin, "test", n, n, texels, TextureWrap::Repeat, Color(2.0f));
  SurfaceHit hit;
  hit.uv = Vec2(0.3f, 0.7f);
  hit.uvFootprint = 4.0f;
  expectNear(filtered.evalFresh(hit), filtered.average(), 2e-3f, "mean");
}

TEST(Footprint, GrowsWithDistanceAndObliquity) {
  CameraParams params;
  params.origin = Vec3(0.0f);
  params.target = Vec3(0.0f, 0.0f, -1.0f);
  params.fovYDeg = 40.0f;
  const Camera camera(params, 200, 100);
  const Vec3 facing(0.0f, 0.0f, 1.0f);
  const float near = camera.footprintAt(Vec3(0.0f, 0.0f, -2.0f), facing);
  // One pixel's height at distance 2: 2 tan(20 deg) 2 / 100.
  EXPECT_NEAR(near, 4.0f * std::tan(glm::radians(20.0f)) / 100.0f, 1e-6f);
  EXPECT_NEAR(camera.footprintAt(Vec3(0.0f, 0.0f, -4.0f), facing) / near, 2.0f, 1e-5f);
  // Seen at cos = 1/4 the footprint ellipse is 4 times as long: its mean width twice as wide.
  const float s = std::sqrt(1.0f - 0.0625f);
  EXPECT_NEAR(camera.footprintAt(Vec3(0.0f, 0.0f, -2.0f), Vec3(s, 0.0f, 0.25f)) / near, 2.0f, 1e-4f);
}

TEST(FilteredTexture, ScenesNameTheFilterAndAWrongNameIsAnError) {
  REQUIRE_PLUGIN(plugin);
  TempDir dir;
  dir.write("checker.pfm", std::string("PF\n2 2\n-1\n") + std::string(12 * sizeof(float), '\0'));
  const auto sceneWith = [&](const std::string& filter) {
    return R"({"camera": {"origin": [0, 1, 3], "target": [0, 0, 0]}, "image": {"width": 8, "height": 6},
      "materials": {"m": {"type": "diffuse", "reflectance": {"texture": "checker.pfm", "filter": ")" +
           filter + R"("}}},
      "shapes": [{"type": "quad", "material": "m",
                  "vertices": [[-1, 0, 1], [1, 0, 1], [1, 0, -1], [-1, 0, -1]]}]})";
  };
  const Scene scene = loadScene(dir.write("tri.json", sceneWith("trilinear")));
  EXPECT_TRUE(scene.filteredTextures);
  EXPECT_FALSE(loadScene(dir.write("bi.json", sceneWith("bilinear"))).filteredTextures);
  try {
    loadScene(dir.write("bad.json", sceneWith("cubic")));
    ADD_FAILURE() << "an unknown filter loaded";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("bad.json"), std::string::npos) << what;
    EXPECT_NE(what.find("filter"), std::string::npos) << what;
    EXPECT_NE(what.find("trilinear"), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace ember
