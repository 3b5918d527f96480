// Filtered textures ("filter": "trilinear", io/filtered_texture.h): with no footprint the lookup is
// the bilinear one; MIP level k is the 2^k x 2^k box average of the image; a footprint as wide as
// the image gives its mean; the camera's footprint grows with distance and obliquity, and after a
// bounce with the segment and the lobe's roughness; a texture looked up from its file equals the
// decoded one; a texture file deleted between renders is an error; scenes ask for the filter by
// name, and a wrong name is an error naming the key.
#include "cli_runner.h"
#include "io/filtered_texture.h"
#include "io/input_error.h"
#include "io/scene_loader.h"
#include "materials/gltf_pbr.h"
#include "renderer/camera.h"
#include "renderer/path_integrator.h"

#include <gtest/gtest.h>

#include "gltf_builder.h"
#include "test_fixtures.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
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

// A unit quad on y = 0 seen from above, textured with `file` under `filter`.
std::string texturedQuad(const std::string& file, const std::string& filter, int width = 8, int height = 6) {
  return R"({"camera": {"origin": [0, 1, 3], "target": [0, 0, 0]}, "image": {"width": )" +
         std::to_string(width) + R"(, "height": )" + std::to_string(height) + R"(},
    "materials": {"m": {"type": "diffuse", "reflectance": {"texture": ")" +
         file + R"(", "filter": ")" + filter + R"("}}},
    "shapes": [{"type": "quad", "material": "m", "vertices": [[-1, 0, 1], [1, 0, 1], [1, 0, -1], [-1, 0, -1]]}]})";
}

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

// After a bounce the footprint widens by the spread of the lobe the path took
// (PathIntegrator::widenFootprint): more for a longer segment and for a rougher lobe (a lower
// pdf: the median pdf of GGX samples at roughness 0.2 against 0.6), not at all after a Dirac lobe
// or for scenes that do not filter.
TEST(Footprint, WidensWithTheSegmentAndTheRoughnessOfTheLastBounce) {
  REQUIRE_PLUGIN(plugin);
  TempDir dir;
  dir.write("checker.pfm", std::string("PF\n2 2\n-1\n") + std::string(12 * sizeof(float), '\0'));
  const auto sceneWith = [](const std::string& filter) {
    return texturedQuad("checker.pfm", filter, 80, 60);
  };
  Scene scene = loadScene(dir.write("tri.json", sceneWith("trilinear")));
  scene.build();
  SurfaceHit hit;
  ASSERT_TRUE(scene.intersect(Ray{Vec3(0.2f, 1.0f, 0.1f), Vec3(0.0f, -1.0f, 0.0f)}, hit));
  const float camera = hit.uvFootprint;
  ASSERT_GT(camera, 0.0f);
  const auto widened = [&](float pdf, bool delta, float t) {
    SurfaceHit h = hit;
    h.t = t;
    PathState path;
    path.ray = Ray{h.p - t * Vec3(0.0f, -1.0f, 0.0f), Vec3(0.0f, -1.0f, 0.0f)};
    path.previousDelta = delta;
    path.previousPdf = pdf;
    PathIntegrator::widenFootprint(scene, path, h);
    return h.uvFootprint;
  };
  // The median pdf of a GGX lobe's samples, head-on.
  const auto medianPdf = [](float roughness) {
    GltfPbrInputs in;
    in.metallicRoughness = std::make_shared<ConstantTexture>(Color(0.0f, roughness, 1.0f));
    const GltfPbrMaterial m(std::move(in));
    const SurfaceHit flat = test::flatHit();
    std::vector<float> pdfs;
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (int i = 0; i < 501; ++i) {
      BsdfSample bs;
      if (m.sample(flat, Vec3(0.0f, 0.0f, 1.0f), Vec2(u(rng), u(rng)), u(rng), bs)) pdfs.push_back(bs.pdf);
    }
    std::nth_element(pdfs.begin(), pdfs.begin() + long(pdfs.size() / 2), pdfs.end());
    return pdfs[pdfs.size() / 2];
  };
  const float smooth = medianPdf(0.2f), rough = medianPdf(0.6f);
  ASSERT_GT(smooth, rough);
  EXPECT_GT(widened(smooth, false, 1.0f), camera);
  EXPECT_GT(widened(rough, false, 1.0f), widened(smooth, false, 1.0f));
  EXPECT_GT(widened(smooth, false, 2.0f), widened(smooth, false, 1.0f));
  // The extra width is the cone's: 2 / sqrt(pi pdf) per unit length, head-on.
  EXPECT_NEAR(widened(4.0f, false, 0.5f) / camera,
              1.0f + 0.5f * 2.0f / std::sqrt(kPi * 4.0f) / scene.camera().footprintAt(hit.p, hit.ng), 1e-4f);
  EXPECT_EQ(widened(smooth, true, 1.0f), camera);
  Scene plain = loadScene(dir.write("bi.json", sceneWith("bilinear")));
  plain.build();
  SurfaceHit h;
  ASSERT_TRUE(plain.intersect(Ray{Vec3(0.2f, 1.0f, 0.1f), Vec3(0.0f, -1.0f, 0.0f)}, h));
  PathState path;
  path.previousDelta = false;
  path.previousPdf = 1.0f;
  PathIntegrator::widenFootprint(plain, path, h);
  EXPECT_EQ(h.uvFootprint, 0.0f);
}

