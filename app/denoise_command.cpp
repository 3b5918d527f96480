// `ember denoise in.exr -o out.exr`: denoises an EXR that `ember render --aov albedo,normal` (or any
// renderer writing the same channel names) wrote, keeping every other layer. An image denoised
// before is denoised again from its noisy.R/G/B layer, not from the denoised colour.
#include "app/commands.h"

#include "denoise/denoiser.h"
#include "denoise/oidn_library.h"
#include "io/image_io.h"
#include "io/input_error.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>

namespace ember::cli {

namespace {

struct DenoiseArgs {
  std::string input, output;
  int threads = 0;
  bool noPrefilter = false;
};

int runDenoise(const DenoiseArgs& a) {
  if (std::string why; !denoiserAvailable(why)) throw InputError(why);
  const ExrChannels exr = readExrChannels(a.input);
  const bool denoisedBefore = exr.has("noisy.R") && exr.has("noisy.G") && exr.has("noisy.B");
  const char* const colour[3] = {"R", "G", "B"};
  const char* const noisy[3] = {"noisy.R", "noisy.G", "noisy.B"};
  Image image(exr.width, exr.height);
  const size_t pixels = size_t(exr.width) * size_t(exr.height);
  for (int c = 0; c < 3; ++c) {
    const std::string name = denoisedBefore ? noisy[c] : colour[c];
    if (!exr.has(name)) throw InputError(a.input + ": no " + name + " channel: not an RGB image");
    const std::vector<float>& values = exr.channels.at(name);
    for (size_t i = 0; i < pixels; ++i) {
      if (!std::isfinite(values[i]))
        throw InputError(a.input + ": channel " + name + " holds a NaN or infinite value at pixel (" +
                         std::to_string(i % size_t(exr.width)) + ", " +
                         std::to_string(i / size_t(exr.width)) + ")");
      image.rgb[3 * i + size_t(c)] = values[i];
    }
  }
  // Every other channel is kept as it is; the guides are those of the render. A guide must be whole
  // and finite: the filter would spread a NaN over its neighbourhood.
  std::vector<ImageLayer> layers;
  std::vector<std::string> gathered;
  const auto gather = [&](std::vector<std::string> names) {
    size_t present = 0;
    for (const std::string& n : names) present += exr.has(n) ? 1 : 0;
    if (present == 0) return;
    if (present != names.size())
      throw InputError(a.input + ": the layer " + names[0].substr(0, names[0].find('.')) + " lacks some of " +
                       names[0] + ", " + names[1] + ", " + names[2]);
    ImageLayer layer{names, std::vector<float>(pixels * names.size())};
    for (size_t k = 0; k < names.size(); ++k)
      for (size_t i = 0; i < pixels; ++i) {
        const float v = exr.channels.at(names[k])[i];
        if (!std::isfinite(v))
          throw InputError(a.input + ": channel " + names[k] + " holds a NaN or infinite value at pixel (" +
                           std::to_string(i % size_t(exr.width)) + ", " +
                           std::to_string(i / size_t(exr.width)) + ")");
        layer.pixels[i * names.size() + k] = v;
      }
    gathered.insert(gathered.end(), names.begin(), names.end());
    layers.push_back(std::move(layer));
  };
  if (denoisedBefore) gather({"noisy.R", "noisy.G", "noisy.B"});
  if (!denoisedBefore) layers.push_back({{"noisy.R", "noisy.G", "noisy.B"}, image.rgb});
  gather({"albedo.R", "albedo.G", "albedo.B"});
  gather({"N.X", "N.Y", "N.Z"});
  for (const auto& [name, values] : exr.channels) {
    const bool taken = name == "R" || name == "G" || name == "B" ||
                       std::find(gathered.begin(), gathered.end(), name) != gathered.end() ||
                       (!denoisedBefore && name.rfind("noisy.", 0) == 0);
    if (!taken) layers.push_back({{name}, values});
  }
  const auto start = std::chrono::steady_clock::now();
  image.rgb = denoise(denoiseInput(image, layers), DenoiseOptions{a.threads, !a.noPrefilter});
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  Metadata meta;
  // OpenEXR's own string attributes (a multi-part file's part name and type) describe the input file.
  for (const auto& [k, v] : exr.metadata)
    if (k != "ember:denoiser" && k != "name" && k != "type" && k != "view") meta.emplace_back(k, v);
  meta.emplace_back("ember:denoiser",
                    denoiserDescription(layers) + (a.noPrefilter ? ", guides as given" : ""));
  writeExr(a.output, image, layers, meta);
  std::fprintf(stderr, "ember: denoised %dx%d in %.3f s (%.3f s per megapixel; %s) -> %s\n", exr.width,
               exr.height, seconds, seconds / (double(pixels) * 1e-6), oidnLibraryPath().c_str(),
               a.output.c_str());
  return 0;
}

}  // namespace

Runner addDenoiseCommand(CLI::App& app) {
  auto args = std::make_shared<DenoiseArgs>();
  CLI::App* cmd = app.add_subcommand(
      "denoise",
      "Denoise a rendered EXR with Intel Open Image Denoise, guided by its albedo and normal layers");
  cmd->add_option("input", args->input,
                  "EXR with R, G, B and, ideally, albedo.R/G/B and N.X/Y/Z (ember render --aov)")
      ->required();
  cmd->add_option("-o,--output", args->output,
                  "Output EXR: the denoised colour, the noisy one as noisy.R/G/B, "
                  "and every other layer of the input")
      ->required();
  cmd->add_option("--threads", args->threads, "OIDN's worker threads (default: all cores)")
      ->check(CLI::Range(1, 4096));
  cmd->add_flag(
      "--no-prefilter", args->noPrefilter,
      "Trust the albedo and normal as they are, rather than denoising them first (for noise-free guides)");
  return [args] { return runDenoise(*args); };
}

}  // namespace ember::cli
