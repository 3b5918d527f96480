#include "app/commands.h"

#include "io/image_io.h"
#include "io/input_error.h"
#include "io/tonemap.h"

#include <memory>
#include <optional>

namespace ember::cli {

Runner addTonemapCommand(CLI::App& app) {
  struct Args {
    std::string input, output;
    float key = 0.18f;
    std::optional<float> white;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "tonemap", "Tone-map a linear EXR to an 8-bit sRGB PNG (Reinhard et al. 2002, global operator)");
  cmd->add_option("input", args->input,
                  "Linear EXR (or Radiance HDR; 8- and 16-bit images are read as stored)")
      ->required();
  cmd->add_option("-o,--output", args->output, "Output PNG")->required();
  cmd->add_option("--key", args->key, "Key value a: the log-average luminance maps to a (default 0.18)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--white", args->white, "Input luminance that maps to white (default: the image's maximum)")
      ->check(CLI::PositiveNumber);
  return [args] {
    const Image image = readImageRgb(args->input);
    const ReinhardResult r = tonemapReinhard(image, ReinhardParams{args->key, args->white, std::nullopt});
    writePng(args->output, image.width, image.height, r.rgb8);
    std::fprintf(stderr, "ember: tonemap: log-average luminance %.6g, white %.6g -> %s\n", r.logAverage,
                 r.white, args->output.c_str());
    return 0;
  };
}

}  // namespace ember::cli