TEST(FilteredTexture, ScenesNameTheFilterAndAWrongNameIsAnError) {
  REQUIRE_PLUGIN(plugin);
  TempDir dir;
  dir.write("checker.pfm", std::string("PF\n2 2\n-1\n") + std::string(12 * sizeof(float), '\0'));
  const auto sceneWith = [](const std::string& filter) { return texturedQuad("checker.pfm", filter); };
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

namespace ember {
namespace {

using test::TempDir;

PluginPixels floatPixels(const std::vector<Color>& texels, int width, int height) {
  PluginPixels px;
  px.width = width;
  px.height = height;
  px.channels = 3;
  px.type = PluginPixels::Type::F32;
  for (const Color& c : texels) px.f32.insert(px.f32.end(), {c.x, c.y, c.z});
  return px;
}

// A float .tx read straight from its file (tiles on demand) gives the texels the decoded image
// gives: the same bounds, the same level-0 lookups, MIP levels within the two box filters'
// rounding; a grey file answers for all three channels; 8-bit files are left to the decoder
// unless called linear; a missing file is an error.
TEST(FilteredTexture, FromItsFileItEqualsTheDecodedImage) {
  REQUIRE_PLUGIN(plugin);
  TempDir dir;
  const int w = 64, h = 32;
  const std::vector<Color> texels = randomTexels(w, h, 9);
  const std::string tx = dir.file("f32.tx");
  ASSERT_EQ(plugin->write(tx, floatPixels(texels, w, h)), "");
  ImagePlugin::TextureFile info;
  std::string error;
  const void* handle = plugin->addTextureFile(tx, false, info, error);
  ASSERT_NE(handle, nullptr) << error;
  EXPECT_EQ(info.width, w);
  EXPECT_EQ(info.height, h);
  EXPECT_TRUE(info.floating);
  EXPECT_TRUE(info.mipmapped);
  const FilteredImageTexture fromFile(*plugin, tx, handle, info, TextureWrap::Repeat, Color(2.0f));
  const FilteredImageTexture decoded(*plugin, "memory", w, h, texels, TextureWrap::Repeat, Color(2.0f));
  expectNear(fromFile.maxValue(), decoded.maxValue(), 0.0f, "max");
  expectNear(fromFile.minValue(), decoded.minValue(), 0.0f, "min");
  expectNear(fromFile.average(), decoded.average(), 1e-5f, "mean");
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-0.5f, 1.5f);
  for (int i = 0; i < 200; ++i) {
    SurfaceHit hit;
    hit.uv = Vec2(u(rng), u(rng));
    const std::string where = "uv (" + std::to_string(hit.uv.x) + ", " + std::to_string(hit.uv.y) + ")";
    expectNear(fromFile.eval(hit.uv), decoded.eval(hit.uv), 2e-5f, where);
    hit.uvFootprint = 0.1f;
    expectNear(fromFile.evalFresh(hit), decoded.evalFresh(hit), 2e-3f, where + ", footprint 0.1");
  }

  // One channel: grey.
  PluginPixels grey;
  grey.width = grey.height = 8;
  grey.channels = 1;
  grey.type = PluginPixels::Type::F32;
  for (int i = 0; i < 64; ++i) grey.f32.push_back(float(i) / 64.0f);
  ASSERT_EQ(plugin->write(dir.file("grey.tx"), grey), "");
  ImagePlugin::TextureFile greyInfo;
  const void* greyHandle = plugin->addTextureFile(dir.file("grey.tx"), false, greyInfo, error);
  ASSERT_NE(greyHandle, nullptr) << error;
  const FilteredImageTexture greyTexture(*plugin, "grey", greyHandle, greyInfo, TextureWrap::Clamp,
                                         Color(1.0f));
  const Color g = greyTexture.eval(Vec2(0.3f, 0.6f));
  EXPECT_GT(g.x, 0.0f);
  EXPECT_EQ(g.x, g.y);
  EXPECT_EQ(g.x, g.z);
  EXPECT_EQ(greyTexture.maxValue(), Color(63.0f / 64.0f));

  // 8-bit: sRGB unless the scene calls it linear.
  PluginPixels bytes;
  bytes.width = bytes.height = 4;
  bytes.channels = 3;
  for (int i = 0; i < 48; ++i) bytes.u8.push_back(uint8_t(i * 5));
  ASSERT_EQ(plugin->write(dir.file("u8.tx"), bytes), "");
  ImagePlugin::TextureFile byteInfo;
  error.clear();
  EXPECT_EQ(plugin->addTextureFile(dir.file("u8.tx"), false, byteInfo, error), nullptr);
  EXPECT_EQ(error, "");
  EXPECT_NE(plugin->addTextureFile(dir.file("u8.tx"), true, byteInfo, error), nullptr) << error;
  EXPECT_EQ(plugin->addTextureFile(dir.file("missing.tx"), false, byteInfo, error), nullptr);
  EXPECT_NE(error, "");
  // A NaN texel is an error; a negative one leaves the file to the decoder, which clamps it.
  std::vector<Color> odd = randomTexels(8, 8, 6);
  odd[9].y = std::nanf("");
  ASSERT_EQ(plugin->write(dir.file("nan.tx"), floatPixels(odd, 8, 8)), "");
  error.clear();
  EXPECT_EQ(plugin->addTextureFile(dir.file("nan.tx"), false, byteInfo, error), nullptr);
  EXPECT_NE(error.find("NaN"), std::string::npos) << error;
  odd[9].y = -0.5f;
  ASSERT_EQ(plugin->write(dir.file("negative.tx"), floatPixels(odd, 8, 8)), "");
  error.clear();
  EXPECT_EQ(plugin->addTextureFile(dir.file("negative.tx"), false, byteInfo, error), nullptr);
  EXPECT_EQ(error, "");
}

// A scene's trilinear texture whose file is gone by the next render (a resume, a re-render) is
// an error naming the file, and nothing is written.
TEST(FilteredTexture, ATextureThatDisappearsBetweenRendersIsAnErrorNamingIt) {
  REQUIRE_PLUGIN(plugin);
  TempDir dir;
  ASSERT_EQ(plugin->write(dir.file("wood.tx"), floatPixels(randomTexels(16, 16, 2), 16, 16)), "");
  const std::string scene = dir.write("s.json", texturedQuad("wood.tx", "trilinear"));
  const std::string out = dir.file("a.exr");
  ASSERT_EQ(test::runEmber("render '" + scene + "' -o '" + out + "' --spp 2 -q").exitCode, 0);
  std::filesystem::remove(dir.file("wood.tx"));
  const test::CliResult again =
      test::runEmber("render '" + scene + "' -o '" + dir.file("b.exr") + "' --spp 2 -q");
  EXPECT_NE(again.exitCode, 0);
  EXPECT_NE(again.output.find("wood.tx"), std::string::npos) << again.output;
  EXPECT_FALSE(std::filesystem::exists(dir.file("b.exr")));
  // A truncated file: an error naming it at load.
  ASSERT_EQ(plugin->write(dir.file("cut.tx"), floatPixels(randomTexels(64, 64, 3), 64, 64)), "");
  std::filesystem::resize_file(dir.file("cut.tx"), std::filesystem::file_size(dir.file("cut.tx")) / 10);
  try {
    loadScene(dir.write("cut.json", texturedQuad("cut.tx", "trilinear")));
    ADD_FAILURE() << "a truncated texture loaded";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cut.tx"), std::string::npos) << e.what();
  }
  // Level 0 whole but the coarser MIP levels cut off: the load (which reads level 0) succeeds, the
  // render's lookups fail, and the render command says so and writes nothing.
  ASSERT_EQ(plugin->write(dir.file("tail.tx"), floatPixels(randomTexels(256, 256, 4), 256, 256)), "");
  std::filesystem::resize_file(dir.file("tail.tx"),
                               std::filesystem::file_size(dir.file("tail.tx")) * 82 / 100);
  const std::string tail = dir.write("tail.json", texturedQuad("tail.tx", "trilinear", 16, 12));
  const test::CliResult cut =
      test::runEmber("render '" + tail + "' -o '" + dir.file("c.exr") + "' --spp 4 -q");
  EXPECT_NE(cut.exitCode, 0);
  EXPECT_NE(cut.output.find("tail.tx: texture lookups failed"), std::string::npos) << cut.output;
  EXPECT_FALSE(std::filesystem::exists(dir.file("c.exr")));
}

}  // namespace
}  // namespace ember

