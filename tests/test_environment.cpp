// Environment lighting: the equirectangular map's importance sampling is consistent with its pdf
// and unbiased, and a convex object under a uniform map reflects its albedo.
#include "accel/sphere.h"
#include "cli_runner.h"
#include "core/sampling.h"
#include "io/image_io.h"
#include "materials/lambertian.h"
#include "mc_mean.h"
#include "renderer/path_integrator.h"
#include "renderer/render.h"

#include <gtest/gtest.h>

namespace ember {
namespace {

using test::McMean;

// A 64x32 map with a smooth gradient and one bright patch, so importance sampling matters.
std::shared_ptr<const ImageTexture> testMap() {
  const int w = 64, h = 32;
  std::vector<Color> texels(size_t(w * h));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      Color c(0.2f + 0.8f * float(x) / float(w), 0.5f, 1.0f - float(y) / float(h));
      if (x >= 40 && x < 44 && y >= 10 && y < 13) c = Color(200.0f, 180.0f, 150.0f);
      texels[size_t(y * w + x)] = c;
    }
  return std::make_shared<ImageTexture>(w, h, std::move(texels), TextureFilter::Nearest, TextureWrap::Repeat);
}

TEST(Environment, SampledDirectionsMatchTheirPdf) {
  const EnvironmentLight env(testMap(), 30.0f);
  Rng rng(4, 4);
  LightSample ls;
  int mismatches = 0;
  constexpr int kSamples = 20000;
  for (int i = 0; i < kSamples; ++i) {
    ASSERT_TRUE(env.sample(Vec3(0.0f), Vec2(rng.uniform(), rng.uniform()), ls));
    ASSERT_NEAR(glm::length(ls.wi), 1.0f, 1e-5f);
    // Float round trip uv -> direction -> uv: equal densities except within rounding of a texel edge.
    if (std::abs(ls.pdf - env.pdfDirection(ls.wi)) > 1e-2f * ls.pdf) ++mismatches;
  }
  EXPECT_LE(mismatches, kSamples / 1000);
}

TEST(Environment, PdfIntegratesToOneAndSamplingIsUnbiased) {
  const EnvironmentLight env(testMap(), 30.0f);
  Rng rng(5, 5);
  McMean pdfIntegral, uniformEstimate, importanceEstimate;
  for (int i = 0; i < 400000; ++i) {
    const Vec3 d = sampleUniformSphere(Vec2(rng.uniform(), rng.uniform()));
    pdfIntegral.add(env.pdfDirection(d) / kUniformSpherePdf);
    uniformEstimate.add(luminance(env.radiance(d)) / kUniformSpherePdf);
    LightSample ls;
    ASSERT_TRUE(env.sample(Vec3(0.0f), Vec2(rng.uniform(), rng.uniform()), ls));
    importanceEstimate.add(luminance(ls.Li) / ls.pdf);
  }
  pdfIntegral.expectNear(1.0, 0.0, "integral of the pdf over the sphere");
  // Both estimate the integral of the radiance over the sphere; importance sampling with far less noise.
  EXPECT_NEAR(
      importanceEstimate.mean(), uniformEstimate.mean(),
      test::kSigmas * std::hypot(importanceEstimate.standardError(), uniformEstimate.standardError()));
  EXPECT_LT(importanceEstimate.standardError(), 0.5 * uniformEstimate.standardError());
}

TEST(Environment, ConvexObjectUnderAUniformMapReflectsItsAlbedo) {
  constexpr float kAlbedo = 0.6f;
  Scene scene;
  scene.settings.width = 12;
  scene.settings.height = 12;
  scene.environmentMap = std::make_shared<ImageTexture>(8, 4, std::vector<Color>(32, Color(1.0f)),
                                                        TextureFilter::Bilinear, TextureWrap::Repeat);
  scene.cameraParams = CameraParams{Vec3(0.0f, 0.0f, 5.0f), Vec3(0), Vec3(0, 1, 0), 40.0f};
  const Material* m = scene.addMaterial(
      "grey", std::make_unique<Lambertian>(std::make_shared<ConstantTexture>(Color(kAlbedo))));
  scene.shapes.push_back({"sphere", std::make_unique<Sphere>(Vec3(0.0f), 1.0f), m, Color(0.0f)});
  scene.build();
  const PathIntegrator integrator(-1, 5);
  Film film(12, 12);
  RenderOptions options;
  options.spp = 256;
  render(scene, integrator, options, film);
  const Image mean = film.mean(), var = film.varianceOfMean();
  // The centre pixels see only the sphere.
  for (int y = 5; y < 7; ++y)
    for (int x = 5; x < 7; ++x)
      EXPECT_NEAR(mean.at(x, y).x, kAlbedo, test::kSigmas * std::sqrt(var.at(x, y).x) + 1e-4)
          << x << "," << y;
  EXPECT_NEAR(mean.at(0, 0).x, 1.0f, 1e-5f);  // a corner sees the map itself
}

TEST(Environment, CommandLineEnvOption) {
  test::TempDir dir;
  const std::string scene = dir.write("s.json", R"({"image": {"width": 4, "height": 4},
    "camera": {"origin": [0, 0, 5], "target": [0, 0, 0]},
    "materials": {"grey": {"type": "diffuse", "reflectance": 0.5}},
    "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 0.1, "material": "grey"}]})");
  ASSERT_EQ(
      test::runEmber("render '" + scene + "' -o '" + dir.file("c.exr") + "' --env 0.25 --spp 2 -q").exitCode,
      0);
  EXPECT_NEAR(readImageRgb(dir.file("c.exr")).at(0, 0).x, 0.25f, 1e-6f);
  Image map(8, 4);
  for (float& v : map.rgb) v = 2.0f;
  writeExr(dir.file("map.exr"), map);
  ASSERT_EQ(test::runEmber("render '" + scene + "' -o '" + dir.file("m.exr") + "' --env '" +
                           dir.file("map.exr") + "' --spp 2 -q")
                .exitCode,
            0);
  EXPECT_NEAR(readImageRgb(dir.file("m.exr")).at(0, 0).x, 2.0f, 1e-5f);
  EXPECT_NE(test::runEmber("render '" + scene + "' -o '" + dir.file("x.exr") + "' --env '" +
                           dir.file("none.exr") + "' -q")
                .exitCode,
            0);
  EXPECT_NE(test::runEmber("render '" + scene + "' -o '" + dir.file("x.exr") + "' --env 1,2 -q").exitCode, 0);
  EXPECT_FALSE(std::filesystem::exists(dir.file("x.exr")));
}

}  // namespace
}  // namespace ember
