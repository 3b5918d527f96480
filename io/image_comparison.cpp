#include "io/image_comparison.h"

#include "io/input_error.h"
#include "io/tonemap.h"

#include <string>

namespace ember {

namespace {

void requireSameSize(const Image& image, const Image& other, const char* what) {
  if (image.width != other.width || image.height != other.height)
    throw InputError(std::string(what) + ": size " + std::to_string(other.width) + "x" +
                     std::to_string(other.height) + " differs from the image's " +
                     std::to_string(image.width) + "x" + std::to_string(image.height));
}

}  // namespace

Comparison compareImages(const Image& image, const Image& reference, const Image* variance,
                         const Image* referenceStderr, const ComparisonOptions& options) {
  requireSameSize(image, reference, "reference");
  if (variance) requireSameSize(image, *variance, "variance");
  if (referenceStderr) requireSameSize(image, *referenceStderr, "reference stderr");
  Comparison c;
  c.metrics = computeMetrics(image, reference);
  // One tone curve for both images: the reference's (Reinhard 2002, as `ember tonemap`).
  float logAverage = 0.0f, white = 0.0f;
  const Image refDisplay =
      options.ldr ? reference : reinhardLinear(reference, ReinhardParams{}, &logAverage, &white);
  ReinhardParams shared;
  shared.white = white;
  shared.logAverage = logAverage;
  const Image imageDisplay = options.ldr ? image : reinhardLinear(image, shared);
  c.flip = computeFlip(refDisplay, imageDisplay, options.pixelsPerDegree);
  if (variance && referenceStderr)
    c.zTest = pixelZTest(image, *variance, reference, *referenceStderr, options.alpha, options.variancePool);
  if (options.maxRelmse && !(c.metrics.relmseAll <= *options.maxRelmse)) c.passed = false;
  if (options.maxFlip && !(c.flip.mean <= *options.maxFlip)) c.passed = false;
  if (c.zTest && !c.zTest->passed()) c.passed = false;
  return c;
}

nlohmann::json comparisonJson(const Comparison& c, const ComparisonOptions& options, int width, int height) {
  auto arr = [](const std::array<double, 3>& v) { return nlohmann::json::array({v[0], v[1], v[2]}); };
  auto optional = [](const std::optional<double>& v) {
    return v ? nlohmann::json(*v) : nlohmann::json(nullptr);
  };
  const ImageMetrics& m = c.metrics;
  nlohmann::json j = {
      {"width", width},
      {"height", height},
      {"mean_image", arr(m.meanImage)},
      {"mean_reference", arr(m.meanReference)},
      {"mae", arr(m.mae)},
      {"rmse", arr(m.rmse)},
      {"relmse", arr(m.relmse)},
      {"mae_all", m.maeAll},
      {"rmse_all", m.rmseAll},
      {"relmse_all", m.relmseAll},
      {"flip_mean", c.flip.mean},
      {"nonfinite_pixels", m.nonFinite},
      {"ztest", nullptr},
      {"criteria",
       {{"max_relmse", optional(options.maxRelmse)},
        {"max_flip", optional(options.maxFlip)},
        {"ztest", c.zTest.has_value()}}},
      {"passed", c.passed},
  };
  if (const auto& z = c.zTest)
    j["ztest"] = {{"alpha", z->alpha},         {"variance_pool", options.variancePool},
                  {"threshold", z->threshold}, {"tests", z->tests},
                  {"rejected", z->rejected},   {"max_abs_z", z->maxAbsZ},
                  {"passed", z->passed()}};
  return j;
}

}  // namespace ember
