// `mpirun -np N ember render`: every rank renders its share of each pixel's samples and rank 0
// writes the sum. The image must equal the single-process render to float rounding (the ranks'
// partial sums are added in rank order, so only the association of the additions differs), with
// an uneven split too; a rank that dies must fail the job, name the rank and leave no image.
#include "io/image_io.h"

#include <gtest/gtest.h>

#include "cli_runner.h"
#include "test_paths.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace ember {
namespace {

const std::string kScene = test::sourcePath("scenes/cornell-area.json");
const std::string kSettings = " --width 48 --height 40 --spp 10 --threads 1 -q";

std::string mpirun(int ranks) {
  return std::string(EMBER_MPIEXEC) + " --oversubscribe --allow-run-as-root -np " + std::to_string(ranks) +
         " ";
}

test::CliResult runShell(const std::string& cmd) {
  const std::string log = (std::filesystem::temp_directory_path() / "ember_mpi_test.log").string();
  const int status = std::system((cmd + " >'" + log + "' 2>&1").c_str());
  test::CliResult r;
  r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  std::ifstream in(log);
  r.output.assign(std::istreambuf_iterator<char>(in), {});
  return r;
}

double worstRelativeDifference(const Image& a, const Image& b) {
  double worst = 0.0;
  for (size_t i = 0; i < a.rgb.size(); ++i)
    worst =
        std::max(worst, std::abs(double(a.rgb[i]) - b.rgb[i]) / std::max(1e-3, double(std::abs(b.rgb[i]))));
  return worst;
}

std::string metadata(const std::string& path, const std::string& key) {
  for (const auto& [k, v] : readStringMetadata(path))
    if (k == key) return v;
  return "";
}

TEST(Mpi, TwoAndThreeRanksGiveTheSingleProcessImage) {
  test::TempDir dir;
  const std::string one = dir.file("one.exr");
  ASSERT_EQ(test::runEmber("render '" + kScene + "' -o '" + one + "'" + kSettings).exitCode, 0);
  const Image reference = readImageRgb(one);
  for (int ranks : {2, 3}) {  // 10 spp over 3 ranks: 4 + 3 + 3, an uneven split
    const std::string out = dir.file("np" + std::to_string(ranks) + ".exr");
    const test::CliResult r = runShell(mpirun(ranks) + "'" + EMBER_BINARY + "' render '" + kScene + "' -o '" +
                                       out + "'" + kSettings);
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find(std::to_string(ranks) + " MPI ranks"), std::string::npos) << r.output;
    const Image image = readImageRgb(out);
    ASSERT_EQ(image.rgb.size(), reference.rgb.size());
    EXPECT_LT(worstRelativeDifference(image, reference), 1e-6) << ranks << " ranks";
    EXPECT_EQ(metadata(out, "ember:spp"), "10");
    // Only rank 0 reports: its summary and the ranks line.
    size_t lines = 0;
    for (size_t at = r.output.find("ember: "); at != std::string::npos; at = r.output.find("ember: ", at + 1))
      ++lines;
    EXPECT_EQ(lines, 2u) << r.output;
  }
}

// The AOV layers are sums like the colour's: the ranks' add up to the single process's.
TEST(Mpi, AovLayersEqualTheSingleProcessOnes) {
  test::TempDir dir;
  const std::string one = dir.file("one.exr"), two = dir.file("two.exr");
  ASSERT_EQ(test::runEmber("render '" + kScene + "' -o '" + one + "'" + kSettings + " --aov all").exitCode,
            0);
  const test::CliResult r = runShell(mpirun(2) + "'" + EMBER_BINARY + "' render '" + kScene + "' -o '" + two +
                                     "'" + kSettings + " --aov all");
  ASSERT_EQ(r.exitCode, 0) << r.output;
  const ExrChannels a = readExrChannels(one), b = readExrChannels(two);
  ASSERT_EQ(a.channels.size(), b.channels.size());
  EXPECT_TRUE(a.has("albedo.R") && a.has("N.X") && a.has("Z") && a.has("spp"));
  for (const auto& [name, values] : a.channels) {
    ASSERT_TRUE(b.has(name)) << name;
    const std::vector<float>& other = b.channels.at(name);
    for (size_t i = 0; i < values.size(); ++i) {
      if (!std::isfinite(values[i])) {
        EXPECT_EQ(values[i], other[i]) << name;
        continue;
      }
      // The variance of the mean is a difference of sums: its rounding is relative to the sums.
      const double tolerance = name.rfind("variance.", 0) == 0 ? 1e-4 : 1e-6;
      ASSERT_NEAR(other[i], values[i], tolerance * std::max(1.0, double(std::abs(values[i]))))
          << name << " " << i;
    }
  }
}

