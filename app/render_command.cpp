#include "app/commands.h"

#include "app/stop_signals.h"
#include "checkpoint/checkpoint_file.h"
#include "denoise/denoiser.h"
#include "denoise/oidn_library.h"
#include "distributed/cluster.h"
#include "io/filtered_texture.h"
#include "io/image_io.h"
#include "io/input_error.h"
#include "io/scene_loader.h"
#include "io/tonemap.h"
#include "packet/wave_integrator.h"
#include "renderer/render.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdlib>
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
  std::string caustics;
  std::string kernel = "wave";
  std::string packetWidth = "auto";
  std::string env;
  std::optional<float> envStrength;
  std::string variant;
  std::string textureFilter;
  std::optional<double> untilRelerr;
  std::string aovs;
  bool denoise = false;
  bool adaptive = false;
  bool quiet = false;
  std::string checkpoint, resume, time;
  double checkpointEvery = 60.0;
  std::optional<int> passSpp;
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

// --env-strength travels inside the --env value, so that a checkpoint's identity (which keeps the
// value) restores both: "SPEC\nstrength=S". No file name holds a line break.
constexpr const char* kStrengthTag = "\nstrength=";

// --env: none, white, "r,g,b" or one number for a constant environment, anything else an
// equirectangular map; times --env-strength. Says on stderr what was taken.
void applyEnvironment(const std::string& spec, Scene& scene) {
  std::string value = spec;
  float strength = 1.0f;
  if (const size_t tag = spec.find(kStrengthTag); tag != std::string::npos) {
    value = spec.substr(0, tag);
    strength = std::strtof(spec.c_str() + tag + std::strlen(kStrengthTag), nullptr);
  }
  const auto say = [&](const std::string& what) {
    std::fprintf(stderr, "ember: environment: %s (--env)\n", what.c_str());
  };
  const auto number = [](float v) {
    char text[32];
    std::snprintf(text, sizeof text, "%g", double(v));
    return std::string(text);
  };
  const std::string times = strength == 1.0f ? "" : " x " + number(strength);
  if (value == "none" || value == "white") {
    scene.background = Color(value == "white" ? strength : 0.0f);
    scene.environmentMap = nullptr;
    say(value == "none" ? "none, black" : "white, radiance " + number(strength));
    return;
  }
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
    scene.background =
        strength * (numbers.size() == 1 ? Color(numbers[0]) : Color(numbers[0], numbers[1], numbers[2]));
    scene.environmentMap = nullptr;
    say("constant radiance " + value + times);
    return;
  }
  if (numeric)
    throw InputError("--env " + value + ": expected none, white, r,g,b or one number >= 0, or an image file");
  scene.environmentMap = loadEnvironmentMap(value, Color(strength));
  scene.background = Color(0.0f);
  say("map " + value + times);
}

// "90", "90s", "10m", "2h" -> seconds.
double parseDuration(const std::string& text) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  const std::string unit = end ? std::string(end) : "";
  const double scale = unit.empty() || unit == "s" ? 1.0 : unit == "m" ? 60.0 : unit == "h" ? 3600.0 : -1.0;
  if (end == text.c_str() || scale < 0.0 || !std::isfinite(v) || v <= 0.0)
    throw InputError("--time " + text + ": expected a positive duration such as 90s, 10m or 2h");
  return v * scale;
}

// Under MPI every rank keeps its own state: out.ckpt becomes out.r0of2.ckpt, out.r1of2.ckpt, ...
std::string rankFile(const std::string& path, const Cluster& cluster) {
  if (!cluster.distributed() || path.empty()) return path;
  const std::string stem = path.substr(0, path.size() - std::string(".ckpt").size());
  return stem + ".r" + std::to_string(cluster.rank()) + "of" + std::to_string(cluster.size()) + ".ckpt";
}

// The scene and settings of this render, from the command line or from a checkpoint.
struct RenderSetup {
  Scene scene;
  RenderIdentity identity;
  uint64_t firstSample = 0;
  int passSpp = 4;
  std::optional<Checkpoint> resumed;
};

