// `ember compare`'s whole verdict on an image against a reference, shared by the command and the
// Python module's ember.compare: the metrics, FLIP on both images tone-mapped by the reference's
// Reinhard curve, the per-pixel z-test when both variances are given, and the pass/fail criteria.
// Its JSON form is the layout documented in docs/compare.md.
#pragma once

#include "io/flip.h"
#include "io/image_metrics.h"

#include <nlohmann/json.hpp>

#include <optional>

namespace ember {

struct ComparisonOptions {
  std::optional<double> maxRelmse;  // fail when relMSE over all channels exceeds it
  std::optional<double> maxFlip;    // fail when the FLIP mean exceeds it
  double alpha = 0.01;              // the z-test's family-wise level
  int variancePool = 2;             // the z-test's pooling radius (pixelZTest)
  float pixelsPerDegree = 67.0f;    // FLIP's observer
  bool ldr = false;                 // the inputs are display-referred: FLIP skips the tone mapping
};

struct Comparison {
  ImageMetrics metrics;
  FlipResult flip;
  std::optional<PixelZTest> zTest;  // with both `variance` and `referenceStderr`
  bool passed = true;
};

// Sizes must match (InputError otherwise). `variance`: of the image's mean per pixel;
// `referenceStderr`: the reference's standard error per pixel; either may be null.
Comparison compareImages(const Image& image, const Image& reference, const Image* variance,
                         const Image* referenceStderr, const ComparisonOptions& options);

// docs/compare.md's layout, less the "image" and "reference" names, which the caller adds.
nlohmann::json comparisonJson(const Comparison& comparison, const ComparisonOptions& options, int width,
                              int height);

}  // namespace ember
