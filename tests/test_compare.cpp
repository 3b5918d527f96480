// `ember compare`: exit codes (0 pass, 1 fail, 2 bad input), metrics on known images, the per-pixel
// z-test's power, and FLIP's basic properties.
#include "cli_runner.h"
#include "io/flip.h"
#include "io/image_io.h"
#include "io/image_metrics.h"

#include <gtest/gtest.h>

namespace ember {
namespace {

using test::TempDir;

Image constantImage(int w, int h, const Color& c) {
  Image img(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) img.set(x, y, c);
  return img;
}

TEST(CompareMetrics, KnownValues) {
  const Image ref = constantImage(4, 4, Color(0.5f));
  const Image img = constantImage(4, 4, Color(0.6f, 0.5f, 0.3f));
  const ImageMetrics m = computeMetrics(img, ref);
  EXPECT_NEAR(m.mae[0], 0.1, 1e-6);
  EXPECT_NEAR(m.mae[1], 0.0, 1e-9);
  EXPECT_NEAR(m.rmse[2], 0.2, 1e-6);
  EXPECT_NEAR(m.relmse[0], 0.01 / (0.25 + 0.01), 1e-6);
  EXPECT_NEAR(m.relmseAll, (0.01 / 0.26 + 0.0 + 0.04 / 0.26) / 3.0, 1e-6);
  EXPECT_NEAR(m.meanImage[2], 0.3, 1e-6);
}

TEST(CompareZTest, AcceptsNoiseAndRejectsAShift) {
  // Images differing by exactly 3 standard errors everywhere pass (|z| = 3 < threshold); 7 fail.
  const Image ref = constantImage(32, 32, Color(1.0f));
  const Image stderrImg = constantImage(32, 32, Color(0.03f));
  const Image var = constantImage(32, 32, Color(0.04f * 0.04f));
  const float sigma = 0.05f;  // sqrt(0.03^2 + 0.04^2)
  const PixelZTest pass = pixelZTest(constantImage(32, 32, Color(1.0f + 3.0f * sigma)), var, ref, stderrImg);
  EXPECT_TRUE(pass.passed());
  EXPECT_NEAR(pass.maxAbsZ, 3.0, 1e-4);
  const PixelZTest fail = pixelZTest(constantImage(32, 32, Color(1.0f + 7.0f * sigma)), var, ref, stderrImg);
  EXPECT_FALSE(fail.passed());
  EXPECT_EQ(fail.rejected, fail.tests);
  // Threshold: Sidak over 32*32*3 tests at alpha 0.01.
  EXPECT_NEAR(pass.threshold, 4.653, 0.002);  // P(|Z| > 4.653) = 3.27e-6 = 1 - 0.99^(1/3072)
}

TEST(CompareFlip, ZeroForIdenticalImagesAndLargeForOpposites) {
  Image a(24, 24);
  for (int y = 0; y < 24; ++y)
    for (int x = 0; x < 24; ++x) a.set(x, y, Color(float(x) / 23.0f, float(y) / 23.0f, 0.5f));
  EXPECT_NEAR(computeFlip(a, a).mean, 0.0, 1e-6);
  const double blackWhite =
      computeFlip(constantImage(24, 24, Color(0.0f)), constantImage(24, 24, Color(1.0f))).mean;
  EXPECT_GT(blackWhite, 0.9);
  EXPECT_LE(blackWhite, 1.0);
  // More difference, more error.
  const double small = computeFlip(a, constantImage(24, 24, Color(0.5f))).mean;
  Image b = a;
  for (float& v : b.rgb) v = std::min(1.0f, v * 1.02f);
  EXPECT_LT(computeFlip(a, b).mean, small);
}

// Agreement with NVIDIA's reference implementation (PyPI flip-evaluator 1.7, LDR mode, linear
// inputs, 67 ppd) on a pair the test builds itself: a horizontal 0..1 ramp against flat 0.5.
// benchmarks/validate_flip.py repeats this and three render-based pairs (all within 0.02%).
TEST(CompareFlip, MatchesTheReferenceImplementation) {
  Image ramp(256, 256);
  for (int y = 0; y < 256; ++y)
    for (int x = 0; x < 256; ++x) ramp.set(x, y, Color(float(x) / 255.0f));
  EXPECT_NEAR(computeFlip(ramp, constantImage(256, 256, Color(0.5f))).mean, 0.44934, 2e-4);
}

TEST(CompareCommand, ExitCodes) {
  TempDir dir;
  const std::string ref = dir.file("ref.exr"), same = dir.file("same.exr"), other = dir.file("other.exr");
  writeExr(ref, constantImage(8, 8, Color(0.5f)));
  writeExr(same, constantImage(8, 8, Color(0.5f)));
  writeExr(other, constantImage(8, 8, Color(0.9f)));
  writeExr(dir.file("small.exr"), constantImage(4, 8, Color(0.5f)));

  EXPECT_EQ(test::runEmber("compare '" + same + "' '" + ref + "' --max-relmse 0.001").exitCode, 0);
  const auto fail = test::runEmber("compare '" + other + "' '" + ref + "' --max-relmse 0.001 --json");
  EXPECT_EQ(fail.exitCode, 1);
  EXPECT_NE(fail.output.find("\"passed\": false"), std::string::npos) << fail.output;
  EXPECT_NE(fail.output.find("\"relmse_all\""), std::string::npos) << fail.output;
  const auto sizes = test::runEmber("compare '" + dir.file("small.exr") + "' '" + ref + "'");
  EXPECT_EQ(sizes.exitCode, 2);
  EXPECT_NE(sizes.output.find("differs"), std::string::npos) << sizes.output;
  EXPECT_EQ(test::runEmber("compare '" + dir.file("missing.exr") + "' '" + ref + "'").exitCode, 2);
  EXPECT_EQ(test::runEmber("compare '" + same + "'").exitCode, 2);  // missing argument

  // The z-test: variance and stderr images of zeros demand exact equality.
  writeExr(dir.file("zero.exr"), constantImage(8, 8, Color(0.0f)));
  const std::string z =
      " --variance '" + dir.file("zero.exr") + "' --ref-stderr '" + dir.file("zero.exr") + "'";
  EXPECT_EQ(test::runEmber("compare '" + same + "' '" + ref + "'" + z).exitCode, 0);
  EXPECT_EQ(test::runEmber("compare '" + other + "' '" + ref + "'" + z).exitCode, 1);
  // The heatmap is written.
  EXPECT_EQ(
      test::runEmber("compare '" + other + "' '" + ref + "' --heatmap '" + dir.file("h.png") + "'").exitCode,
      0);
  EXPECT_TRUE(std::filesystem::exists(dir.file("h.png")));
}

}  // namespace
}  // namespace ember