// Adaptive sampling under MPI: each rank samples its share from its own pilot (16 samples per
// pixel each), to the target times sqrt(ranks); the image agrees with one process's adaptive one
// (the image means within 2%), and the spp layer adds the ranks' counts.
TEST(Mpi, AdaptiveRanksSampleTheirSharesAndAgreeWithOneProcess) {
  test::TempDir dir;
  const std::string one = dir.file("one.exr"), two = dir.file("two.exr");
  const std::string settings =
      " --width 48 --height 40 --threads 1 -q --until-relerr 0.1 --adaptive --spp 1024";
  ASSERT_EQ(test::runEmber("render '" + kScene + "' -o '" + one + "'" + settings).exitCode, 0);
  const test::CliResult r =
      runShell(mpirun(2) + "'" + EMBER_BINARY + "' render '" + kScene + "' -o '" + two + "'" + settings);
  ASSERT_EQ(r.exitCode, 0) << r.output;
  const ExrChannels a = readExrChannels(one), b = readExrChannels(two);
  ASSERT_TRUE(b.has("spp"));
  for (float n : b.channels.at("spp")) EXPECT_GE(n, 32.0f);
  for (const char* c : {"R", "G", "B"}) {
    double ma = 0.0, mb = 0.0;
    for (float v : a.channels.at(c)) ma += v;
    for (float v : b.channels.at(c)) mb += v;
    EXPECT_NEAR(mb / ma, 1.0, 0.02) << c;
  }
  // --until-relerr alone is still refused: no rank could judge the whole image.
  const test::CliResult alone = runShell(mpirun(2) + "'" + EMBER_BINARY + "' render '" + kScene + "' -o '" +
                                         dir.file("x.exr") + "' -q --until-relerr 0.1");
  EXPECT_NE(alone.exitCode, 0);
  EXPECT_FALSE(std::filesystem::exists(dir.file("x.exr")));
}

TEST(Mpi, CheckpointedRanksResumeToTheSameImage) {
  test::TempDir dir;
  const std::string out = dir.file("np2.exr"), ckpt = dir.file("job.ckpt");
  const test::CliResult first = runShell(mpirun(2) + "'" + EMBER_BINARY + "' render '" + kScene + "' -o '" +
                                         out + "'" + kSettings + " --checkpoint '" + ckpt + "'");
  ASSERT_EQ(first.exitCode, 0) << first.output;
  EXPECT_TRUE(std::filesystem::exists(dir.file("job.r0of2.ckpt")));
  EXPECT_TRUE(std::filesystem::exists(dir.file("job.r1of2.ckpt")));
  const Image before = readImageRgb(out);
  std::filesystem::remove(out);
  const test::CliResult again =
      runShell(mpirun(2) + "'" + EMBER_BINARY + "' render --resume '" + ckpt + "' -q --threads 1");
  ASSERT_EQ(again.exitCode, 0) << again.output;
  const Image after = readImageRgb(out);
  EXPECT_EQ(worstRelativeDifference(after, before), 0.0);
}

TEST(Mpi, ARankThatDiesFailsTheJobAndLeavesNoImage) {
  test::TempDir dir;
  const std::string out = dir.file("dead.exr");
  // Rank 1's ember is killed half a second in; rank 0 would wait for its sums forever.
  const std::string render = "'" + std::string(EMBER_BINARY) + "' render '" + kScene + "' -o '" + out +
                             "' --width 160 --height 120 --spp 2000 --threads 1 -q";
  const std::string script = "if [ \"$OMPI_COMM_WORLD_RANK\" = 1 ]; then " + render +
                             " & sleep 0.5; kill -9 $!; wait $!; exit $?; else exec " + render + "; fi";
  const test::CliResult r = runShell(mpirun(2) + "sh -c '" + [&] {
    std::string escaped;
    for (char c : script) escaped += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return escaped;
  }() + "'");
  EXPECT_NE(r.exitCode, 0) << r.output;
  // mpirun names the process: "rank 1" or its process name "[[job,1],1]".
  EXPECT_TRUE(r.output.find("rank 1") != std::string::npos || r.output.find(",1],1]") != std::string::npos)
      << r.output;
  EXPECT_FALSE(std::filesystem::exists(out));
}

}  // namespace
}  // namespace ember
