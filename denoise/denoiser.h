// Denoising a rendered image with Intel Open Image Denoise's "RT" filter (denoise/oidn_library.h),
// guided by the albedo and normal AOVs (renderer/aov.h). The guides are noisy too (a few samples
// per pixel), so each is first denoised alone and the colour filter is then told they are clean
// (cleanAux): OIDN's recommended "prefiltering" for the highest quality, which keeps the guides'
// noise out of the result. The colour filter runs at OIDN's high quality, the guides' at balanced.
#pragma once

#include "renderer/film.h"

#include <stdexcept>
#include <string>
#include <vector>

namespace ember {

struct DenoiseInput {
  int width = 0, height = 0;
  std::vector<float> color;   // linear HDR RGB, interleaved
  std::vector<float> albedo;  // RGB in [0, 1], or empty
  std::vector<float> normal;  // XYZ in [-1, 1], or empty; used only with an albedo (OIDN's rule)
};

struct DenoiseOptions {
  int threads = 0;              // OIDN's worker threads; 0 = its default (all cores)
  bool prefilterGuides = true;  // denoise albedo and normal first (else trust them as given)
};

// The denoised colour, RGB interleaved. Throws DenoiseError where OIDN is missing (saying how to
// install it) or reports an error.
std::vector<float> denoise(const DenoiseInput& input, const DenoiseOptions& options);

struct DenoiseError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// The colour to denoise and its guides from an image's layers (renderer/film.h): the colour, and the
// layers albedo.R/G/B and N.X/Y/Z where present.
DenoiseInput denoiseInput(const Image& color, const std::vector<ImageLayer>& layers);
// What the EXR's ember:denoiser attribute says was done with these layers.
std::string denoiserDescription(const std::vector<ImageLayer>& layers);

// Whether OIDN can be loaded; otherwise `why` says where Ember looked and how to install it.
bool denoiserAvailable(std::string& why);

}  // namespace ember