// --until-relerr without --spp: render until the target, up to this many samples per pixel.
constexpr int kUntilRelerrSppCap = 65536;

Scene loadConfigured(const std::string& path, int camera, const std::string& variant, const std::string& env,
                     const std::string& textureFilter) {
  LoadOptions loadOptions;
  loadOptions.camera = camera;
  loadOptions.variant = variant;
  loadOptions.trilinearTextures = textureFilter == "trilinear";
  loadOptions.environmentGiven = !env.empty();
  Scene scene = loadScene(path, loadOptions);
  if (!env.empty()) applyEnvironment(env, scene);
  return scene;
}

RenderSetup setUp(RenderArgs& a) {
  RenderSetup setup;
  if (!a.resume.empty()) {
    // Everything but the output, the target spp and how the work is run comes from the state.
    for (const auto& [given, name] :
         std::vector<std::pair<bool, const char*>>{{!a.scene.empty(), "a scene file"},
                                                   {a.seed.has_value(), "--seed"},
                                                   {a.width.has_value(), "--width"},
                                                   {a.height.has_value(), "--height"},
                                                   {a.maxDepth.has_value(), "--max-depth"},
                                                   {!a.sampler.empty(), "--sampler"},
                                                   {!a.strategy.empty(), "--strategy"},
                                                   {!a.caustics.empty(), "--caustics"},
                                                   {!a.env.empty(), "--env"},
                                                   {a.envStrength.has_value(), "--env-strength"},
                                                   {!a.variant.empty(), "--variant"},
                                                   {!a.textureFilter.empty(), "--texture-filter"},
                                                   {a.camera >= 0, "--camera"},
                                                   {a.firstSample != 0, "--first-sample"},
                                                   {!a.aovs.empty(), "--aov"},
                                                   {a.adaptive, "--adaptive"},
                                                   {a.passSpp.has_value(), "--pass-spp"}})
      if (given)
        throw InputError(std::string("--resume takes the render's settings from its checkpoint; ") + name +
                         " cannot be given with it");
    const Cluster& cluster = Cluster::instance();
    if (cluster.distributed() && a.spp)
      throw InputError("--spp cannot be changed when resuming under MPI: each rank resumes its own share");
    Checkpoint c = readCheckpoint(rankFile(a.resume, cluster));
    // Another version may draw other samples for the same indices: no longer the same render.
    if (c.emberVersion != EMBER_VERSION)
      throw InputError(a.resume + ": written by ember " + c.emberVersion + "; this is ember " +
                       EMBER_VERSION +
                       ", whose samples may differ: resume it with the version that wrote it");
    const RenderIdentity& id = c.identity;
    setup.scene = loadConfigured(id.scene, id.camera, id.variant, id.env, id.textureFilter);
    RenderSettings& s = setup.scene.settings;
    s.width = id.width;
    s.height = id.height;
    s.maxDepth = id.maxDepth;
    s.rrDepth = id.rrDepth;
    s.seed = id.seed;
    s.sampler = id.sampler == "sobol" ? SamplerType::Sobol : SamplerType::Independent;
    s.strategy = parseStrategy(id.strategy).value_or(Strategy::Mis);
    s.traceCaustics = id.caustics == "trace";
    s.spp = a.spp.value_or(c.spp);
    const int held = std::min(c.spp, c.passes * c.passSpp);
    if (s.spp < held)
      throw InputError("--spp " + std::to_string(s.spp) + ": the checkpoint already holds " +
                       std::to_string(held) + " samples per pixel");
    // Pass p always covers samples [p passSpp, (p + 1) passSpp): a render whose last pass was cut
    // short by its spp cannot grow without leaving a gap.
    if (s.spp > held && held % c.passSpp != 0)
      throw InputError("--spp " + std::to_string(s.spp) + ": the checkpoint's last pass ended at its spp (" +
                       std::to_string(held) + ", not a multiple of the pass size " +
                       std::to_string(c.passSpp) + "), so it cannot be extended");
    setup.identity = identityOf(setup.scene, id.scene, id.camera, id.variant, id.env);
    setup.identity.textureFilter = id.textureFilter;
    if (const std::string diff = id.differenceFrom(setup.identity); !diff.empty())
      throw InputError(a.resume + ": the checkpoint no longer matches its scene: " + diff);
    if (a.output.empty()) a.output = c.output;
    setup.firstSample = c.firstSample;
    setup.passSpp = c.passSpp;
    setup.resumed = std::move(c);
    return setup;
  }
  if (a.scene.empty()) throw InputError("a scene file is required (or --resume FILE)");
  if (a.output.empty()) throw InputError("-o/--output is required");
  if (a.envStrength) {
    if (a.env.empty())
      throw InputError("--env-strength scales the --env light; give --env too (e.g. --env white)");
    a.env += kStrengthTag + std::to_string(*a.envStrength);
  }
  if (a.textureFilter == "bilinear") a.textureFilter.clear();  // the samplers' own: the default
  setup.scene = loadConfigured(a.scene, a.camera, a.variant, a.env, a.textureFilter);
  RenderSettings& s = setup.scene.settings;
  if (a.spp)
    s.spp = *a.spp;
  else if (a.untilRelerr)
    s.spp = kUntilRelerrSppCap;
  if (a.seed) s.seed = *a.seed;
  if (a.width) s.width = *a.width;
  if (a.height) s.height = *a.height;
  if (a.maxDepth) s.maxDepth = *a.maxDepth;
  if (a.sampler == "sobol") s.sampler = SamplerType::Sobol;
  if (a.sampler == "independent") s.sampler = SamplerType::Independent;
  if (!a.strategy.empty()) s.strategy = *parseStrategy(a.strategy);  // CLI11 checked the name
  if (!a.caustics.empty()) s.traceCaustics = a.caustics == "trace";
  setup.identity = identityOf(setup.scene, a.scene, a.camera, a.variant, a.env);
  setup.identity.textureFilter = a.textureFilter;
  setup.firstSample = a.firstSample;
  setup.passSpp = a.passSpp.value_or(4);
  return setup;
}

