// Shared by the fuzz targets: the loaders read files, so each input is written to a file of its
// own in the temporary folder first, and only InputError — the loaders' one way of rejecting
// bad input — is an acceptable outcome besides success. Any other exception, a crash, or an
// ASan/UBSan report is a finding.
#pragma once

#include "io/input_error.h"
#include "packet/wave_integrator.h"
#include "renderer/render.h"

#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>

namespace ember::fuzz {

inline std::string inputFile(const char* extension) {
  return (std::filesystem::temp_directory_path() / ("ember_fuzz_" + std::to_string(::getpid()) + extension))
      .string();
}

inline void writeInput(const std::string& path, const uint8_t* data, size_t size) {
  std::ofstream(path, std::ios::binary | std::ios::trunc)
      .write(reinterpret_cast<const char*>(data), std::streamsize(size));
}

// Runs `body`; InputError is the expected rejection, anything else aborts (a finding).
template <typename Body>
void expectOnlyInputErrors(Body body) {
  try {
    body();
  } catch (const InputError&) {
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fuzz finding: exception other than InputError: %s\n", e.what());
    std::abort();
  }
}

// Builds a loaded scene and renders one sample of 4x4 pixels with at most `maxDepth` segments:
// whatever a loader accepts must also build and render without a crash.
inline void buildAndRenderTiny(Scene& scene, int maxDepth) {
  scene.settings.width = scene.settings.height = 4;
  scene.settings.maxDepth =
      scene.settings.maxDepth < 0 ? maxDepth : std::min(scene.settings.maxDepth, maxDepth);
  scene.build();
  const auto integrator = makeIntegrator(scene.settings, Kernel::Wave);  // the default kernel
  Film film(4, 4);
  RenderOptions options;
  options.spp = 1;
  options.threads = 1;
  render(scene, *integrator, options, film);
}

}  // namespace ember::fuzz
