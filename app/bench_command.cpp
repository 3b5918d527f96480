// `ember bench`: load, build and render scenes K times and report throughput. Measures only; the
// test suite never times anything. The JSON layout is documented in docs/performance.md.
#include "app/commands.h"

#include "io/input_error.h"
#include "io/scene_loader.h"
#include "packet/wave_integrator.h"
#include "renderer/path_phases.h"
#include "renderer/render.h"

#include <sys/resource.h>
#include <tbb/info.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>

namespace ember::cli {

namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

std::string cpuModel() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("model name", 0) == 0) return line.substr(line.find(':') + 2);
  return "unknown";
}

double peakResidentMb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return double(usage.ru_maxrss) / 1024.0;  // Linux reports kilobytes
}

// Resident memory that is the process's own (heap, stacks, Embree's BVH), without the pages of
// shared libraries, whose touched pages count in RSS before main() runs and are shared with every
// other process that uses them.
double anonymousResidentMb() {
  std::ifstream in("/proc/self/status");
  std::string key;
  while (in >> key) {
    if (key == "RssAnon:") {
      double kb = 0.0;
      in >> kb;
      return kb / 1024.0;
    }
    in.ignore(1 << 12, '\n');
  }
  return 0.0;
}

struct BenchArgs {
  std::vector<std::string> scenes;
  std::optional<int> spp;
  int threads = 0;
  int repeat = 3;
  std::string json;
  std::string kernel = "wave";
  std::string packetWidth = "auto";
  bool phases = false;
  std::string caustics;  // "trace", "path", or empty: each scene's render.caustic_tracing
};

int runBench(const BenchArgs& a) {
  std::vector<std::string> scenes = a.scenes;
  if (scenes.empty())
    for (const char* s : {"cornell-area", "cornell-point", "shapes", "textured"})
      scenes.push_back(std::string("scenes/") + s + ".json");

  nlohmann::json report;
  report["ember_version"] = EMBER_VERSION;
  report["build"] = {{"type", EMBER_BUILD_TYPE},
                     {"cxx_flags", EMBER_CXX_FLAGS},
                     {"compiler", EMBER_COMPILER},
                     {"lto", bool(EMBER_LTO_BUILD)},
                     {"pgo", bool(EMBER_PGO_BUILD)}};
  report["machine"] = {{"cpu", cpuModel()}, {"cores", tbb::info::default_concurrency()}};
  report["threads"] = a.threads > 0 ? a.threads : tbb::info::default_concurrency();
  report["repeat"] = a.repeat;
  report["kernel"] = a.kernel;
  report["scenes"] = nlohmann::json::array();

  std::printf("%-22s %7s %5s %8s %8s %9s %10s %10s %10s %10s %9s %8s %8s\n", "scene", "spp", "thr", "load s",
              "build s", "render s", "Msamples/s", "Mverts/s", "Mrays/s", "Mshadow/s", "nonfinite", "peak MB",
              "anon MB");
  for (const std::string& path : scenes) {
    const auto loadStart = Clock::now();
    Scene scene = loadScene(path);
    const double loadSeconds = secondsSince(loadStart);
    if (a.spp) scene.settings.spp = *a.spp;
    if (!a.caustics.empty()) scene.settings.traceCaustics = a.caustics == "trace";
    const auto buildStart = Clock::now();
    scene.build();
    const double buildSeconds = secondsSince(buildStart);
    report["machine"]["native_packet_width"] = scene.accel().packetWidth();
    if (a.packetWidth != "auto") scene.setPacketWidth(unsigned(std::stoi(a.packetWidth)));
    report["packet_width"] = scene.accel().packetWidth();
    if (const std::string w = unreachableLightsWarning(scene, scene.settings.strategy); !w.empty())
      std::fprintf(stderr, "ember: warning: %s: %s\n", path.c_str(), w.c_str());
    report["machine"]["isa"] = scene.accel().isaName();

    const std::unique_ptr<Integrator> integrator = makeIntegrator(scene.settings, *parseKernel(a.kernel));
    RenderOptions options;
    options.spp = scene.settings.spp;
    options.seed = scene.settings.seed;
    options.sampler = scene.settings.sampler;
    options.threads = a.threads;
    options.timePhases = a.phases;
    std::vector<RenderStats> runs;
    double anonymousMb = 0.0;
    for (int k = 0; k < a.repeat; ++k) {
      Film film(scene.settings.width, scene.settings.height);
      runs.push_back(render(scene, *integrator, options, film));
      anonymousMb = std::max(anonymousMb, anonymousResidentMb());  // scene, BVH and film alive
    }
    nlohmann::json secondsInRunOrder = nlohmann::json::array();
    for (const RenderStats& r : runs) secondsInRunOrder.push_back(r.seconds);
    std::sort(runs.begin(), runs.end(),
              [](const RenderStats& x, const RenderStats& y) { return x.seconds < y.seconds; });
    const RenderStats& med = runs[runs.size() / 2];
    const double s = std::max(med.seconds, 1e-9);
    nlohmann::json row = {
        {"scene", path},
        {"width", scene.settings.width},
        {"height", scene.settings.height},
        {"spp", options.spp},
        {"caustics", integrator->tracesCaustics() && scene.causticTracer().enabled() ? "trace" : "path"},
        {"threads", med.threads},
        {"load_seconds", loadSeconds},
        {"build_seconds", buildSeconds},
        {"render_seconds_median", med.seconds},
        {"render_seconds_all", secondsInRunOrder},
        {"samples_per_second", double(med.samples) / s},
        {"path_vertices_per_second", double(med.paths.vertices) / s},
        {"closest_hit_rays_per_second", double(med.paths.rays) / s},
        {"shadow_rays_per_second", double(med.paths.shadowRays) / s},
        {"rays_per_second", double(med.paths.rays + med.paths.shadowRays) / s},
        {"nonfinite_samples", med.nonFinite},
        // Traversal on Ember's own rays (the batched kernels time their batches' trace calls):
        // its thread-seconds, and its share of the render's thread-seconds. 0 for --kernel scalar.
        {"trace_seconds", double(med.paths.traceNanoseconds) * 1e-9},
        {"trace_share", double(med.paths.traceNanoseconds) * 1e-9 / (s * med.threads)},
        {"peak_resident_mb", peakResidentMb()},
        {"anonymous_resident_mb", anonymousMb},
    };
    if (a.phases) {
      nlohmann::json phases = nlohmann::json::object();
      for (size_t i = 0; i < kPathPhases; ++i)
        phases[std::string(kPathPhaseNames[i])] = double(med.paths.phaseNanoseconds[i]) * 1e-9;
      row["phase_seconds"] = phases;
    }
    report["scenes"].push_back(row);
    std::printf(
        "%-22s %7d %5d %8.3f %8.3f %9.3f %10.3f %10.3f %10.3f %10.3f %9llu %8.1f %8.1f\n",
        std::filesystem::path(path).stem().string().c_str(), options.spp, med.threads, loadSeconds,
        buildSeconds, med.seconds, double(med.samples) / s * 1e-6, double(med.paths.vertices) / s * 1e-6,
        double(med.paths.rays + med.paths.shadowRays) / s * 1e-6, double(med.paths.shadowRays) / s * 1e-6,
        static_cast<unsigned long long>(med.nonFinite), peakResidentMb(), anonymousMb);
    std::fflush(stdout);
  }
  std::printf("machine: %s, %d cores, Embree ISA %s; ember %s (%s%s%s)\n", cpuModel().c_str(),
              tbb::info::default_concurrency(), report["machine"].value("isa", "?").c_str(), EMBER_VERSION,
              EMBER_BUILD_TYPE, EMBER_LTO_BUILD ? ", LTO" : "", EMBER_PGO_BUILD ? ", PGO" : "");
  if (!a.json.empty()) {
    // Temporary file, then rename, like every other output of ember.
    const std::string tmp = a.json + ".tmp";
    {
      std::ofstream out(tmp);
      if (!out) throw InputError(a.json + ": cannot write");
      out << report.dump(2) << "\n";
      if (!out) throw InputError(a.json + ": write failed");
    }
    std::filesystem::rename(tmp, a.json);
  }
  return 0;
}

}  // namespace