int runRender(RenderArgs a) {
  using Clock = std::chrono::steady_clock;
  const Cluster& cluster = Cluster::instance();
  StopSignals signals;
  const auto loadStart = Clock::now();
  if (!a.output.empty()) checkOutputPath(a.output, ".exr", "-o");
  if (!a.png.empty()) checkOutputPath(a.png, ".png", "--png");
  if (!a.variance.empty()) checkOutputPath(a.variance, ".exr", "--variance");
  if (!a.checkpoint.empty()) checkOutputPath(a.checkpoint, ".ckpt", "--checkpoint");
  const double budget = a.time.empty() ? 0.0 : parseDuration(a.time);
  // Before any work: a denoised render needs the library, and says so with nothing written.
  if (std::string why; a.denoise && !denoiserAvailable(why)) throw InputError("--denoise: " + why);

  RenderSetup setup = setUp(a);
  checkOutputPath(a.output, ".exr", "-o");
  Scene& scene = setup.scene;
  const RenderSettings& s = scene.settings;
  std::string aovError;
  AovSet aovs = setup.resumed    ? setup.resumed->film.aovs()
                : a.aovs.empty() ? AovSet{}
                                 : parseAovs(a.aovs, aovError).value();  // CLI11 checked it
  if (a.denoise && !setup.resumed) {                                     // the denoiser's guides
    aovs.add(Aov::Albedo);
    aovs.add(Aov::Normal);
  }
  if (a.adaptive && !setup.resumed) aovs.add(Aov::Spp);  // each pixel's own count, which merge weighs by
  scene.uvOnEveryHit = aovs.has(Aov::Uv);
  scene.build();
  if (a.packetWidth != "auto") scene.setPacketWidth(unsigned(std::stoi(a.packetWidth)));
  if (const std::string w = unreachableLightsWarning(scene, s.strategy); !w.empty())
    std::fprintf(stderr, "ember: warning: %s\n", w.c_str());
  const double loadSeconds = std::chrono::duration<double>(Clock::now() - loadStart).count();

  const std::unique_ptr<Integrator> integrator = makeIntegrator(s, *parseKernel(a.kernel));
  Film film = setup.resumed ? std::move(setup.resumed->film) : Film(s.width, s.height, aovs);
  // This process's samples: all of them, or under MPI its rank's share of every pixel's (a resumed
  // rank's share is in its own checkpoint).
  uint64_t first = setup.firstSample;
  int spp = s.spp;
  if (cluster.distributed() && !setup.resumed) {
    const Cluster::Share share = cluster.shareOf(s.spp);
    first += share.offset;
    spp = share.count;
  } else if (setup.resumed) {
    first = setup.resumed->firstSample;
    spp = a.spp.value_or(setup.resumed->spp);
  }
  RenderOptions options;
  options.spp = spp;
  options.seed = s.seed;
  options.threads = a.threads.value_or(0);
  options.firstSample = first;
  options.sampler = s.sampler;
  options.progress = !a.quiet && cluster.isRoot();
  options.passSpp = setup.passSpp;
  options.passesDone = setup.resumed ? setup.resumed->passes : 0;
  options.stop = &signals.flag();
  options.timeBudgetSeconds = budget;
  if (a.untilRelerr) {
    // Each rank holds only its share of every pixel's samples: none could judge the whole.
    if (cluster.distributed() && !a.adaptive)
      throw InputError("--until-relerr cannot be used under MPI without --adaptive");
    options.targetRelativeError = *a.untilRelerr;
  }
  if (a.adaptive) {
    if (!a.untilRelerr)
      throw InputError("--adaptive needs --until-relerr X: the relative error the image is to reach");
    options.adaptive = true;
    // Under MPI each rank samples its own share adaptively, from its own pilot, to X sqrt(ranks):
    // the ranks' independent images average to about X (docs/aovs.md).
    if (cluster.distributed()) options.targetRelativeError *= std::sqrt(double(cluster.size()));
  } else if (setup.resumed && setup.resumed->adaptiveTarget > 0.0) {  // the checkpoint's settings
    if (a.untilRelerr)
      throw InputError("--until-relerr: the checkpoint samples adaptively to " +
                       std::to_string(setup.resumed->adaptiveTarget) + "; resume it without");
    options.adaptive = true;
    options.targetRelativeError = setup.resumed->adaptiveTarget;
    options.adaptivePilotSpp = setup.resumed->adaptivePilotSpp;
  }

  Checkpoint state;
  state.identity = setup.identity;
  state.firstSample = first;
  state.spp = spp;
  state.passSpp = setup.passSpp;
  state.output = a.output;
  state.emberVersion = EMBER_VERSION;
  if (options.adaptive) {
    state.adaptiveTarget = options.targetRelativeError;
    state.adaptivePilotSpp = options.adaptivePilotSpp;
  }
  const std::string checkpointPath = rankFile(!a.checkpoint.empty() ? a.checkpoint : a.resume, cluster);
  const bool checkpointing = !a.checkpoint.empty() || (!a.resume.empty() && a.checkpointEvery > 0);
  auto saveState = [&](const Film& f, int passes) {
    state.passes = passes;
    // The film is copied into the state only for the write; the render is paused meanwhile.
    state.film = f;
    writeCheckpoint(checkpointPath, state);
  };
  auto lastSave = Clock::now();
  if (checkpointing)
    options.onPass = [&](const Film& f, int passes) {
      if (std::chrono::duration<double>(Clock::now() - lastSave).count() < a.checkpointEvery) return;
      if (!filteredTextureFailure().empty()) return;  // never a checkpoint with black lookups
      saveState(f, passes);
      lastSave = Clock::now();
    };
  const RenderStats stats = render(scene, *integrator, options, film);
  // A texture file that vanished mid-render made some lookups black: nothing is written, on any
  // rank.
  if (const std::string failure = filteredTextureFailure(); cluster.any(!failure.empty()))
    throw InputError(failure.empty() ? "another MPI rank's texture lookups failed during the render"
                                     : failure);
  if (checkpointing) saveState(film, stats.passes);
  // Rank 0 gathers the other ranks' sums; only it writes images and reports.
  const bool interrupted = cluster.any(stats.interrupted);
  const int sppDone = int(cluster.sum(uint64_t(stats.sppDone)));
  cluster.reduceToRoot(film);
  if (!cluster.isRoot()) return interrupted ? 128 + (signals.signal() ? signals.signal() : SIGTERM) : 0;

  Metadata meta{{"ember:scene", setup.identity.scene},
                {"ember:scene_hash", hexHash(setup.identity.hash())},
                {"ember:spp", std::to_string(sppDone)},
                {"ember:spp_requested", std::to_string(s.spp)},
                {"ember:passes", std::to_string(stats.passes)},
                {"ember:seed", std::to_string(s.seed)},
                {"ember:sampler", s.sampler == SamplerType::Sobol ? "sobol" : "independent"},
                {"ember:strategy", std::string(strategyName(s.strategy))},
                {"ember:caustics", setup.identity.caustics},
                {"ember:max_depth", std::to_string(s.maxDepth)},
                {"ember:rr_depth", std::to_string(s.rrDepth)},
                {"ember:first_sample", std::to_string(setup.firstSample)},
                {"ember:render_seconds", std::to_string(stats.seconds)},
                {"ember:version", EMBER_VERSION},
                {"DateTime", isoTime()},
                {"Software", std::string("ember ") + EMBER_VERSION}};
  if (!film.aovs().empty()) meta.push_back({"ember:aovs", aovList(film.aovs())});
  if (a.untilRelerr) meta.push_back({"ember:until_relerr", std::to_string(*a.untilRelerr)});
  if (options.adaptive) meta.push_back({"ember:adaptive", std::to_string(options.targetRelativeError)});
  if (options.targetRelativeError > 0.0)
    meta.push_back({"ember:relerr", std::to_string(stats.relativeError)});
  if (sppDone > 0) {
    Image image = film.mean();
    std::vector<ImageLayer> layers = film.aovLayers();
    if (a.denoise) {
      const auto denoiseStart = Clock::now();
      std::vector<ImageLayer> withNoisy = layers;
      withNoisy.insert(withNoisy.begin(), ImageLayer{{"noisy.R", "noisy.G", "noisy.B"}, image.rgb});
      try {
        image.rgb = denoise(denoiseInput(image, withNoisy), DenoiseOptions{a.threads.value_or(0), true});
      } catch (const DenoiseError& e) {
        // The render is not thrown away: its noisy image is written, and `ember denoise` can retry.
        writeExr(a.output, image, layers, meta);
        throw InputError(std::string(e.what()) + " (the render's noisy image was written to " + a.output +
                         "; denoise it with ember denoise)");
      }
      layers = std::move(withNoisy);
      const double seconds = std::chrono::duration<double>(Clock::now() - denoiseStart).count();
      meta.push_back({"ember:denoiser", denoiserDescription(layers)});
      std::fprintf(stderr, "ember: denoised in %.3f s (%s)\n", seconds, oidnLibraryPath().c_str());
      if (!film.aovs().has(Aov::Albedo))
        std::fprintf(stderr,
                     "ember: warning: the checkpoint has no albedo or normal layers: denoised from the "
                     "colour alone\n");
    }
    writeExr(a.output, image, layers, meta);
    if (!a.variance.empty()) writeExr(a.variance, film.varianceOfMean(), meta);
    if (!a.png.empty()) {
      const ReinhardResult tm = tonemapReinhard(image, ReinhardParams{});
      writePng(a.png, image.width, image.height, tm.rgb8);
    }
  }

  const double secs = std::max(stats.seconds, 1e-9);
  const uint64_t rays = stats.paths.rays + stats.paths.shadowRays;
  std::fprintf(stderr,
               "ember: %dx%d, %d spp, %d threads: load+build %.3f s, render %.3f s, %.3f M samples/s, "
               "%.3f M rays/s (%.3f M closest-hit + %.3f M shadow), %llu non-finite samples dropped -> %s\n",
               s.width, s.height, sppDone, stats.threads, loadSeconds, stats.seconds,
               double(stats.samples) / secs * 1e-6, double(rays) / secs * 1e-6,
               double(stats.paths.rays) / secs * 1e-6, double(stats.paths.shadowRays) / secs * 1e-6,
               static_cast<unsigned long long>(stats.nonFinite),
               sppDone > 0 ? a.output.c_str() : "(no pass completed: no image written)");
  if (cluster.distributed())
    std::fprintf(stderr, "ember: %d MPI ranks, each rendering its share of every pixel's samples\n",
                 cluster.size());
  if (stats.outOfTime)
    std::fprintf(stderr, "ember: --time %s: stopped after %d of %d spp\n", a.time.c_str(), sppDone, s.spp);
  if (options.adaptive && !film.budgets().empty()) {
    const auto [fewest, most] = std::minmax_element(film.counts().begin(), film.counts().end());
    double total = 0.0;
    for (uint32_t n : film.counts()) total += n;
    std::fprintf(stderr, "ember: --adaptive: pixels took %u to %u samples, %.1f on average\n", *fewest, *most,
                 total / double(film.pixelCount()));
  }
  if (a.untilRelerr && !interrupted)
    std::fprintf(stderr, "ember: --until-relerr %g: %s %.4g at %d spp\n", *a.untilRelerr,
                 stats.converged ? "reached" : "not reached, estimated relative error", stats.relativeError,
                 sppDone);
  if (interrupted) {
    const std::string resume = !a.checkpoint.empty() ? a.checkpoint : a.resume;
    std::fprintf(stderr, "ember: interrupted after %d of %d spp%s\n", sppDone, s.spp,
                 checkpointing ? ("; resume with: ember render --resume " + resume).c_str() : "");
    return 128 + (signals.signal() ? signals.signal() : SIGTERM);
  }
  return 0;
}

}  // namespace

