// Whole images against the Mitsuba 3 references (tests/data/<scene>/reference.exr, 8192 spp, with
// per-pixel standard errors in stderr.exr). Each scene is rendered twice with independent seeds;
// every 16x16 block mean and the whole-image mean per channel are z-tested against the reference,
// the variance coming from the renders' own per-pixel sample variances plus the reference's
// stderr^2, at a family-wise level of 1% (Sidak-corrected). The two renders are also z-tested
// against each other, which checks that the variance estimate itself is right. Every pixel and
// channel is z-tested on its own as well (io/image_metrics.h, variances pooled over 5x5 pixels).
// The power tests change the scene slightly (a light 2x or 2% brighter, a point light 2% brighter,
// the white albedo 1% higher, swapped wall colours, a moved sphere) and require the comparison to
// fail. The Sobol sampler is checked against the references too (conservatively: its samples are
// not independent, so their sample variance overestimates the noise).
#include "accel/sphere.h"
#include "materials/lambertian.h"
#include "reference_comparison.h"
#include "renderer/path_integrator.h"
#include "renderer/render.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <functional>

namespace ember {
namespace {

constexpr int kSpp = 64;
constexpr int kBlock = 16;
constexpr double kAlpha = 0.01;

using test::average;
using test::describe;
using test::loadReference;
using test::Reference;
using test::Rendered;

Rendered renderScene(const std::string& name, uint64_t seed, int spp,
                     const std::function<void(Scene&)>& mutate = {},
                     SamplerType sampler = SamplerType::Independent) {
  return test::renderFile(test::sourcePath("scenes/" + name + ".json"), seed, spp, mutate, sampler);
}

class ReferenceImage : public ::testing::TestWithParam<std::string> {};

TEST_P(ReferenceImage, MatchesMitsubaWithinNoise) {
  const std::string name = GetParam();
  const Rendered a = renderScene(name, 1, kSpp);
  const Rendered b = renderScene(name, 2, kSpp);

  // The two seeds against each other: validates the variance estimate.
  const BlockZTestResult selfCheck = blockZTest(a.mean, a.variance, b.mean, b.variance, kBlock, kAlpha);
  EXPECT_TRUE(selfCheck.passes()) << "seed 1 vs seed 2: " << describe(selfCheck);

  const Reference ref = loadReference(name);
  const Rendered both = average(a, b);
  const BlockZTestResult r = blockZTest(both.mean, both.variance, ref.mean, ref.variance, kBlock, kAlpha);
  EXPECT_TRUE(r.passes()) << name << " vs reference: " << describe(r);
  std::printf("[ %s ] %s\n", name.c_str(), describe(r).c_str());

  // Every pixel and channel on its own (as `ember compare --variance --ref-stderr` does).
  Image refStderr = ref.variance;
  for (float& v : refStderr.rgb) v = std::sqrt(v);
  const PixelZTest z = pixelZTest(both.mean, both.variance, ref.mean, refStderr, kAlpha);
  EXPECT_TRUE(z.passed()) << name << ": " << z.rejected << " of " << z.tests
                          << " pixel-channels beyond |z| > " << z.threshold << ", max |z| " << z.maxAbsZ;
  std::printf("[ %s ] per-pixel z-test: %zu of %zu rejected (|z| > %.3f), max |z| %.3f\n", name.c_str(),
              z.rejected, z.tests, z.threshold, z.maxAbsZ);
}

// The Sobol sampler's samples within a pixel are negatively correlated, so the sample variance
// overestimates the variance of the pixel mean: the same z-tests are conservative here, and still
// catch any bias beyond the (larger) noise bound.
TEST_P(ReferenceImage, SobolSamplerMatchesMitsuba) {
  const std::string name = GetParam();
  const Rendered a = renderScene(name, 1, kSpp, {}, SamplerType::Sobol);
  const Rendered b = renderScene(name, 2, kSpp, {}, SamplerType::Sobol);
  const Reference ref = loadReference(name);
  const Rendered both = average(a, b);
  const BlockZTestResult r = blockZTest(both.mean, both.variance, ref.mean, ref.variance, kBlock, kAlpha);
  EXPECT_TRUE(r.passes()) << name << " (sobol) vs reference: " << describe(r);
  std::printf("[ %s, sobol ] %s\n", name.c_str(), describe(r).c_str());
}

INSTANTIATE_TEST_SUITE_P(SharedScenes, ReferenceImage,
                         ::testing::Values("cornell-area", "cornell-point", "shapes", "textured"),
                         [](const auto& info) { return test::testName(info.param); });

// The other two estimators of direct light (renderer/strategy.h) are unbiased too, so they must
// match the same references. BSDF sampling alone cannot reach cornell-point's point light.
struct StrategyCase {
  std::string scene;
  Strategy strategy;
};

void PrintTo(const StrategyCase& c, std::ostream* os) {
  *os << c.scene << ", " << strategyName(c.strategy);
}

class StrategyReference : public ::testing::TestWithParam<StrategyCase> {};

TEST_P(StrategyReference, MatchesMitsubaWithinNoise) {
  const auto& [name, strategyBinding] = GetParam();
  const Strategy strategy = strategyBinding;  // clang 14 cannot capture structured bindings
  const auto set = [strategy](Scene& s) { s.settings.strategy = strategy; };
  const Rendered both = average(renderScene(name, 1, kSpp, set), renderScene(name, 2, kSpp, set));
  const Reference ref = loadReference(name);
  const BlockZTestResult r = blockZTest(both.mean, both.variance, ref.mean, ref.variance, kBlock, kAlpha);
  const std::string label = name + ", " + std::string(strategyName(strategy));
  EXPECT_TRUE(r.passes()) << label << " vs reference: " << describe(r);
  std::printf("[ %s ] %s\n", label.c_str(), describe(r).c_str());
}

INSTANTIATE_TEST_SUITE_P(
    SharedScenes, StrategyReference,
    ::testing::Values(StrategyCase{"cornell-area", Strategy::Bsdf},
                      StrategyCase{"cornell-area", Strategy::Light},
                      StrategyCase{"cornell-point", Strategy::Light}, StrategyCase{"shapes", Strategy::Bsdf},
                      StrategyCase{"shapes", Strategy::Light}, StrategyCase{"textured", Strategy::Bsdf},
                      StrategyCase{"textured", Strategy::Light}),
    [](const auto& info) {
      return test::testName(info.param.scene + "_" + std::string(strategyName(info.param.strategy)));
    });

// --- the comparison must be able to fail ----------------------------------------------------

BlockZTestResult compareMutated(const std::string& name, const std::function<void(Scene&)>& mutate) {
  const Rendered a = renderScene(name, 1, kSpp, mutate);
  const Rendered b = renderScene(name, 2, kSpp, mutate);
  const Reference ref = loadReference(name);
  const Rendered both = average(a, b);
  const BlockZTestResult r = blockZTest(both.mean, both.variance, ref.mean, ref.variance, kBlock, kAlpha);
  std::printf("[ %s, changed ] %s\n", name.c_str(), describe(r).c_str());
  return r;
}

Scene::ShapeEntry& shapeNamed(Scene& scene, const std::string& name) {
  for (auto& s : scene.shapes)
    if (s.name == name) return s;
  throw std::runtime_error("no shape " + name);
}

// Renders stopped by a relative-error target (--until-relerr, RenderOptions::targetRelativeError)
// still agree with the references: the pass they stop at depends on their own noise, which must
// not bias the image. Two seeds, each stopped at 0.07 (about 60 spp), z-tested as above.
TEST(ReferenceImageStopping, RelativeErrorTargetStaysUnbiased) {
  for (const std::string name : {"cornell-area", "shapes"}) {
    Scene scene = loadJsonScene(test::sourcePath("scenes/" + name + ".json"));
    scene.build();
    const std::unique_ptr<Integrator> integrator = makeIntegrator(scene.settings, Kernel::Wave);
    Rendered runs[2];
    for (int k = 0; k < 2; ++k) {
      Film film(scene.settings.width, scene.settings.height);
      RenderOptions options;
      options.spp = 4096;
      options.seed = uint64_t(k + 1);
      options.targetRelativeError = 0.07;
      const RenderStats stats = render(scene, *integrator, options, film);
      EXPECT_TRUE(stats.converged) << name;
      EXPECT_EQ(stats.nonFinite, 0u) << name;
      runs[k] = {film.mean(), film.varianceOfMean()};
      std::printf("[ %s ] seed %d stopped at %d spp, estimated relative error %.4f\n", name.c_str(), k + 1,
                  stats.sppDone, stats.relativeError);
    }
    const Reference ref = loadReference(name);
    const Rendered both = average(runs[0], runs[1]);
    const BlockZTestResult r = blockZTest(both.mean, both.variance, ref.mean, ref.variance, kBlock, kAlpha);
    EXPECT_TRUE(r.passes()) << name << " vs reference: " << describe(r);
  }
}

// Adaptive sampling (renderer/adaptive.h): each pixel's sample count comes from its neighbours'
// pilot, so pixels take from 16 to hundreds of samples and every one must stay unbiased. Four
// seeds at a target of 0.07, averaged and z-tested as above with each pixel's own variance. (Two
// runs were not enough: a pixel left at 16 samples that missed a rare bright path reports too
// small a variance, and one block in three runs failed the test without any bias. A budget taken
// from the pixel's own pilot, which is biased, fails it by 50 blocks and an image-mean z of -15.)
TEST(ReferenceImageStopping, AdaptiveSamplingStaysUnbiased) {
  for (const std::string name : {"cornell-area", "shapes"}) {
    Scene scene = loadJsonScene(test::sourcePath("scenes/" + name + ".json"));
    scene.build();
    const std::unique_ptr<Integrator> integrator = makeIntegrator(scene.settings, Kernel::Wave);
    Rendered runs[4];
    for (int k = 0; k < 4; ++k) {
      Film film(scene.settings.width, scene.settings.height);
      RenderOptions options;
      options.spp = 4096;
      options.seed = uint64_t(k + 1);
      options.targetRelativeError = 0.07;
      options.adaptive = true;
      const RenderStats stats = render(scene, *integrator, options, film);
      EXPECT_TRUE(stats.converged) << name;
      const auto [fewest, most] = std::minmax_element(film.counts().begin(), film.counts().end());
      EXPECT_EQ(*fewest, 16u) << name;
      EXPECT_GT(*most, 64u) << name;
      runs[k] = {film.mean(), film.varianceOfMean()};
      std::printf("[ %s ] seed %d: pixels took %u to %u samples\n", name.c_str(), k + 1, *fewest, *most);
    }
    const Reference ref = loadReference(name);
    const Rendered both = average(average(runs[0], runs[1]), average(runs[2], runs[3]));
    const BlockZTestResult r = blockZTest(both.mean, both.variance, ref.mean, ref.variance, kBlock, kAlpha);
    EXPECT_TRUE(r.passes()) << name << " vs reference: " << describe(r);
  }
}

TEST(ReferenceImagePower, FailsWhenTheLightIsTwiceAsBright) {
  const auto r = compareMutated("cornell-area", [](Scene& s) { shapeNamed(s, "light").emission *= 2.0f; });
  EXPECT_FALSE(r.passes()) << describe(r);
}

TEST(ReferenceImagePower, FailsWhenWallColoursAreSwapped) {
  const auto r = compareMutated("shapes", [](Scene& s) {
    std::swap(shapeNamed(s, "left_wall").material, shapeNamed(s, "right_wall").material);
  });
  EXPECT_FALSE(r.passes()) << describe(r);
}

TEST(ReferenceImagePower, FailsWhenASphereMoves) {
  const auto r = compareMutated("textured", [](Scene& s) {
    auto& sphere = shapeNamed(s, "sphere");
    const auto* old = static_cast<const Sphere*>(sphere.shape.get());
    sphere.shape = std::make_unique<Sphere>(old->center() + Vec3(0.03f, 0.0f, 0.0f), old->radius());
  });
  EXPECT_FALSE(r.passes()) << describe(r);
}

TEST(ReferenceImagePower, FailsWhenTheAreaLightIsTwoPercentBrighter) {
  const auto r = compareMutated("cornell-area", [](Scene& s) { shapeNamed(s, "light").emission *= 1.02f; });
  EXPECT_FALSE(r.passes()) << describe(r);
}

TEST(ReferenceImagePower, FailsWhenThePointLightIsTwoPercentBrighter) {
  const auto r = compareMutated("cornell-point", [](Scene& s) {
    ASSERT_EQ(s.lights.size(), 1u);
    s.lights[0] = std::make_unique<PointLight>(Vec3(0.0f, 1.7f, 0.0f), Color(3.0f * 1.02f));
  });
  EXPECT_FALSE(r.passes()) << describe(r);
}

TEST(ReferenceImagePower, FailsWhenTheWhiteAlbedoChangesByOnePercent) {
  const auto r = compareMutated("shapes", [](Scene& s) {
    const Material* whiter = s.addMaterial(
        "whiter", std::make_unique<Lambertian>(std::make_shared<ConstantTexture>(Color(0.75f * 1.01f))));
    for (const char* wall : {"floor", "ceiling", "back_wall"}) shapeNamed(s, wall).material = whiter;
  });
  EXPECT_FALSE(r.passes()) << describe(r);
}

}  // namespace
}  // namespace ember
