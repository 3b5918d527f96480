// Denoising (denoise/denoiser.h): OIDN removes most of the error of a noisy image, of a render
// against its Mitsuba reference too; `ember render --denoise` keeps the noisy colour bit for bit
// and equals `ember denoise` of the same layers; a missing library or a bad input is an error
// naming it, with nothing written. Tests that need OIDN skip, saying why, where it is not
// installed (scripts/setup-deps.sh installs it, so CI runs them).
#include "denoise/denoiser.h"
#include "io/image_io.h"
#include "io/image_metrics.h"

#include <gtest/gtest.h>

#include "cli_runner.h"
#include "test_paths.h"

#include <cmath>
#include <filesystem>
#include <random>

namespace ember {
namespace {

#define SKIP_WITHOUT_OIDN()                           \
  do {                                                \
    std::string why;                                  \
    if (!denoiserAvailable(why)) GTEST_SKIP() << why; \
  } while (0)

std::string quoted(const std::string& s) {
  return "'" + s + "'";
}

Image channels(const ExrChannels& exr, const char* r, const char* g, const char* b) {
  Image image(exr.width, exr.height);
  const char* names[3] = {r, g, b};
  for (int c = 0; c < 3; ++c)
    for (size_t i = 0; i < size_t(exr.width) * size_t(exr.height); ++i)
      image.rgb[3 * i + size_t(c)] = exr.channels.at(names[c])[i];
  return image;
}

// A grey image with Gaussian noise of 0.1 and flat guides: the denoised image is within a quarter
// of the noise of the truth.
TEST(Denoise, RemovesNoiseFromAFlatImage) {
  SKIP_WITHOUT_OIDN();
  DenoiseInput in;
  in.width = in.height = 64;
  const size_t n = 64 * 64 * 3;
  std::mt19937 rng(1);
  std::normal_distribution<float> noise(0.0f, 0.1f);
  for (size_t i = 0; i < n; ++i) in.color.push_back(0.5f + noise(rng));
  in.albedo.assign(n, 0.5f);
  in.normal.assign(n, 0.0f);
  for (size_t i = 2; i < n; i += 3) in.normal[i] = 1.0f;
  const std::vector<float> out = denoise(in, DenoiseOptions{});
  ASSERT_EQ(out.size(), n);
  double noisy = 0.0, clean = 0.0;
  for (size_t i = 0; i < n; ++i) {
    noisy += (in.color[i] - 0.5) * (in.color[i] - 0.5);
    clean += (out[i] - 0.5) * (out[i] - 0.5);
  }
  EXPECT_LT(std::sqrt(clean / double(n)), 0.25 * std::sqrt(noisy / double(n)));
  // Mismatched sizes are refused.
  in.albedo.resize(3);
  EXPECT_THROW(denoise(in, DenoiseOptions{}), DenoiseError);
}

// cornell-area at 8 spp: denoised, its relMSE against the Mitsuba reference falls at least
// fourfold; the noisy colour stays in the file, equal to a render without --denoise.
TEST(DenoiseCli, ADenoisedRenderIsCloserToTheReferenceAndKeepsTheNoisyOne) {
  SKIP_WITHOUT_OIDN();
  test::TempDir dir;
  const std::string scene = test::sourcePath("scenes/cornell-area.json");
  const std::string denoised = dir.file("d.exr"), plain = dir.file("p.exr");
  const test::CliResult r =
      test::runEmber("render " + quoted(scene) + " -o " + quoted(denoised) + " --spp 8 --denoise -q");
  ASSERT_EQ(r.exitCode, 0) << r.output;
  ASSERT_EQ(test::runEmber("render " + quoted(scene) + " -o " + quoted(plain) + " --spp 8 -q").exitCode, 0);
  const ExrChannels exr = readExrChannels(denoised);
  for (const char* name : {"noisy.R", "albedo.R", "N.X"}) EXPECT_TRUE(exr.has(name)) << name;
  const Image reference = readImageRgb(test::sourcePath("tests/data/cornell-area/reference.exr"));
  const Image noisy = channels(exr, "noisy.R", "noisy.G", "noisy.B");
  EXPECT_EQ(noisy.rgb, readImageRgb(plain).rgb);
  const double before = computeMetrics(noisy, reference).relmseAll;
  const double after = computeMetrics(channels(exr, "R", "G", "B"), reference).relmseAll;
  EXPECT_LT(after, before / 4.0) << "relMSE noisy " << before << ", denoised " << after;
  std::string description;
  for (const auto& [k, v] : exr.metadata)
    if (k == "ember:denoiser") description = v;
  EXPECT_NE(description.find("albedo and normal"), std::string::npos) << description;

  // `ember denoise` of an image with the same layers gives the same colour.
  const std::string layers = dir.file("l.exr"), again = dir.file("a.exr");
  ASSERT_EQ(test::runEmber("render " + quoted(scene) + " -o " + quoted(layers) +
                           " --spp 8 --aov albedo,normal --threads 2 -q")
                .exitCode,
            0);
  const test::CliResult d =
      test::runEmber("denoise " + quoted(layers) + " -o " + quoted(again) + " --threads 2");
  ASSERT_EQ(d.exitCode, 0) << d.output;
  const ExrChannels second = readExrChannels(again);
  const Image a = channels(exr, "R", "G", "B"), b = channels(second, "R", "G", "B");
  double worst = 0.0;
  for (size_t i = 0; i < a.rgb.size(); ++i) worst = std::max(worst, double(std::abs(a.rgb[i] - b.rgb[i])));
  EXPECT_LT(worst, 1e-3);
  EXPECT_EQ(second.channels.at("noisy.R"), exr.channels.at("noisy.R"));
  // A denoised image is not a mean of samples: merge refuses it.
  const test::CliResult merge =
      test::runEmber("merge " + quoted(denoised) + " " + quoted(plain) + " -o " + quoted(dir.file("m.exr")));
  EXPECT_EQ(merge.exitCode, 1);
  EXPECT_NE(merge.output.find("denoised"), std::string::npos) << merge.output;
  // Denoised again, it starts from the noisy layer, not from the denoised colour.
  const std::string third = dir.file("t.exr");
  ASSERT_EQ(test::runEmber("denoise " + quoted(again) + " -o " + quoted(third) + " --threads 2").exitCode, 0);
  EXPECT_EQ(readExrChannels(third).channels.at("R"), second.channels.at("R"));
}

// Without the library, or with a bad input, nothing is written and the error says why. (Runs
// whether OIDN is installed or not: EMBER_OIDN_LIBRARY names a file that is not there.)
TEST(DenoiseCli, AMissingLibraryOrBadInputIsAnErrorWithNothingWritten) {
  test::TempDir dir;
  const std::string scene = test::sourcePath("scenes/cornell-area.json");
  const std::string out = dir.file("o.exr"), missing = dir.file("no-oidn.so");
  const test::CliResult without = [&] {
    ::setenv("EMBER_OIDN_LIBRARY", missing.c_str(), 1);
    const test::CliResult x =
        test::runEmber("render " + quoted(scene) + " -o " + quoted(out) + " --spp 1 --denoise -q");
    ::unsetenv("EMBER_OIDN_LIBRARY");
    return x;
  }();
  EXPECT_EQ(without.exitCode, 1) << without.output;
  EXPECT_NE(without.output.find(missing), std::string::npos) << without.output;
  EXPECT_NE(without.output.find("setup-deps.sh"), std::string::npos) << without.output;
  EXPECT_FALSE(std::filesystem::exists(out));

  const test::CliResult noFile =
      test::runEmber("denoise " + quoted(dir.file("none.exr")) + " -o " + quoted(out));
  EXPECT_EQ(noFile.exitCode, 1);
  const std::string png = dir.write("x.png", "not a png");
  const test::CliResult notExr = test::runEmber("denoise " + quoted(png) + " -o " + quoted(out));
  EXPECT_EQ(notExr.exitCode, 1);
  // A colour with a NaN: the denoiser would spread it; named instead.
  std::string why;
  if (denoiserAvailable(why)) {
    Image nan(4, 4);
    nan.rgb[5] = std::nanf("");
    writeExr(dir.file("nan.exr"), nan, {}, {});
    const test::CliResult bad =
        test::runEmber("denoise " + quoted(dir.file("nan.exr")) + " -o " + quoted(out));
    EXPECT_EQ(bad.exitCode, 1);
    EXPECT_NE(bad.output.find("NaN or infinite value at pixel (1, 0)"), std::string::npos) << bad.output;
  }
  EXPECT_FALSE(std::filesystem::exists(out));
}

}  // namespace
}  // namespace ember
