#include "app/commands.h"

#include "io/image_io.h"
#include "io/input_error.h"
#include "io/scene_loader.h"
#include "io/tonemap.h"
#include "packet/wavefront_integrator.h"
#include "renderer/render.h"

#include <unistd.h>

#include <chrono>
#include <ctime>
#include <filesystem>
#include <memory>
#include <optional>
#include <sstream>

namespace ember::cli {

namespace {

struct RenderArgs {
  std::string scene;
  std::string output;
  std::string png;
  std::string variance;
  std::optional<int> spp, threads, width, height, maxDepth;
  int camera = -1;
  std::optional<uint64_t> seed;
  uint64_t firstSample = 0;
  std::string sampler;
  std::string strategy;
  std::string kernel = "wavefront";
  std::string env;
  bool quiet = false;
};

void checkOutputPath(const std::string& path, const char* extension, const char* what) {
  namespace fs = std::filesystem;
  std::string ext = fs::path(path).extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  if (ext != extension) throw InputError(path + ": " + what + " must end in " + extension);
  const fs::path dir = fs::path(path).parent_path();
  if (!dir.empty() && !fs::is_directory(dir))
    throw InputError(path + ": output folder " + dir.string() + " does not exist");
}

std::string isoTime() {
  const std::time_t now = std::time(nullptr);
  char buf[64];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
  return buf;
}

// --env: "r,g,b" or one number is a constant environment, anything else an equirectangular map.
void applyEnvironment(const std::string& value, Scene& scene) {
  std::vector<float> numbers;
  std::stringstream in(value);
  std::string part;
  bool numeric = true;
  while (numeric && std::getline(in, part, ',')) {
    char* end = nullptr;
    const float v = std::strtof(part.c_str(), &end);
    numeric = end != part.c_str() && *end == '\0' && std::isfinite(v) && v >= 0.0f;
    numbers.push_back(v);
  }
  if (numeric && (numbers.size() == 1 || numbers.size() == 3)) {
    scene.background = numbers.size() == 1 ? Color(numbers[0]) : Color(numbers[0], numbers[1], numbers[2]);
    scene.environmentMap = nullptr;
    return;
  }
  if (numeric) throw InputError("--env " + value + ": expected r,g,b or one number >= 0, or an image file");
  scene.environmentMap = loadEnvironmentMap(value);
  scene.background = Color(0.0f);
}

int runRender(const RenderArgs& a) {
  checkOutputPath(a.output, ".exr", "-o");
  if (!a.png.empty()) checkOutputPath(a.png, ".png", "--png");
  if (!a.variance.empty()) checkOutputPath(a.variance, ".exr", "--variance");

  const auto loadStart = std::chrono::steady_clock::now();
  LoadOptions loadOptions;
  loadOptions.camera = a.camera;
  loadOptions.environmentGiven = !a.env.empty();
  Scene scene = loadScene(a.scene, loadOptions);
  RenderSettings& s = scene.settings;
  if (a.spp) s.spp = *a.spp;
  if (a.seed) s.seed = *a.seed;
  if (a.width) s.width = *a.width;
  if (a.height) s.height = *a.height;
  if (a.maxDepth) s.maxDepth = *a.maxDepth;
  if (!a.env.empty()) applyEnvironment(a.env, scene);
  if (a.sampler == "sobol") s.sampler = SamplerType::Sobol;
  if (a.sampler == "independent") s.sampler = SamplerType::Independent;
  if (!a.strategy.empty()) s.strategy = *parseStrategy(a.strategy);  // CLI11 checked the name
  scene.build();
  if (const std::string w = unreachableLightsWarning(scene, s.strategy); !w.empty())
    std::fprintf(stderr, "ember: warning: %s\n", w.c_str());
  const double loadSeconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - loadStart).count();

  const std::unique_ptr<Integrator> integrator = makeIntegrator(s, *parseKernel(a.kernel));
  Film film(s.width, s.height);
  RenderOptions options;
  options.spp = s.spp;
  options.seed = s.seed;
  options.threads = a.threads.value_or(0);
  options.firstSample = a.firstSample;
  options.sampler = s.sampler;
  options.progress = !a.quiet;
  const RenderStats stats = render(scene, *integrator, options, film);

