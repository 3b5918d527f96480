// Adaptive sampling to an error target, in two stages (Mitchell 1987's pilot-then-refine scheme):
// every pixel first takes a pilot of samples; then each pixel gets the share of samples that
// minimises the image's expected relMSE: n_i proportional to the pixel's relative standard
// deviation sigma_i (minimising sum sigma_i^2 / n_i for a fixed sum n_i, by Cauchy-Schwarz),
// scaled so that the image's relative error (Film::relativeError) reaches the target:
//   n_i = ceil(sigma_i * mean_j(sigma_j) / target^2).
// Giving each pixel the count that brings its own error to the target (n_i proportional to
// sigma_i^2) would over-sample the noisiest pixels: it lost 16-32% efficiency against uniform
// sampling on the analytic scenes (docs/performance.md), where this rule gains.
//
// Unbiasedness: a pixel's budget is worked out from the other pixels' pilot samples only, never
// its own: sigma_i is the mean over its 8 neighbours, and the image mean leaves it out. Every
// (pixel, sample index) has its own random stream, so a pixel's samples are independent of its
// budget and their mean is an unbiased estimate of the pixel's value whatever the budget (a rule
// that looked at the pixel's own samples would stop it early exactly when they happen to agree,
// which darkens rare bright paths). The budgets are a function of the pilot alone, so a resumed
// render sets the same ones (or reads them from its checkpoint). The light tracer's splats are
// the one shared input (one light path can splat into two neighbouring pixels): a correlation
// below the reference z-tests' resolution (tests/test_reference_images.cpp).
#pragma once

#include "renderer/film.h"

#include <cstdint>
#include <vector>

namespace ember {

// The per-sample relative variance at each pixel, the mean over its channels of
// s^2 / (mean^2 + 0.01) (the regularised relative error of Film::relativeError, per sample);
// 0 where a pixel holds fewer than 2 samples.
std::vector<double> relativeSampleVariance(const Film& film);

// The most samples a budget asks for (the largest --spp). Budgets are not clamped to a render's own
// spp, which only stops the sampling: a render extended on resume keeps the budgets it had.
inline constexpr uint32_t kMaxAdaptiveBudget = 1u << 24;

// Each pixel's sample budget by the rule above, within [pilot, cap]: sigma_i the mean of the square
// root of relativeSampleVariance over the pixel's neighbours inside the image, the image mean over
// every other pixel. A 1x1 image, which has no neighbours, gets the cap.
std::vector<uint32_t> adaptiveBudgets(const Film& film, double target, uint32_t pilot, uint32_t cap);

}  // namespace ember