Runner addRenderCommand(CLI::App& app) {
  auto args = std::make_shared<RenderArgs>();
  CLI::App* cmd =
      app.add_subcommand("render", "Render a scene (Ember JSON, .gltf or .glb) to a linear float EXR");
  cmd->add_option("scene", args->scene,
                  "Scene file: Ember JSON (docs/scene-format.md), .gltf or .glb (not with --resume)");
  cmd->add_option("-o,--output", args->output,
                  "Output EXR (linear float32 RGB), written atomically (with --resume: default the "
                  "checkpoint's)");
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
  cmd->add_option("--caustics", args->caustics,
                  "How caustics (light through mirrors and glass onto diffuse surfaces) are estimated, both "
                  "unbiased: trace (light paths from the area lights towards the specular objects, connected "
                  "to the camera: far less noise; the default) or path (the path tracer alone); default: the "
                  "scene's render.caustic_tracing")
      ->check(CLI::IsMember({"trace", "path"}));
  cmd->add_option(
         "--kernel", args->kernel,
         "How paths are traced, both giving the same image: wave (the default: a tile's paths advance "
         "together, rays cast as Embree packets, the bounce's state in arrays and vector kernels) or "
         "scalar (one ray at a time, the reference); lanes and wavefront are old names of wave")
      ->check(CLI::IsMember({"wave", "scalar", "lanes", "wavefront"}));
  cmd->add_option(
         "--packet-width", args->packetWidth,
         "Rays per packet of the wave kernel: auto (the default: 16 where Embree "
         "traverses 16-ray packets natively, as with AVX-512, else 8), 8 or 16; the image is the same")
      ->check(CLI::IsMember({"auto", "8", "16"}));
  cmd->add_option("--env", args->env,
                  "Environment light: none, white, r,g,b (or one number) for a constant colour, or an "
                  "equirectangular EXR/HDR map; replaces the scene's or the default one");
  cmd->add_option("--env-strength", args->envStrength, "Multiplies the --env light (default 1)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--until-relerr", args->untilRelerr,
                  "Stop once the image's estimated relative error (the root of the relMSE it is expected to "
                  "have against its converged self, from the per-pixel variance) is at most this, checked "
                  "before every pass; --spp is then the most it may take (default 65536). The EXR records "
                  "the estimate (ember:relerr)")
      ->check(CLI::Validator(
          [](std::string& v) {
            // CLI::PositiveNumber lets "nan" through, and a NaN target would never be reached.
            char* end = nullptr;
            const double d = std::strtod(v.c_str(), &end);
            return end != v.c_str() && *end == '\0' && std::isfinite(d) && d > 0.0
                       ? std::string()
                       : "expected a positive number, got '" + v + "'";
          },
          "POSITIVE"));
  cmd->add_option("--aov", args->aovs,
                  std::string("Also write these layers into the EXR, comma-separated (docs/aovs.md): ") +
                      kAovNames + "; or all. Albedo and normal are the denoiser's guides")
      ->check(CLI::Validator(
          [](std::string& v) {
            std::string error;
            return parseAovs(v, error) ? std::string() : error;
          },
          "LIST"));
  cmd->add_flag(
      "--adaptive", args->adaptive,
      "With --until-relerr X: sample each pixel until its own relative error is about X (a budget "
      "from its neighbours' first 16 samples, which keeps every pixel unbiased; renderer/adaptive.h); "
      "the spp layer records each pixel's count");
  cmd->add_flag(
      "--denoise", args->denoise,
      "Denoise the image with Intel Open Image Denoise, guided by the albedo and normal AOVs (added "
      "to --aov); the noisy image stays in the EXR as the layer noisy.R/G/B. Needs the OIDN 2 "
      "library (scripts/setup-deps.sh installs it; docs/aovs.md)");
  cmd->add_option("--texture-filter", args->textureFilter,
                  "glTF files: how their images are filtered: bilinear (the default; nearest where a sampler "
                  "asks) or trilinear (MIP-mapped over each hit's pixel footprint through OpenImageIO: less "
                  "aliasing at low sample counts, a little blur)")
      ->check(CLI::IsMember({"bilinear", "trilinear"}));
  cmd->add_option("--variant", args->variant,
                  "glTF files: render the materials of this KHR_materials_variants variant (`ember info` "
                  "lists them)");
  cmd->add_option("--camera", args->camera,
                  "glTF files: render through camera N of the file's `cameras` (default: the first one a "
                  "node places, else a camera framing the scene)")
      ->check(CLI::Range(0, 1 << 20));
  cmd->add_option("--variance", args->variance, "Also write the per-pixel variance of the mean as an EXR");
  cmd->add_flag("-q,--quiet", args->quiet, "No progress display (the summary line is still printed)");
  cmd->add_option("--pass-spp", args->passSpp,
                  "Samples per pixel per progressive pass (default 4); the image is the same for any value")
      ->check(CLI::Range(1, 1 << 24));
  cmd->add_option("--checkpoint", args->checkpoint,
                  "Save the render's state to this .ckpt file (atomically, every --checkpoint-every seconds, "
                  "on SIGINT/SIGTERM and at the end) for --resume");
  cmd->add_option("--checkpoint-every", args->checkpointEvery, "Seconds between checkpoints (default 60)")
      ->check(CLI::Range(0.0, 1e9));
  cmd->add_option("--resume", args->resume,
                  "Continue the render saved in this checkpoint to its spp (or --spp); the image is "
                  "bit-identical to an uninterrupted render. Keeps checkpointing to the same file");
  cmd->add_option("--time", args->time,
                  "Time budget (90s, 10m, 2h): no pass starts that would not end within it; the EXR "
                  "records the spp reached");
  return [args] { return runRender(*args); };
}

}  // namespace ember::cli