namespace ember {
namespace {

// glTF images filtered trilinearly (--texture-filter trilinear, LoadOptions::trilinearTextures):
// a checkerboard of 8-texel squares repeated 64 times over a quad seen whole in a 32 x 24 image
// spans about 128 texels per pixel, so the filtered base colour is the checkerboard's mean (0.5 after sRGB
// decoding of 0 and 255) while the bilinear one is black or white; KHR_texture_transform's scale
// widens the footprint as it shrinks the texture.
TEST(FilteredTexture, GltfImagesFilterTrilinearlyOnRequest) {
  REQUIRE_PLUGIN(plugin);
  TempDir dir;
  test::GltfBuilder b;
  std::vector<unsigned char> checker;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) checker.insert(checker.end(), 3, ((x / 8 + y / 8) & 1) ? 255 : 0);
  tinygltf::Material m;
  m.pbrMetallicRoughness.baseColorTexture.index = b.addTexture(64, 64, 3, checker);
  m.pbrMetallicRoughness.metallicFactor = 0.0;
  b.addQuad(1.0f, b.addMaterial(m), 64.0f);
  ASSERT_TRUE(b.write(dir.file("checker.gltf")));
  const auto baseColors = [&](bool trilinear) {
    LoadOptions options;
    options.trilinearTextures = trilinear;
    Scene scene = loadScene(dir.file("checker.gltf"), options);
    EXPECT_EQ(scene.filteredTextures, trilinear);
    scene.settings.width = 32;
    scene.settings.height = 24;
    scene.build();
    std::vector<float> values;
    for (int y = 8; y < 16; y += 2)
      for (int x = 12; x < 20; x += 2) {
        SurfaceHit hit;
        if (!scene.intersect(scene.camera().generateRay(float(x) + 0.37f, float(y) + 0.61f), hit)) continue;
        const auto* pbr = dynamic_cast<const GltfPbrMaterial*>(hit.material);
        EXPECT_NE(pbr, nullptr);
        if (pbr) values.push_back(pbr->inputs().baseColor->evalFresh(hit).x);
      }
    return values;
  };
  const std::vector<float> filtered = baseColors(true), plain = baseColors(false);
  ASSERT_EQ(filtered.size(), 16u);
  ASSERT_EQ(plain.size(), 16u);
  int extremes = 0;
  for (size_t i = 0; i < filtered.size(); ++i) {
    EXPECT_NEAR(filtered[i], 0.5f, 0.05f) << "hit " << i;
    extremes += plain[i] < 0.1f || plain[i] > 0.9f ? 1 : 0;
  }
  EXPECT_GT(extremes, 8);
}

// A texture that remembers the footprint it was asked for.
class FootprintProbe final : public Texture {
 public:
  mutable float width = -1.0f;
  Color eval(Vec2) const override { return Color(0.0f); }
  Color evalFootprint(Vec2, float w) const override {
    width = w;
    return Color(0.0f);
  }
  Color maxValue() const override { return Color(0.0f); }
  Color minValue() const override { return Color(0.0f); }
  Color average() const override { return Color(0.0f); }
};

TEST(FilteredTexture, TextureTransformsScaleTheFootprint) {
  const auto probe = std::make_shared<FootprintProbe>();
  const UvTransformTexture transformed(probe, Vec2(0.1f, 0.2f), 0.7f, Vec2(4.0f, 9.0f));
  SurfaceHit hit;
  hit.uv = Vec2(0.3f, 0.4f);
  hit.uvFootprint = 0.01f;
  transformed.evalFresh(hit);
  EXPECT_NEAR(probe->width, 0.06f, 1e-6f);  // 0.01 sqrt(4 x 9)
  const TexCoordSetTexture set1(probe, 1);
  set1.evalFresh(hit);
  EXPECT_EQ(probe->width, 0.01f);
}

}  // namespace
}  // namespace ember
