// The renderer as a whole: thread-count independence, sample ranges that merge, non-finite samples
// dropped and counted, and closed-form answers: a convex Lambertian object under a uniform
// environment, a Lambertian plane under a point light, the white furnace (Le / (1 - rho)) and a
// plane on the axis of a disc light (its view factor).
#include "accel/box.h"
#include "accel/cylinder.h"
#include "accel/disc.h"
#include "accel/flipped_shape.h"
#include "accel/sphere.h"
#include "accel/triangle.h"
#include "io/scene_loader.h"
#include "materials/lambertian.h"
#include "materials/texture.h"
#include "renderer/path_integrator.h"
#include "renderer/render.h"

#include <glm/gtc/matrix_transform.hpp>
#include "test_fixtures.h"
#include "test_paths.h"

#include <gtest/gtest.h>

namespace ember {
namespace {

Image renderWith(const Scene& scene, int spp, int threads, uint64_t seed, uint64_t first = 0,
                 RenderStats* statsOut = nullptr, const Integrator* integrator = nullptr) {
  const PathIntegrator path(scene.settings);
  Film film(scene.settings.width, scene.settings.height);
  RenderOptions options;
  options.spp = spp;
  options.threads = threads;
  options.seed = seed;
  options.firstSample = first;
  const RenderStats stats = render(scene, integrator ? *integrator : path, options, film);
  if (statsOut) *statsOut = stats;
  return film.mean();
}

using test::renderFilm;

// A 10 x 10 quad at y = 0 facing +y: the receiving plane of the analytic lighting tests.
std::unique_ptr<Shape> floorQuad() {
  return std::make_unique<Quad>(
      std::array<Vec3, 4>{Vec3(-5, 0, 5), Vec3(5, 0, 5), Vec3(5, 0, -5), Vec3(-5, 0, -5)},
      std::array<Vec2, 4>{Vec2(0, 0), Vec2(1, 0), Vec2(1, 1), Vec2(0, 1)});
}

Scene smallCornell() {
  Scene scene = loadJsonScene(test::sourcePath("scenes/cornell-area.json"));
  scene.settings.width = 40;
  scene.settings.height = 30;  // not a multiple of the tile size
  scene.build();
  return scene;
}

TEST(Render, BitIdenticalForAnyThreadCount) {
  const Scene scene = smallCornell();
  const Image one = renderWith(scene, 8, 1, 7);
  const Image two = renderWith(scene, 8, 2, 7);
  const Image four = renderWith(scene, 8, 4, 7);
  EXPECT_EQ(one.rgb, two.rgb);
  EXPECT_EQ(one.rgb, four.rgb);
  const Image otherSeed = renderWith(scene, 8, 2, 8);
  EXPECT_NE(one.rgb, otherSeed.rgb);
}

TEST(Render, SampleRangesMergeIntoTheFullRender) {
  const Scene scene = smallCornell();
  const Image full = renderWith(scene, 8, 2, 3, 0);
  const Image first = renderWith(scene, 4, 2, 3, 0);
  const Image second = renderWith(scene, 4, 2, 3, 4);
  for (size_t i = 0; i < full.rgb.size(); ++i)
    ASSERT_NEAR(0.5f * (first.rgb[i] + second.rgb[i]), full.rgb[i], 1e-5f * (1.0f + full.rgb[i])) << i;
}

// Returns NaN for every third sample, infinity for every fifth, else 1.
class PoisonedIntegrator final : public Integrator {
 public:
  Color Li(const Scene&, Ray, Sampler& sampler, PathStats&) const override {
    const uint32_t r = uint32_t(sampler.get1D() * 15.0f) % 15;
    if (r % 3 == 0) return Color(NAN, 1.0f, 1.0f);
    if (r % 5 == 0) return Color(INFINITY);
    return Color(1.0f);
  }
};

TEST(Render, NonFiniteSamplesAreDroppedAndCounted) {
  const Scene scene = smallCornell();
  const PoisonedIntegrator poisoned;
  RenderStats stats;
  const Image img = renderWith(scene, 16, 2, 1, 0, &stats, &poisoned);
  EXPECT_GT(stats.nonFinite, stats.samples / 3);
  EXPECT_LT(stats.nonFinite, stats.samples * 2 / 3);
  for (float v : img.rgb) ASSERT_EQ(v, 1.0f);  // only the finite samples, each exactly 1
}

std::shared_ptr<const Texture> grey(float v) {
  return std::make_shared<ConstantTexture>(Color(v));
}

// A convex Lambertian object of albedo rho alone under a uniform environment of radiance 1
// reflects exactly rho (irradiance pi, BRDF rho / pi, nothing to interreflect with); the
// background is exactly 1. Pixel tolerances come from each pixel's own sample variance.
TEST(Render, ConvexObjectUnderUniformEnvironmentReflectsItsAlbedo) {
  constexpr float kAlbedo = 0.6f;
  std::vector<std::unique_ptr<Shape>> shapes;
  shapes.push_back(std::make_unique<Sphere>(Vec3(0.0f), 0.8f));
  shapes.push_back(
      std::make_unique<Box>(Vec3(0.0f), Vec3(0.9f), glm::mat3(glm::rotate(Mat4(1.0f), 0.5f, Vec3(1, 1, 0)))));
  shapes.push_back(std::make_unique<Cylinder>(Vec3(0.0f, -0.6f, 0.0f), Vec3(0.1f, 0.6f, 0.3f), 0.5f, true));
  for (auto& shape : shapes) {
    const std::string type(shape->typeName());
    Scene scene;
    scene.settings.width = 16;
    scene.settings.height = 16;
    scene.background = Color(1.0f);
    scene.cameraParams = CameraParams{Vec3(0.5f, 1.0f, 5.0f), Vec3(0), Vec3(0, 1, 0), 30.0f};
    const Material* m = scene.addMaterial("grey", std::make_unique<Lambertian>(grey(kAlbedo)));
    scene.shapes.push_back({type, std::move(shape), m, Color(0.0f)});
    scene.build();
    const Film film = renderFilm(scene, 128, 11);
    const Image mean = film.mean(), var = film.varianceOfMean();
    int inside = 0;
    for (int y = 0; y < 16; ++y)
      for (int x = 0; x < 16; ++x) {
        const float v = mean.at(x, y).x;
        const float sigma = std::sqrt(var.at(x, y).x);
        if (v == 1.0f && sigma == 0.0f) continue;  // background only
        // Silhouette pixels mix object and background: between rho and 1, within 5 sigma.
        EXPECT_GT(v, kAlbedo - 5.0f * sigma - 1e-6f) << type << " pixel " << x << "," << y;
        EXPECT_LT(v, 1.0f + 5.0f * sigma + 1e-6f) << type << " pixel " << x << "," << y;
        inside += std::abs(v - kAlbedo) < 5.0f * sigma + 1e-6f;
      }
    EXPECT_GT(inside, 20) << type;
  }
}

// Irradiance from a point light: L = rho / pi * I cos(theta) / r^2 on a Lambertian plane, seen by a
// narrow camera straight above the point of interest (direct light only: max depth 2).
TEST(Render, PlaneUnderPointLightMatchesAnalyticIrradiance) {
  constexpr float kAlbedo = 0.5f, kIntensity = 10.0f;
  const Vec3 light(0.3f, 2.0f, -0.2f);
  Scene scene;
  scene.settings.width = 1;
  scene.settings.height = 1;
  scene.settings.maxDepth = 2;
  scene.cameraParams = CameraParams{Vec3(0, 1, 0), Vec3(0, 0, 0), Vec3(0, 0, -1), 0.05f};
  const Material* m = scene.addMaterial("grey", std::make_unique<Lambertian>(grey(kAlbedo)));
  scene.shapes.push_back({"floor", floorQuad(), m, Color(0.0f)});
  scene.lights.push_back(std::make_unique<PointLight>(light, Color(kIntensity)));
  scene.build();
  const Image img = renderWith(scene, 64, 1, 5);
  const float r2 = glm::dot(light, light);
  const float cosTheta = light.y / std::sqrt(r2);
  const float expected = kAlbedo / kPi * kIntensity * cosTheta / r2;
  // The pixel footprint is ~1e-3 wide: the irradiance varies by far less than 1e-4 across it.
  EXPECT_NEAR(img.at(0, 0).x, expected, 1e-4f * expected);
}

// Paths end at a black texel after its emission (Material::absorbsAt), which must change nothing
// but the time: the image equals the one whose dark texels are 1e-30 instead, and whose paths go
// on from them with a throughput of 1e-30, up to those paths' 1e-30-sized contributions. Every
// surface gets the checkerboard, the light's too, so that emission at black texels counts as well.
TEST(Render, PathsEndingAtBlackTexelsLeaveTheImageAsItWas) {
  const auto renderChecker = [](float dark) {
    Scene scene = loadJsonScene(test::sourcePath("scenes/cornell-area.json"));
    scene.settings.width = 32;
    scene.settings.height = 24;
    const std::vector<Color> texels = {Color(dark), Color(0.8f), Color(0.8f), Color(dark)};
    auto texture = std::make_shared<ImageTexture>(2, 2, texels, TextureFilter::Nearest, TextureWrap::Repeat);
    EXPECT_EQ(texture->mayBeBlack(), dark == 0.0f);
    const Material* checker = scene.addMaterial("checker", std::make_unique<Lambertian>(std::move(texture)));
    for (Scene::ShapeEntry& shape : scene.shapes) shape.material = checker;
    scene.build();
    return renderFilm(scene, 16, 3).mean();
  };
  const Image ended = renderChecker(0.0f), continued = renderChecker(1e-30f);
  double sum = 0.0;
  for (int y = 0; y < ended.height; ++y)
    for (int x = 0; x < ended.width; ++x)
      for (int c = 0; c < 3; ++c) {
        const float a = ended.at(x, y)[c], b = continued.at(x, y)[c];
        ASSERT_NEAR(a, b, 1e-6f * std::max(1.0f, b)) << "pixel (" << x << ", " << y << ") channel " << c;
        sum += a;
      }
  EXPECT_GT(sum / (3.0 * ended.width * ended.height), 0.01);  // lit, not black everywhere
}

// Mean and standard error of the mean over all pixels of one channel.
struct ImageEstimate {
  double mean, stderr_;
};
ImageEstimate estimate(const Film& film) {
  const Image mean = film.mean(), var = film.varianceOfMean();
  double m = 0.0, v = 0.0;
  const double n = double(mean.width) * mean.height;
  for (int y = 0; y < mean.height; ++y)
    for (int x = 0; x < mean.width; ++x) {
      m += mean.at(x, y).x;
      v += var.at(x, y).x;
    }
  return {m / n, std::sqrt(v) / n};
}

// White furnace (PBRT4's analytic integrator test; Nori's furnace scene): the camera inside a
// closed sphere of albedo rho whose inner surface emits Le sees L = Le / (1 - rho) in every
// direction: the geometric series of bounces, each of which emits Le and reflects rho of the rest.
TEST(Render, WhiteFurnaceConvergesToTheGeometricSeries) {
  for (float rho : {0.3f, 0.5f, 0.8f}) {
    constexpr float kLe = 1.0f;
    Scene scene;
    scene.settings.width = 16;
    scene.settings.height = 16;
    scene.cameraParams = CameraParams{Vec3(0.1f, -0.2f, 0.3f), Vec3(1, 0, 0), Vec3(0, 1, 0), 90.0f};
    const Material* m = scene.addMaterial("grey", std::make_unique<Lambertian>(grey(rho)));
    scene.shapes.push_back({"furnace",
                            std::make_unique<FlippedShape>(std::make_unique<Sphere>(Vec3(0.0f), 1.0f)), m,
                            Color(kLe)});
    scene.build();
    RenderStats stats;
    const Film film = renderFilm(scene, 64, 3, &stats);
    EXPECT_EQ(stats.nonFinite, 0u);
    const ImageEstimate e = estimate(film);
    const double expected = kLe / (1.0 - rho);
    EXPECT_NEAR(e.mean, expected, 0.005 * expected) << "rho " << rho << ", stderr " << e.stderr_;
    EXPECT_NEAR(e.mean, expected, 5.0 * e.stderr_) << "rho " << rho;
  }
}

// On the axis of a disc light of radius R and radiance L at height h, a Lambertian plane of albedo
// rho receives E = pi L R^2 / (h^2 + R^2) and reflects rho E / pi (view-factor form of a disc,
// e.g. Howell's catalogue, configuration B-13). The MIS estimate must agree within its error.
TEST(Render, PlaneOnTheAxisOfADiscLightMatchesTheViewFactor) {
  constexpr float kAlbedo = 0.7f, kRadiance = 5.0f, kRadius = 0.5f, kHeight = 1.2f;
  Scene scene;
  scene.settings.width = 2;
  scene.settings.height = 2;
  scene.cameraParams = CameraParams{Vec3(2.0f, 0.8f, 0.0f), Vec3(0.0f), Vec3(0, 1, 0), 0.02f};
  const Material* m = scene.addMaterial("grey", std::make_unique<Lambertian>(grey(kAlbedo)));
  const Material* black = scene.addMaterial("black", std::make_unique<Lambertian>(grey(0.0f)));
  scene.shapes.push_back({"floor", floorQuad(), m, Color(0.0f)});
  scene.shapes.push_back({"light", std::make_unique<Disc>(Vec3(0.0f, kHeight, 0.0f), Vec3(0, -1, 0), kRadius),
                          black, Color(kRadiance)});
  scene.build();
  const Film film = renderFilm(scene, 4096, 9);
  const ImageEstimate e = estimate(film);
  const double expected = kAlbedo * kRadiance * kRadius * kRadius / (kHeight * kHeight + kRadius * kRadius);
  // The pixel footprint spans ~1e-3 around the axis, where the irradiance is flat to ~1e-6.
  EXPECT_NEAR(e.mean, expected, 5.0 * e.stderr_ + 1e-5 * expected) << "stderr " << e.stderr_;
  EXPECT_LT(e.stderr_, 0.01 * expected);  // and the estimate is precise enough to mean something
}

}  // namespace
}  // namespace ember
