// Reinhard et al. 2002, "Photographic Tone Reproduction for Digital Images", global operator:
//   log-average luminance   Lavg = exp(mean(log(delta + Lw)))                 (eq. 1), over the
//                           pixels that are not black (an empty background would set the key)
//   scaled luminance        L = key / Lavg * Lw                                (eq. 2)
//   display luminance       Ld = L (1 + L / Lwhite^2) / (1 + L)                (eq. 4)
// Lwhite is given in input (scene) luminance and scaled like L; by default it is the image's
// maximum luminance, so the brightest pixel maps to exactly 1. Colours keep their ratios:
// RGB_out = RGB_in * Ld / Lw, then the sRGB OETF and 8-bit quantisation.
#pragma once

#include "renderer/film.h"

#include <cstdint>
#include <optional>
#include <vector>

namespace ember {

struct ReinhardParams {
  float key = 0.18f;
  std::optional<float> white;  // input luminance mapped to white; default: the maximum
  // Log-average luminance to use instead of the image's own, so two images (a render and its
  // reference) can share one tone curve.
  std::optional<float> logAverage;
};

struct ReinhardResult {
  std::vector<uint8_t> rgb8;
  float logAverage = 0.0f;
  float white = 0.0f;  // the Lwhite used, in input luminance
};

// Tone-mapped linear display values in [0, 1] (before sRGB encoding), for tests and FLIP.
Image reinhardLinear(const Image& image, const ReinhardParams& params, float* logAverage = nullptr,
                     float* white = nullptr);
ReinhardResult tonemapReinhard(const Image& image, const ReinhardParams& params);

}  // namespace ember