Runner addBenchCommand(CLI::App& app) {
  auto args = std::make_shared<BenchArgs>();
  CLI::App* cmd =
      app.add_subcommand("bench", "Measure load, build and render throughput (samples/s, rays/s) on scenes");
  cmd->add_option("scenes", args->scenes, "Scene files (default: the four shared scenes in scenes/)");
  cmd->add_option("--spp", args->spp, "Samples per pixel (default: each scene's own)")
      ->check(CLI::Range(1, 1 << 24));
  cmd->add_option("--threads", args->threads, "Worker threads (default: all cores)")
      ->check(CLI::Range(1, 4096));
  cmd->add_option("--repeat", args->repeat, "Renders per scene; the median is reported (default 3)")
      ->check(CLI::Range(1, 1000));
  cmd->add_option("--kernel", args->kernel, "wave (default) or scalar; see `ember render --help`")
      ->check(CLI::IsMember({"wave", "scalar", "lanes", "wavefront"}));
  cmd->add_option("--packet-width", args->packetWidth,
                  "auto (default), 8 or 16 rays per packet; see `ember render --help`")
      ->check(CLI::IsMember({"auto", "8", "16"}));
  cmd->add_option(
         "--caustics", args->caustics,
         "trace or path, as `ember render --caustics` (default: each scene's render.caustic_tracing)")
      ->check(CLI::IsMember({"trace", "path"}));
  cmd->add_flag("--phases", args->phases,
                "Also time the batched kernels' bounce step by step (phase_seconds in the JSON; a few "
                "clock reads per bounce)");
  cmd->add_option("--json", args->json, "Also write the results as JSON (layout: docs/performance.md)");
  return [args] { return runBench(*args); };
}

}  // namespace ember::cli
