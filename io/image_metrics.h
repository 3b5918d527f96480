// Error metrics of an image against a reference, per channel and overall, and the per-pixel z-test
// used by `ember compare` and the reference-image tests (docs/compare.md).
#pragma once

#include "renderer/film.h"

#include <array>
#include <optional>

namespace ember {

struct ImageMetrics {
  std::array<double, 3> meanImage{}, meanReference{};
  std::array<double, 3> mae{}, rmse{}, relmse{};
  double maeAll = 0.0, rmseAll = 0.0, relmseAll = 0.0;  // over all channels
  size_t nonFinite = 0;  // pixels where the image or the reference is NaN/inf (excluded)
};

// relMSE = mean((x - r)^2 / (r^2 + 0.01)), the regularised relative MSE of Rousselle et al. 2011.
ImageMetrics computeMetrics(const Image& image, const Image& reference);

struct PixelZTest {
  double alpha = 0.01;
  double threshold = 0.0;  // |z| bound after Sidak correction over all pixels and channels
  size_t tests = 0;
  size_t rejected = 0;
  double maxAbsZ = 0.0;
  bool passed() const { return rejected == 0; }
};

// z = (x - r) / sqrt(var_x + stderr_r^2) per pixel and channel. Where both variances are zero the
// values must agree to float precision.
// A pixel's own sample variance underestimates the true one wherever rare, bright paths (caustics,
// light leaking through small gaps) were not sampled, and at a few hundred samples per pixel that
// alone rejects hundreds of unbiased pixels. With poolRadius R > 0 each variance is therefore
// max(own, mean over the (2R+1)^2 neighbourhood): neighbouring pixels see the same light paths, so
// their variances are a sounder estimate. poolRadius = 0 is the plain per-pixel test.
PixelZTest pixelZTest(const Image& image, const Image& imageVariance, const Image& reference,
                      const Image& referenceStderr, double alpha = 0.01, int poolRadius = 2);

// max(v, box mean of v over (2r+1)^2 pixels, clamped at the borders), per channel.
Image poolVariance(const Image& variance, int radius);

}  // namespace ember
