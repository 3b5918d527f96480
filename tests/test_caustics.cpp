// The caustic tracer's deterministic parts (renderer/caustic_tracer.h, packet/caustic_wave.h):
// splats summed in fixed point whatever the order, when the tracer runs, the camera projection
// its connections use, and renders that stay bit-identical for any kernel, thread count and pass
// size with light tracing on. Its estimates are tested in test_caustic_estimators.cpp.
#include "io/scene_loader.h"
#include "packet/wave_integrator.h"
#include "renderer/render.h"

#include <gtest/gtest.h>

#include "test_paths.h"

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

namespace ember {
namespace {

Scene loadSmall(const std::string& name, int width, int height) {
  Scene scene = loadScene(test::sourcePath("scenes/" + name + ".json"));
  scene.settings.width = width;
  scene.settings.height = height;
  scene.build();
  return scene;
}

Film renderWith(const Scene& scene, Kernel kernel, int threads, int spp, int passSpp,
                PathStats* paths = nullptr) {
  const std::unique_ptr<Integrator> integrator = makeIntegrator(scene.settings, kernel);
  Film film(scene.settings.width, scene.settings.height);
  RenderOptions options;
  options.spp = spp;
  options.passSpp = passSpp;
  options.seed = 3;
  options.sampler = scene.settings.sampler;
  options.threads = threads;
  const RenderStats stats = render(scene, *integrator, options, film);
  if (paths) *paths = stats.paths;
  return film;
}

bool identical(const Film& a, const Film& b) {
  const Image ma = a.mean(), mb = b.mean(), va = a.varianceOfMean(), vb = b.varianceOfMean();
  return ma.rgb.size() == mb.rgb.size() &&
         std::memcmp(ma.rgb.data(), mb.rgb.data(), ma.rgb.size() * sizeof(float)) == 0 &&
         std::memcmp(va.rgb.data(), vb.rgb.data(), va.rgb.size() * sizeof(float)) == 0;
}

TEST(CausticSplats, SumsDoNotDependOnTheOrderOfTheAdditions) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> value(0.0f, 1.0f);
  std::vector<Color> splats;
  for (int i = 0; i < 1000; ++i) {
    const float scale = std::pow(10.0f, 6.0f * value(rng) - 4.0f);  // 1e-4 .. 1e2
    splats.emplace_back(scale * value(rng), scale * value(rng), scale * value(rng));
  }
  CausticSplats forward, backward;
  forward.reset(2, 3, 2);
  backward.reset(2, 3, 2);
  for (size_t i = 0; i < splats.size(); ++i) ASSERT_TRUE(forward.add(1, 2, 1, splats[i]));
  for (size_t i = splats.size(); i-- > 0;) ASSERT_TRUE(backward.add(1, 2, 1, splats[i]));
  const Color f = forward.at(1, 2, 1), b = backward.at(1, 2, 1);
  EXPECT_EQ(std::memcmp(&f, &b, sizeof f), 0);
  double exact = 0.0;
  for (const Color& c : splats) exact += double(c.x);
  EXPECT_NEAR(double(f.x), exact, 1e-5 * exact);
  // The other cells stay zero.
  EXPECT_EQ(forward.at(0, 2, 1), Color(0.0f));
  EXPECT_EQ(forward.at(1, 1, 1), Color(0.0f));
}

TEST(CausticSplats, RefusesNonFiniteAndHugeValues) {
  CausticSplats s;
  s.reset(1, 2, 2);
  const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
  EXPECT_FALSE(s.add(0, 0, 0, Color(inf, 0.0f, 0.0f)));
  EXPECT_FALSE(s.add(0, 0, 0, Color(0.0f, nan, 0.0f)));
  EXPECT_FALSE(s.add(0, 0, 0, Color(0.0f, 0.0f, 1e30f)));
  EXPECT_FALSE(s.add(0, 0, 0, Color(0.0f, 0.0f, 5e9f)));  // above 2^32: its pixel could wrap
  EXPECT_EQ(s.at(0, 0, 0), Color(0.0f));
  EXPECT_TRUE(s.add(0, 0, 0, Color(-1.5f, 0.25f, 3.0f)));
  EXPECT_EQ(s.at(0, 0, 0), Color(-1.5f, 0.25f, 3.0f));  // exact in 2^-24 steps
  s.reset(1, 2, 2);
  EXPECT_EQ(s.at(0, 0, 0), Color(0.0f));
}

TEST(CausticTracer, RunsWithCastersAnyFiniteLightAndAPerspectiveCamera) {
  EXPECT_TRUE(loadSmall("cornell-area", 8, 8).causticTracer().enabled());   // mirror, glass, quad light
  EXPECT_TRUE(loadSmall("cornell-point", 8, 8).causticTracer().enabled());  // mirror, glass, point light
  EXPECT_FALSE(loadSmall("shapes", 8, 8).causticTracer().enabled());        // nothing specular
  Scene scene = loadScene(test::sourcePath("scenes/cornell-area.json"));
  scene.cameraParams.projection = Projection::Orthographic;
  scene.build();
  EXPECT_FALSE(scene.causticTracer().enabled());
  // Only the lights it traces are left to it by the path tracer.
  const Scene area = loadSmall("cornell-area", 8, 8);
  size_t traced = 0;
  for (const auto& light : area.lights) traced += light->causticTraced ? 1 : 0;
  EXPECT_EQ(traced, 1u);
  EXPECT_EQ(area.causticTracer().casters().size(), 2u);
}

TEST(Camera, ProjectInvertsGenerateRay) {
  CameraParams params;
  params.origin = Vec3(0.3f, 1.1f, 3.0f);
  params.target = Vec3(-0.2f, 0.8f, 0.0f);
  params.fovYDeg = 47.0f;
  const Camera camera(params, 64, 40);
  for (float x : {0.5f, 10.25f, 63.5f})
    for (float y : {0.25f, 20.0f, 39.75f}) {
      const Ray ray = camera.generateRay(x, y);
      Vec2 raster;
      float cosTheta;
      ASSERT_TRUE(camera.project(ray.origin + 2.5f * ray.dir, raster, cosTheta));
      EXPECT_NEAR(raster.x, x, 1e-3f);
      EXPECT_NEAR(raster.y, y, 1e-3f);
      EXPECT_NEAR(cosTheta, glm::dot(ray.dir, glm::normalize(params.target - params.origin)), 1e-6f);
    }
  Vec2 raster;
  float cosTheta;
  EXPECT_FALSE(camera.project(params.origin + Vec3(0.0f, 0.0f, 1.0f), raster, cosTheta));  // behind
  EXPECT_FALSE(camera.project(camera.generateRay(-0.5f, 3.0f).dir * 2.0f + params.origin, raster, cosTheta));
}

// Light tracing on: the same image for every kernel, thread count and pass size, and the light
// paths' rays are counted.
TEST(CausticTracer, SameImageForAnyKernelThreadsAndPassSize) {
  const Scene scene = loadSmall("cornell-area", 37, 29);
  ASSERT_TRUE(scene.causticTracer().enabled());
  PathStats withLight;
  const Film reference = renderWith(scene, Kernel::Scalar, 1, 6, 4, &withLight);
  EXPECT_TRUE(identical(reference, renderWith(scene, Kernel::Wave, 2, 6, 4))) << "wave";
  EXPECT_TRUE(identical(reference, renderWith(scene, Kernel::Wave, 1, 6, 1))) << "pass size 1";
  EXPECT_TRUE(identical(reference, renderWith(scene, Kernel::Wave, 2, 6, 6))) << "one pass";

  Scene off = loadScene(test::sourcePath("scenes/cornell-area.json"));
  off.settings.width = 37;
  off.settings.height = 29;
  off.settings.traceCaustics = false;
  off.build();
  PathStats pathOnly;
  const Film without = renderWith(off, Kernel::Wave, 2, 6, 4, &pathOnly);
  EXPECT_FALSE(identical(reference, without));
  EXPECT_GT(withLight.rays, pathOnly.rays);  // the light paths' rays are counted too
  EXPECT_GT(withLight.shadowRays, pathOnly.shadowRays);
}

// The light wave against the scalar driver where its steps branch: depth limits that stop the
// BSDF sample (max_depth 3 and 4), Russian roulette from the first segments, and the independent
// sampler, whose requests never take the Sobol lanes.
TEST(CausticTracer, SameImageForAnyKernelAtShortDepthsAndWithEverySampler) {
  for (const SamplerType sampler : {SamplerType::Sobol, SamplerType::Independent}) {
    for (const int maxDepth : {3, 4, -1}) {
      Scene scene = loadScene(test::sourcePath("scenes/cornell-area.json"));
      scene.settings.width = 23;
      scene.settings.height = 19;
      scene.settings.sampler = sampler;
      scene.settings.maxDepth = maxDepth;
      scene.settings.rrDepth = 2;
      scene.build();
      ASSERT_TRUE(scene.causticTracer().enabled());
      const std::string what = std::string(sampler == SamplerType::Sobol ? "sobol" : "independent") +
                               ", max depth " + std::to_string(maxDepth);
      const Film reference = renderWith(scene, Kernel::Scalar, 1, 4, 2);
      EXPECT_TRUE(identical(reference, renderWith(scene, Kernel::Wave, 2, 4, 2))) << what;
    }
  }
}

}  // namespace
}  // namespace ember
