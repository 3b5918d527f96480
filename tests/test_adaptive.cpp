// Adaptive sampling (renderer/adaptive.h): the budget rule against its closed form, a pixel's
// budget blind to its own samples, and the render: budgets from the pilot, counts within them,
// the same film from both drivers, any thread count and a resume, through checkpoints too; the
// command line's checks, spp layer and merge.
#include "checkpoint/checkpoint_file.h"
#include "io/image_io.h"
#include "io/scene_loader.h"
#include "packet/wave_integrator.h"
#include "renderer/adaptive.h"
#include "renderer/render.h"

#include <gtest/gtest.h>

#include "cli_runner.h"
#include "test_paths.h"

#include <cmath>
#include <filesystem>

namespace ember {
namespace {

// A film whose pixel i holds n samples of mean m and per-sample variance s2[i] (all channels).
Film filmWith(int w, int h, uint32_t n, double m, const std::vector<double>& s2) {
  Film film(w, h);
  for (size_t i = 0; i < film.pixelCount(); ++i) {
    film.counts()[i] = n;
    film.sums()[i] = glm::dvec3(n * m);
    film.sumsOfSquares()[i] = glm::dvec3(s2[i] * (n - 1.0) + n * m * m);
  }
  return film;
}

TEST(AdaptiveBudgets, FollowTheirClosedForm) {
  // 3x1 pixels, mean 1: relative per-sample variances s2 / 1.01.
  const std::vector<double> s2 = {0.0101 * 4, 0.0101 * 16, 0.0101 * 64};
  const Film film = filmWith(3, 1, 16, 1.0, s2);
  const std::vector<double> v = relativeSampleVariance(film);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(v[size_t(i)], s2[size_t(i)] / 1.01, 1e-12);
  const double sigma[3] = {0.2, 0.4, 0.8};
  const double target = 0.01;
  const std::vector<uint32_t> budget = adaptiveBudgets(film, target, 16, 100000);
  // n_i = ceil(mean of the neighbours' sigma x mean of the other pixels' sigma / target^2).
  const double expected[3] = {
      std::ceil(sigma[1] * (sigma[1] + sigma[2]) / 2 / (target * target)),
      std::ceil((sigma[0] + sigma[2]) / 2 * (sigma[0] + sigma[2]) / 2 / (target * target)),
      std::ceil(sigma[1] * (sigma[0] + sigma[1]) / 2 / (target * target))};
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(double(budget[size_t(i)]), expected[i], 1.0) << i;
  // Clamped to [pilot, cap].
  const std::vector<uint32_t> capped = adaptiveBudgets(film, target, 16, 500);
  for (uint32_t b : capped) EXPECT_LE(b, 500u);
  const std::vector<uint32_t> floor = adaptiveBudgets(film, 10.0, 16, 500);
  for (uint32_t b : floor) EXPECT_EQ(b, 16u);
  // No neighbours: the cap.
  EXPECT_EQ(adaptiveBudgets(filmWith(1, 1, 16, 1.0, {1.0}), target, 16, 500)[0], 500u);
}

// The unbiasedness argument: pixel i's budget reads no sample of pixel i.
TEST(AdaptiveBudgets, APixelsBudgetIgnoresItsOwnSamples) {
  std::vector<double> s2(25);
  for (size_t i = 0; i < s2.size(); ++i) s2[i] = 0.01 * double(1 + (i * 7) % 5);
  Film film = filmWith(5, 5, 16, 0.5, s2);
  const std::vector<uint32_t> before = adaptiveBudgets(film, 0.02, 16, 1 << 20);
  const size_t centre = 12;
  film.sumsOfSquares()[centre] *= 50.0;  // a very noisy pilot at the centre
  film.sums()[centre] *= 0.1;
  const std::vector<uint32_t> after = adaptiveBudgets(film, 0.02, 16, 1 << 20);
  EXPECT_EQ(after[centre], before[centre]);
  EXPECT_GT(after[centre - 1], before[centre - 1]);  // its neighbours see it
}

Scene cornell() {
  Scene scene = loadScene(test::sourcePath("scenes/cornell-area.json"));
  scene.settings.width = 40;
  scene.settings.height = 32;
  scene.build();
  return scene;
}

Film renderAdaptive(const Scene& scene, Kernel kernel, int threads, int passes = -1,
                    const Film* from = nullptr, int passesDone = 0) {
  const std::unique_ptr<Integrator> integrator = makeIntegrator(scene.settings, kernel);
  Film film = from ? *from : Film(scene.settings.width, scene.settings.height);
  RenderOptions options;
  options.spp = passes > 0 ? passes * 4 : 1024;
  options.seed = 5;
  options.threads = threads;
  options.targetRelativeError = 0.1;
  options.adaptive = true;
  options.passesDone = passesDone;
  render(scene, *integrator, options, film);
  return film;
}

TEST(AdaptiveRender, CountsFollowTheBudgetsAndAreExactUnderAnyRun) {
  const Scene scene = cornell();
  const Film wave = renderAdaptive(scene, Kernel::Wave, 2);
  ASSERT_EQ(wave.budgets().size(), wave.pixelCount());
  uint32_t most = 0;
  for (size_t i = 0; i < wave.pixelCount(); ++i) {
    EXPECT_EQ(wave.counts()[i], wave.budgets()[i]) << i;  // no non-finite samples here
    EXPECT_GE(wave.counts()[i], 16u);
    most = std::max(most, wave.counts()[i]);
  }
  EXPECT_GT(most, 32u);
  const Film scalar = renderAdaptive(scene, Kernel::Scalar, 1);
  EXPECT_EQ(scalar.sums(), wave.sums());
  EXPECT_EQ(scalar.counts(), wave.counts());
  // Stopped inside the pilot (3 passes of 4) and after it (6 passes), then resumed.
  for (int stop : {3, 6}) {
    const Film part = renderAdaptive(scene, Kernel::Wave, 1, stop);
    const Film resumed = renderAdaptive(scene, Kernel::Wave, 2, -1, &part, stop);
    EXPECT_EQ(resumed.sums(), wave.sums()) << stop;
    EXPECT_EQ(resumed.counts(), wave.counts()) << stop;
    EXPECT_EQ(resumed.budgets(), wave.budgets()) << stop;
  }
}

std::string quoted(const std::string& s) {
  return "'" + s + "'";
}
const std::string kScene = test::sourcePath("scenes/cornell-area.json");
const std::string kSmall = " --width 24 --height 16 -q";

TEST(AdaptiveCli, CheckpointResumeSppLayerMergeAndMisuse) {
  test::TempDir dir;
  const std::string whole = dir.file("w.exr"), ckpt = dir.file("a.ckpt"), part = dir.file("p.exr");
  ASSERT_EQ(test::runEmber("render " + quoted(kScene) + " -o " + quoted(whole) + kSmall +
                           " --until-relerr 0.1 --adaptive --spp 1024")
                .exitCode,
            0);
  const ExrChannels w = readExrChannels(whole);
  ASSERT_TRUE(w.has("spp"));
  std::string adaptive;
  for (const auto& [k, v] : w.metadata)
    if (k == "ember:adaptive") adaptive = v;
  EXPECT_EQ(adaptive, "0.100000");
  // Killed after 24 spp (past the pilot), then resumed: the same file.
  ASSERT_EQ(test::runEmber("render " + quoted(kScene) + " -o " + quoted(part) + kSmall +
                           " --until-relerr 0.1 --adaptive --spp 24 --checkpoint " + quoted(ckpt))
                .exitCode,
            0);
  const test::CliResult resumed = test::runEmber("render --resume " + quoted(ckpt) + " --spp 1024 -q");
  ASSERT_EQ(resumed.exitCode, 0) << resumed.output;
  const ExrChannels r = readExrChannels(part);
  for (const char* c : {"R", "G", "B", "spp"}) EXPECT_EQ(r.channels.at(c), w.channels.at(c)) << c;
  // The checkpoint says how it samples; the command line may not change that.
  EXPECT_EQ(test::runEmber("render --resume " + quoted(ckpt) + " --adaptive -q").exitCode, 1);
  EXPECT_EQ(test::runEmber("render --resume " + quoted(ckpt) + " --until-relerr 0.2 -q").exitCode, 1);
  // --adaptive needs its target.
  const std::string none = dir.file("none.exr");
  const test::CliResult noTarget =
      test::runEmber("render " + quoted(kScene) + " -o " + quoted(none) + kSmall + " --adaptive");
  EXPECT_EQ(noTarget.exitCode, 1);
  EXPECT_NE(noTarget.output.find("--until-relerr"), std::string::npos) << noTarget.output;
  EXPECT_FALSE(std::filesystem::exists(none));

  // Two adaptive renders of disjoint sample ranges merge by their spp layers.
  const std::string second = dir.file("s.exr"), merged = dir.file("m.exr");
  ASSERT_EQ(test::runEmber("render " + quoted(kScene) + " -o " + quoted(second) + kSmall +
                           " --until-relerr 0.1 --adaptive --spp 1024 --first-sample 1024")
                .exitCode,
            0);
  ASSERT_EQ(
      test::runEmber("merge " + quoted(whole) + " " + quoted(second) + " -o " + quoted(merged)).exitCode, 0);
  const ExrChannels s = readExrChannels(second), m = readExrChannels(merged);
  for (size_t i = 0; i < w.channels.at("R").size(); ++i) {
    const double n1 = w.channels.at("spp")[i], n2 = s.channels.at("spp")[i];
    EXPECT_EQ(m.channels.at("spp")[i], float(n1 + n2));
    const double expected = (n1 * w.channels.at("R")[i] + n2 * s.channels.at("R")[i]) / (n1 + n2);
    EXPECT_NEAR(m.channels.at("R")[i], expected, 1e-6 * std::max(1.0, std::abs(expected)));
  }
}

}  // namespace
}  // namespace ember