  const Image image = film.mean();
  const Metadata meta{{"ember:scene", a.scene},
                      {"ember:spp", std::to_string(s.spp)},
                      {"ember:seed", std::to_string(s.seed)},
                      {"ember:sampler", s.sampler == SamplerType::Sobol ? "sobol" : "independent"},
                      {"ember:strategy", std::string(strategyName(s.strategy))},
                      {"ember:first_sample", std::to_string(a.firstSample)},
                      {"ember:render_seconds", std::to_string(stats.seconds)},
                      {"ember:version", EMBER_VERSION},
                      {"DateTime", isoTime()},
                      {"Software", std::string("ember ") + EMBER_VERSION}};
  writeExr(a.output, image, meta);
  if (!a.variance.empty()) writeExr(a.variance, film.varianceOfMean(), meta);
  if (!a.png.empty()) {
    const ReinhardResult tm = tonemapReinhard(image, ReinhardParams{});
    writePng(a.png, image.width, image.height, tm.rgb8);
  }

  const double secs = std::max(stats.seconds, 1e-9);
  const uint64_t rays = stats.paths.rays + stats.paths.shadowRays;
  std::fprintf(stderr,
               "ember: %dx%d, %d spp, %d threads: load+build %.3f s, render %.3f s, %.3f M samples/s, "
               "%.3f M rays/s (%.3f M closest-hit + %.3f M shadow), %llu non-finite samples dropped -> %s\n",
               s.width, s.height, s.spp, stats.threads, loadSeconds, stats.seconds,
               double(stats.samples) / secs * 1e-6, double(rays) / secs * 1e-6,
               double(stats.paths.rays) / secs * 1e-6, double(stats.paths.shadowRays) / secs * 1e-6,
               static_cast<unsigned long long>(stats.nonFinite), a.output.c_str());
  return 0;
}

}  // namespace

Runner addRenderCommand(CLI::App& app) {
  auto args = std::make_shared<RenderArgs>();
  CLI::App* cmd =
      app.add_subcommand("render", "Render a scene (Ember JSON, .gltf or .glb) to a linear float EXR");
  cmd->add_option("scene", args->scene, "Scene file: Ember JSON (docs/scene-format.md), .gltf or .glb")
      ->required();
  cmd->add_option("-o,--output", args->output, "Output EXR (linear float32 RGB), written atomically")
      ->required();
  cmd->add_option("--png", args->png, "Also write a tone-mapped (Reinhard 2002) sRGB PNG");
  cmd->add_option("--spp", args->spp, "Samples per pixel (default: the scene's render.spp, else 64)")
      ->check(CLI::Range(1, 1 << 24));
  cmd->add_option("--seed", args->seed, "Random seed (default: the scene's render.seed, else 0)");
  cmd->add_option("--threads", args->threads, "Worker threads (default: all cores)")
      ->check(CLI::Range(1, 4096));
  cmd->add_option("--width", args->width, "Image width in pixels (overrides the scene)")
      ->check(CLI::Range(1, 16384));
  cmd->add_option("--height", args->height, "Image height in pixels (overrides the scene)")
      ->check(CLI::Range(1, 16384));
  cmd->add_option("--max-depth", args->maxDepth,
                  "Longest path in segments; -1 = unbounded with Russian roulette")
      ->check(CLI::Range(-1, 100000));
  cmd->add_option(
      "--first-sample", args->firstSample,
      "Index of the first sample to render: renders [first, first + spp), so separate runs can be merged");
  cmd->add_option("--sampler", args->sampler,
                  "Random numbers: sobol (Owen-scrambled, the default) or independent; default: the scene's "
                  "render.sampler")
      ->check(CLI::IsMember({"independent", "sobol"}));
  cmd->add_option(
         "--strategy", args->strategy,
         "Direct-light estimator, all unbiased: mis (light and BSDF sampling with MIS, the default), "
         "bsdf (BSDF sampling only: emitters count when paths hit them; point, spot and "
         "directional lights are unreachable), light (light sampling at every non-specular "
         "vertex; emitters seen by the camera or through mirrors and glass still count); "
         "default: the scene's render.strategy")
      ->check(CLI::IsMember({"mis", "bsdf", "light"}));
  cmd->add_option("--kernel", args->kernel,
                  "How paths are traced, all giving the same image: wavefront (16-wide Embree packets, the "
                  "default), stream (Embree ray streams) or scalar (one ray at a time, the reference)")
      ->check(CLI::IsMember({"wavefront", "stream", "scalar"}));
  cmd->add_option("--env", args->env,
                  "Environment light: r,g,b (or one number) for a constant colour, or an equirectangular "
                  "EXR/HDR map; replaces the scene's");
  cmd->add_option("--camera", args->camera,
                  "glTF files: render through camera N of the file's `cameras` (default: the first one a "
                  "node places, else a camera framing the scene)")
      ->check(CLI::Range(0, 1 << 20));
  cmd->add_option("--variance", args->variance, "Also write the per-pixel variance of the mean as an EXR");
  cmd->add_flag("-q,--quiet", args->quiet, "No progress display (the summary line is still printed)");
  return [args] { return runRender(*args); };
}

}  // namespace ember::cli
