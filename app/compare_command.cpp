// `ember compare`: an image against a reference. Metrics, the FLIP mean on tone-mapped images, and
// with variances on both sides a per-pixel z-test. Exit 0 when the chosen criteria pass, 1 when
// not, 2 on bad input. The --json layout is documented in docs/compare.md.
#include "app/commands.h"

#include "io/image_comparison.h"
#include "io/image_io.h"
#include "io/input_error.h"

#include <nlohmann/json.hpp>

#include <cstdio>
#include <memory>
#include <optional>

namespace ember::cli {

namespace {

struct CompareArgs {
  std::string image, reference, refStderr, variance, heatmap;
  bool json = false;
  bool ldr = false;
  std::optional<double> maxRelmse;
  std::optional<double> maxFlip;
  double alpha = 0.01;
  int pool = 2;
  float ppd = 67.0f;
};

// The "magma" colour ramp, nine samples interpolated linearly, for the FLIP heatmap.
Color magma(float t) {
  static const Color ramp[9] = {{0.001f, 0.000f, 0.014f}, {0.114f, 0.065f, 0.277f}, {0.316f, 0.072f, 0.485f},
                                {0.512f, 0.128f, 0.507f}, {0.716f, 0.215f, 0.475f}, {0.904f, 0.323f, 0.388f},
                                {0.990f, 0.525f, 0.382f}, {0.997f, 0.768f, 0.533f}, {0.987f, 0.991f, 0.750f}};
  const float x = std::clamp(t, 0.0f, 1.0f) * 8.0f;
  const int i = std::min(int(x), 7);
  return glm::mix(ramp[i], ramp[i + 1], x - float(i));
}

Image load(const std::string& path, const char* what) {
  try {
    return readImageRgb(path);
  } catch (const InputError& e) {
    throw InputError(std::string(what) + ": " + e.what());
  }
}

void requireSameSize(const Image& a, const Image& b, const std::string& pathB) {
  if (a.width != b.width || a.height != b.height)
    throw InputError(pathB + ": size " + std::to_string(b.width) + "x" + std::to_string(b.height) +
                     " differs from the image's " + std::to_string(a.width) + "x" + std::to_string(a.height));
}

int runCompare(const CompareArgs& a) {
  const Image image = load(a.image, "image");
  const Image reference = load(a.reference, "reference");
  requireSameSize(image, reference, a.reference);
  std::optional<Image> refStderr, variance;
  if (!a.refStderr.empty()) {
    refStderr = load(a.refStderr, "--ref-stderr");
    requireSameSize(image, *refStderr, a.refStderr);
  }
  if (!a.variance.empty()) {
    variance = load(a.variance, "--variance");
    requireSameSize(image, *variance, a.variance);
  }
  ComparisonOptions options;
  options.maxRelmse = a.maxRelmse;
  options.maxFlip = a.maxFlip;
  options.alpha = a.alpha;
  options.variancePool = a.pool;
  options.pixelsPerDegree = a.ppd;
  options.ldr = a.ldr;
  const Comparison c = compareImages(image, reference, variance ? &*variance : nullptr,
                                     refStderr ? &*refStderr : nullptr, options);
  const ImageMetrics& m = c.metrics;
  const FlipResult& flip = c.flip;
  const std::optional<PixelZTest>& z = c.zTest;
  const bool passed = c.passed;

  if (!a.heatmap.empty()) {
    std::vector<uint8_t> rgb8(size_t(image.width) * size_t(image.height) * 3);
    for (size_t i = 0; i < flip.errorMap.size(); ++i) {
      const Color c = magma(flip.errorMap[i]);
      for (int k = 0; k < 3; ++k) rgb8[i * 3 + size_t(k)] = uint8_t(std::lround(255.0f * c[k]));
    }
    writePng(a.heatmap, image.width, image.height, rgb8);
  }

  if (a.json) {
    nlohmann::json j = {{"image", a.image}, {"reference", a.reference}};
    j.update(comparisonJson(c, options, image.width, image.height));
    std::printf("%s\n", j.dump(2).c_str());
  } else {
    std::printf("image      %s (%dx%d)\nreference  %s\n", a.image.c_str(), image.width, image.height,
                a.reference.c_str());
    std::printf("%-10s %12s %12s %12s\n", "", "R", "G", "B");
    auto row = [](const char* name, const std::array<double, 3>& v) {
      std::printf("%-10s %12.6g %12.6g %12.6g\n", name, v[0], v[1], v[2]);
    };
    row("mean", m.meanImage);
    row("ref mean", m.meanReference);
    row("MAE", m.mae);
    row("RMSE", m.rmse);
    row("relMSE", m.relmse);
    std::printf("relMSE (all channels) %.6g, FLIP mean %.6g\n", m.relmseAll, flip.mean);
    if (m.nonFinite) std::printf("non-finite pixels skipped: %zu\n", m.nonFinite);
    if (z)
      std::printf(
          "z-test: %zu of %zu pixel-channels beyond |z| > %.3f (alpha %.3g, Sidak), max |z| %.3f: %s\n",
          z->rejected, z->tests, z->threshold, z->alpha, z->maxAbsZ, z->passed() ? "pass" : "FAIL");
    else if (refStderr || variance)
      std::printf("z-test: needs both --variance and --ref-stderr\n");
    std::printf("%s\n", passed ? "PASS" : "FAIL");
  }
  return passed ? 0 : 1;
}

}  // namespace

Runner addCompareCommand(CLI::App& app) {
  auto args = std::make_shared<CompareArgs>();
  CLI::App* cmd = app.add_subcommand(
      "compare",
      "Compare an image with a reference: means, MAE, RMSE, relMSE, FLIP, per-pixel z-test.\n"
      "Exit code 0 when the chosen criteria pass, 1 when they fail, 2 on bad input.");
  cmd->add_option("image", args->image, "The image under test (linear EXR)")->required();
  cmd->add_option("reference", args->reference, "The reference (linear EXR)")->required();
  cmd->add_option("--ref-stderr", args->refStderr, "Per-pixel standard error of the reference (EXR)");
  cmd->add_option("--variance", args->variance,
                  "Per-pixel variance of the image's mean (EXR, as `ember render --variance` writes); "
                  "with --ref-stderr enables the per-pixel z-test");
  cmd->add_option("--alpha", args->alpha, "Family-wise significance level of the z-test (default 0.01)")
      ->check(CLI::Range(1e-12, 0.5));
  cmd->add_option("--variance-pool", args->pool,
                  "z-test: use max(own, mean over the (2R+1)^2 neighbourhood) as each pixel's variance "
                  "(default 2; 0 = per pixel)")
      ->check(CLI::Range(0, 64));
  cmd->add_option("--max-relmse", args->maxRelmse, "Fail when relMSE over all channels exceeds this")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--max-flip", args->maxFlip, "Fail when the FLIP mean exceeds this")
      ->check(CLI::Range(0.0, 1.0));
  cmd->add_option("--ppd", args->ppd, "FLIP observer resolution in pixels per degree (default 67)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--heatmap", args->heatmap, "Write the FLIP error map as a PNG (magma colours)");
  cmd->add_flag("--json", args->json, "Print the results as JSON (layout: docs/compare.md)");
  cmd->add_flag("--ldr", args->ldr,
                "FLIP: the inputs are display-referred linear values in [0, 1]; skip the tone mapping");
  return [args] {
    try {
      return runCompare(*args);
    } catch (const InputError& e) {
      std::fprintf(stderr, "ember: error: %s\n", e.what());
      return 2;
    } catch (const std::exception& e) {
      std::fprintf(stderr, "ember: error: %s\n", e.what());
      return 2;
    }
  };
}

}  // namespace ember::cli
