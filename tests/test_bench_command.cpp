// `ember bench` as a user runs it: the JSON report's layout (docs/performance.md, "ember bench
// --json"), which tells builds apart, and bad input.
#include "renderer/path_phases.h"
#include "tests/cli_runner.h"
#include "tests/test_paths.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <string>

namespace ember {
namespace {

// The report's one scene, of `ember bench` on cornell-point at 1 thread with `flags` (the report
// written in `dir` as `name`).
nlohmann::json benchCornellPoint(const test::TempDir& dir, const std::string& name,
                                 const std::string& flags) {
  const std::string out = dir.file(name);
  const test::CliResult r = test::runEmber("bench '" + test::sourcePath("scenes/cornell-point.json") +
                                           "' --repeat 1 --threads 1 " + flags + " --json '" + out + "'");
  EXPECT_EQ(r.exitCode, 0) << r.output;
  std::ifstream in(out);
  return nlohmann::json::parse(in).at("scenes")[0];
}

TEST(BenchCommand, JsonReportsTheBuildAndTheRates) {
  test::TempDir dir;
  const std::string out = dir.file("bench.json");
  const test::CliResult r = test::runEmber("bench '" + test::sourcePath("scenes/cornell-point.json") +
                                           "' --spp 1 --repeat 2 --threads 1 --json '" + out + "'");
  ASSERT_EQ(r.exitCode, 0) << r.output;
  std::ifstream in(out);
  const nlohmann::json report = nlohmann::json::parse(in);

  const nlohmann::json& build = report.at("build");
  EXPECT_TRUE(build.at("type").is_string());
  EXPECT_TRUE(build.at("compiler").is_string());
  EXPECT_TRUE(build.at("lto").is_boolean());
  EXPECT_TRUE(build.at("pgo").is_boolean());
  EXPECT_EQ(report.at("threads"), 1);
  EXPECT_EQ(report.at("repeat"), 2);

  ASSERT_EQ(report.at("scenes").size(), 1u);
  const nlohmann::json& scene = report.at("scenes")[0];
  EXPECT_EQ(scene.at("spp"), 1);
  EXPECT_EQ(scene.at("width"), 256);
  EXPECT_EQ(scene.at("render_seconds_all").size(), 2u);
  for (const char* rate : {"samples_per_second", "path_vertices_per_second", "closest_hit_rays_per_second",
                           "shadow_rays_per_second", "rays_per_second"})
    EXPECT_GT(scene.at(rate).get<double>(), 0.0) << rate;
  EXPECT_EQ(scene.at("nonfinite_samples"), 0);
}

// trace_seconds and trace_share: the batched kernels time their batches' trace calls, which are
// a part of the render and never all of it; the scalar kernel, one ray per call, times none.
TEST(BenchCommand, TraceShareComesFromTheBatchedKernels) {
  test::TempDir dir;
  for (const std::string kernel : {"wave", "scalar"}) {
    const nlohmann::json scene = benchCornellPoint(dir, kernel + ".json", "--spp 2 --kernel " + kernel);
    const double seconds = scene.at("trace_seconds"), share = scene.at("trace_share");
    if (kernel == "scalar") {
      EXPECT_EQ(seconds, 0.0);
      EXPECT_EQ(share, 0.0);
    } else {
      EXPECT_GT(seconds, 0.0) << kernel;
      EXPECT_LT(seconds, scene.at("render_seconds_median").get<double>()) << kernel;
      EXPECT_GT(share, 0.0) << kernel;
      EXPECT_LT(share, 1.0) << kernel;
    }
  }
}

// --phases: every step of the bounce is timed, the steps together are most of the render and never
// more, and the two trace steps contain the trace calls that trace_seconds times. Without the flag
// the report has no phases.
TEST(BenchCommand, PhasesAddUpToTheRender) {
  test::TempDir dir;
  // Path-traced caustics: the phases time the path tracer's bounce, not the light tracer's waves.
  const nlohmann::json scene = benchCornellPoint(dir, "phases.json", "--spp 2 --phases --caustics path");
  const nlohmann::json& phases = scene.at("phase_seconds");
  ASSERT_EQ(phases.size(), kPathPhases);
  double sum = 0.0;
  for (const std::string_view name : kPathPhaseNames) {
    const double seconds = phases.at(std::string(name));
    EXPECT_GT(seconds, 0.0) << name;
    sum += seconds;
  }
  const double render = scene.at("render_seconds_median");
  EXPECT_LE(sum, render);
  EXPECT_GT(sum, 0.5 * render);
  EXPECT_GE(phases.at("trace_closest").get<double>() + phases.at("trace_shadows").get<double>(),
            scene.at("trace_seconds").get<double>());

  EXPECT_FALSE(benchCornellPoint(dir, "plain.json", "--spp 1").contains("phase_seconds"));
}

// --packet-width: the report says the width the render used, whatever this machine's native one
// is; a width Embree has no packets of is refused before anything runs.
TEST(BenchCommand, PacketWidthReachesTheReport) {
  test::TempDir dir;
  for (const int width : {8, 16}) {
    const std::string out = dir.file("bench" + std::to_string(width) + ".json");
    const test::CliResult r = test::runEmber("bench '" + test::sourcePath("scenes/cornell-point.json") +
                                             "' --spp 1 --repeat 1 --packet-width " + std::to_string(width) +
                                             " --json '" + out + "'");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    std::ifstream in(out);
    const nlohmann::json report = nlohmann::json::parse(in);
    EXPECT_EQ(report.at("packet_width"), width);
    const int native = report.at("machine").at("native_packet_width");
    EXPECT_TRUE(native == 8 || native == 16) << native;
  }
  const test::CliResult bad =
      test::runEmber("bench '" + test::sourcePath("scenes/cornell-point.json") +
                     "' --spp 1 --packet-width 4 --json '" + dir.file("no.json") + "'");
  EXPECT_NE(bad.exitCode, 0);
  EXPECT_NE(bad.output.find("--packet-width"), std::string::npos) << bad.output;
  EXPECT_FALSE(std::filesystem::exists(dir.file("no.json")));
}

TEST(BenchCommand, MissingSceneNamesItAndWritesNoReport) {
  test::TempDir dir;
  const std::string out = dir.file("bench.json");
  const test::CliResult r =
      test::runEmber("bench '" + dir.file("absent.json") + "' --spp 1 --json '" + out + "'");
  EXPECT_NE(r.exitCode, 0);
  EXPECT_NE(r.output.find("absent.json"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(out));
}

}  // namespace
}  // namespace ember
