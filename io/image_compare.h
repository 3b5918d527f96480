// Statistical comparison of a rendered image with a reference, both noisy: z-tests of block means
// (and of the whole-image mean per channel) against their combined standard error, with the
// significance level Sidak-corrected over all tests, as Mitsuba 3's render tests do per pixel.
#pragma once

#include "renderer/film.h"

#include <array>

namespace ember {

struct BlockZTestResult {
  int tests = 0;           // blocks x channels
  int failures = 0;        // |z| above the threshold
  double threshold = 0.0;  // |z| bound after Sidak correction
  double maxAbsZ = 0.0;
  std::array<double, 3> meanZ{};  // z of the whole-image mean, per channel
  bool meanPasses = true;
  bool passes() const { return failures == 0 && meanPasses; }
};

// `variance` and `refVariance` hold the variance of each pixel's mean (stderr squared).
// Pixels are grouped into blocks of blockSize x blockSize; alpha is the family-wise level.
BlockZTestResult blockZTest(const Image& image, const Image& variance, const Image& reference,
                            const Image& refVariance, int blockSize, double alpha);

// Two-sided standard-normal quantile: the z with P(|Z| > z) = p.
double twoSidedNormalQuantile(double p);
// Per-test level that keeps the family-wise level alpha over m independent tests (Sidak 1967).
double sidakLevel(double alpha, int m);

Image squared(const Image& stderrImage);

}  // namespace ember
