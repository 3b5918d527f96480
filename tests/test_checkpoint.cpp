// Renders that never lose work: progressive passes, interruption, checkpoint files, resume, time
// budgets and merging of sample ranges. The promise tested throughout: a render stopped at any
// moment and resumed from its last checkpoint ends bit-identical to one that never stopped.
#include "checkpoint/checkpoint_file.h"
#include "io/image_io.h"
#include "io/input_error.h"
#include "io/pending_file.h"
#include "io/scene_loader.h"
#include "packet/wave_integrator.h"
#include "renderer/render.h"

#include <gtest/gtest.h>

#include <cmath>

#include "cli_runner.h"
#include "test_fixtures.h"
#include "test_paths.h"

#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <thread>

namespace ember {
namespace {

Scene smallScene(int size = 40) {
  Scene scene = loadScene(test::sourcePath("scenes/cornell-area.json"));
  scene.settings.width = size;
  scene.settings.height = size;
  scene.build();
  return scene;
}

RenderOptions optionsFor(const Scene& scene, int spp, int passSpp) {
  RenderOptions o;
  o.spp = spp;
  o.seed = scene.settings.seed;
  o.sampler = scene.settings.sampler;
  o.passSpp = passSpp;
  return o;
}

bool sameFilm(const Film& a, const Film& b) {
  return a.counts() == b.counts() &&
         std::memcmp(a.sums().data(), b.sums().data(), a.sums().size() * sizeof(glm::dvec3)) == 0 &&
         std::memcmp(a.sumsOfSquares().data(), b.sumsOfSquares().data(),
                     a.sums().size() * sizeof(glm::dvec3)) == 0;
}

bool sameImage(const Image& a, const Image& b) {
  return a.width == b.width && a.height == b.height &&
         std::memcmp(a.rgb.data(), b.rgb.data(), a.rgb.size() * sizeof(float)) == 0;
}

// An integrator that raises the stop flag after a number of tiles, from inside a pass.
class StopAfterTiles final : public test::ForwardingIntegrator {
 public:
  StopAfterTiles(const Integrator& inner, std::atomic<bool>& stop, int tiles)
      : ForwardingIntegrator(inner), stop_(stop), left_(tiles) {}
  void renderTile(const Scene& s, const TileWork& w, Film& f, PathStats& st) const override {
    ForwardingIntegrator::renderTile(s, w, f, st);
    if (--left_ <= 0) stop_.store(true);
  }

 private:
  std::atomic<bool>& stop_;
  mutable std::atomic<int> left_;
};

TEST(Passes, AnyPassSizeGivesTheSameFilm) {
  const Scene scene = smallScene();
  const auto integrator = makeIntegrator(scene.settings, Kernel::Wave);
  Film one(40, 40), passes(40, 40), odd(40, 40);
  render(scene, *integrator, optionsFor(scene, 10, 1000), one);
  const RenderStats st = render(scene, *integrator, optionsFor(scene, 10, 3), passes);
  render(scene, *integrator, optionsFor(scene, 10, 1), odd);
  EXPECT_EQ(st.passes, 4);
  EXPECT_EQ(st.sppDone, 10);
  EXPECT_TRUE(sameFilm(one, passes));
  EXPECT_TRUE(sameFilm(one, odd));
}

TEST(Passes, AnInterruptedPassIsTakenBackAndResumingEndsBitIdentical) {
  const Scene scene = smallScene();
  const auto integrator = makeIntegrator(scene.settings, Kernel::Wave);
  Film reference(40, 40);
  render(scene, *integrator, optionsFor(scene, 12, 4), reference);
  Film afterOnePass(40, 40);
  render(scene, *integrator, optionsFor(scene, 4, 4), afterOnePass);

  // 9 tiles per pass at 40x40: stop in the middle of the second pass.
  std::atomic<bool> stop{false};
  const StopAfterTiles stopping(*integrator, stop, 9 + 4);
  Film film(40, 40);
  RenderOptions o = optionsFor(scene, 12, 4);
  o.threads = 1;
  o.stop = &stop;
  const RenderStats cut = render(scene, stopping, o, film);
  EXPECT_TRUE(cut.interrupted);
  EXPECT_EQ(cut.passes, 1);
  EXPECT_EQ(cut.sppDone, 4);
  EXPECT_TRUE(sameFilm(film, afterOnePass)) << "the half-done second pass must be taken back exactly";

  RenderOptions resume = optionsFor(scene, 12, 4);
  resume.passesDone = cut.passes;
  const RenderStats rest = render(scene, *integrator, resume, film);
  EXPECT_EQ(rest.passes, 3);
  EXPECT_TRUE(sameFilm(film, reference));
}

TEST(Passes, TimeBudgetStopsBeforeAPassThatWouldNotFit) {
  const Scene scene = smallScene(64);
  const auto integrator = makeIntegrator(scene.settings, Kernel::Wave);
  Film film(64, 64);
  RenderOptions o = optionsFor(scene, 100000, 4);
  o.timeBudgetSeconds = 0.3;
  const auto t0 = std::chrono::steady_clock::now();
  const RenderStats st = render(scene, *integrator, o, film);
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_TRUE(st.outOfTime);
  EXPECT_GE(st.passes, 1);
  EXPECT_LT(st.sppDone, 100000);
  EXPECT_EQ(st.sppDone, st.passes * 4);
  // Generous: the check is that the budget stops the render, not how fast this machine is.
  EXPECT_LT(s, 0.3 * 3.0 + 1.0) << "the budget was overrun";
  for (uint32_t n : film.counts()) EXPECT_EQ(n, uint32_t(st.sppDone));
}

// --until-relerr (RenderOptions::targetRelativeError): the render stops before the first pass
// at which the film's estimated relative error is within the target, so one pass fewer is still
// above it; the stop depends on the film alone, so a render cut short and resumed stops at the same
// pass with the same film, bit for bit.
TEST(Passes, ARelativeErrorTargetStopsAtTheFirstPassWithinIt) {
  const Scene scene = smallScene(24);
  const auto integrator = makeIntegrator(scene.settings, Kernel::Wave);
  const double target = 0.05;
  Film film(24, 24);
  RenderOptions o = optionsFor(scene, 4096, 4);
  o.targetRelativeError = target;
  const RenderStats st = render(scene, *integrator, o, film);
  ASSERT_TRUE(st.converged);
  EXPECT_LE(st.relativeError, target);
  EXPECT_EQ(st.relativeError, film.relativeError());
  EXPECT_GT(st.sppDone, 4);
  EXPECT_LT(st.sppDone, 4096);
  Film fewer(24, 24);
  render(scene, *integrator, optionsFor(scene, st.sppDone - 4, 4), fewer);
  EXPECT_GT(fewer.relativeError(), target);

  // Cut after two passes, then resumed with the same target.
  Film resumed(24, 24);
  RenderOptions first = optionsFor(scene, 8, 4);
  render(scene, *integrator, first, resumed);
  RenderOptions rest = optionsFor(scene, 4096, 4);
  rest.passesDone = 2;
  rest.targetRelativeError = target;
  const RenderStats after = render(scene, *integrator, rest, resumed);
  EXPECT_EQ(after.sppDone, st.sppDone);
  EXPECT_TRUE(sameFilm(resumed, film));

  // A film already within the target renders no further pass.
  const RenderStats none = render(scene, *integrator, rest, resumed);
  EXPECT_TRUE(none.converged);
  EXPECT_EQ(none.samples, 0u);
}

// Film::relativeError against its definition: two samples, 1 and 3, in every channel of every
// pixel: mean 2, sample variance 2, variance of the mean 1, so sqrt(1 / (4 + 0.01)).
TEST(Passes, RelativeErrorIsTheExpectedRelMseRoot) {
  Film film(3, 2);
  EXPECT_TRUE(std::isinf(film.relativeError()));
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 3; ++x) {
      film.addSample(x, y, Color(1.0f));
      film.addSample(x, y, Color(3.0f));
    }
  EXPECT_NEAR(film.relativeError(), std::sqrt(1.0 / 4.01), 1e-12);
}

Checkpoint sampleCheckpoint() {
  const Scene scene = smallScene(12);
  const auto integrator = makeIntegrator(scene.settings, Kernel::Wave);
  Checkpoint c;
  c.identity = identityOf(scene, test::sourcePath("scenes/cornell-area.json"), -1, "", "");
  c.spp = 8;
  c.passSpp = 2;
  c.passes = 2;
  c.output = "out.exr";
  c.emberVersion = "test";
  c.film = Film(12, 12);
  render(scene, *integrator, optionsFor(scene, 4, 2), c.film);
  return c;
}

TEST(CheckpointFile, RoundTripsExactly) {
  test::TempDir dir;
  const Checkpoint c = sampleCheckpoint();
  writeCheckpoint(dir.file("a.ckpt"), c);
  const Checkpoint back = readCheckpoint(dir.file("a.ckpt"));
  EXPECT_TRUE(sameFilm(c.film, back.film));
  EXPECT_EQ(back.identity.hash(), c.identity.hash());
  EXPECT_EQ(back.passes, 2);
  EXPECT_EQ(back.passSpp, 2);
  EXPECT_EQ(back.spp, 8);
  EXPECT_EQ(back.output, "out.exr");
  EXPECT_EQ(c.identity.differenceFrom(back.identity), "");
  EXPECT_EQ(std::strlen(pendingFile()), 0u);
  for (const auto& entry : std::filesystem::directory_iterator(dir.path))
    EXPECT_EQ(entry.path().extension(), ".ckpt") << "temporary file left behind: " << entry.path();
}

// Every truncation, every flipped byte of a sample of positions, and foreign files: a clear error
// naming the file, never a crash or a state that loads.
TEST(CheckpointFile, CorruptedTruncatedAndForeignFilesAreRejected) {
  test::TempDir dir;
  writeCheckpoint(dir.file("good.ckpt"), sampleCheckpoint());
  std::ifstream in(dir.file("good.ckpt"), std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), {});
  auto expectRejected = [&](const std::string& content, const std::string& what) {
    const std::string path = dir.write("bad.ckpt", content);
    try {
      readCheckpoint(path);
      ADD_FAILURE() << what << ": accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << what << ": " << e.what();
    }
  };
  for (size_t n = 0; n < bytes.size(); n += std::max<size_t>(1, bytes.size() / 97))
    expectRejected(bytes.substr(0, n), "truncated to " + std::to_string(n));
  expectRejected(bytes.substr(0, bytes.size() - 1), "one byte short");
  std::mt19937 rng(3);
  for (int k = 0; k < 64; ++k) {
    std::string flipped = bytes;
    const size_t at = rng() % bytes.size();
    flipped[at] = char(flipped[at] ^ (1 << (rng() % 8)));
    expectRejected(flipped, "bit flipped at " + std::to_string(at));
  }
  expectRejected(bytes + "x", "one byte too many");
  expectRejected("", "empty");
  expectRejected("\x89PNG\r\n\x1a\n", "a PNG");
  std::string future = bytes;
  future[8] = char(kCheckpointFormat + 1);  // a format after this one
  expectRejected(future, "a newer format");
  EXPECT_THROW(readCheckpoint(dir.file("missing.ckpt")), InputError);
}

// --- the command line -------------------------------------------------------------------------

std::string quoted(const std::string& s) {
  return "'" + s + "'";
}

// Starts `ember args` in the background; returns its pid.
pid_t spawnEmber(const std::string& args, const std::string& log) {
  const pid_t pid = fork();
  if (pid == 0) {
    const std::string cmd = "exec '" + std::string(EMBER_BINARY) + "' " + args + " >'" + log + "' 2>&1";
    execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  return pid;
}

// The exit code, or minus the signal that killed the process.
int waitExit(pid_t pid) {
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -WTERMSIG(status);
}

const std::string kScene = test::sourcePath("scenes/cornell-area.json");
const std::string kSettings = " --width 128 --height 96 --spp 64 --pass-spp 2 -q --threads 2";

Image referenceImage(const test::TempDir& dir) {
  const std::string out = dir.file("reference.exr");
  EXPECT_EQ(test::runEmber("render " + quoted(kScene) + " -o " + quoted(out) + kSettings).exitCode, 0);
  return readImageRgb(out);
}

// SIGTERM, then SIGKILL, at random moments of a checkpointing render; each time resume from what
// is on disk and finish: the same image, bit for bit. The first four trials wait for the first
// checkpoint and then kill at a random moment after it (a fixed sleep alone killed most sanitizer
// runs on a busy machine before any checkpoint, leaving nothing to resume); the last two kill at
// any moment, the first checkpoint included.
TEST(CheckpointCli, KilledAtRandomMomentsThenResumedIsBitIdentical) {
  test::TempDir dir;
  const Image reference = referenceImage(dir);
  std::mt19937 rng(11);
  int resumedFromState = 0;
  for (int trial = 0; trial < 6; ++trial) {
    const bool kill9 = trial % 2 == 1;
    // Appended, not "t" + ...: GCC 12 warns falsely (-Wrestrict, its bug 105329) on that form here.
    std::string stem = "t";
    stem += std::to_string(trial);
    const std::string ckpt = dir.file(stem + ".ckpt");
    const std::string out = dir.file(stem + ".exr");
    const pid_t pid = spawnEmber("render " + quoted(kScene) + " -o " + quoted(out) + kSettings +
                                     " --checkpoint " + quoted(ckpt) + " --checkpoint-every 0",
                                 dir.file("log"));
    if (trial < 4) {
      const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
      while (!std::filesystem::exists(ckpt) && std::chrono::steady_clock::now() < deadline)
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
      std::this_thread::sleep_for(std::chrono::milliseconds(rng() % 300));
    } else {
      std::this_thread::sleep_for(std::chrono::milliseconds(250 + rng() % 600));
    }
    kill(pid, kill9 ? SIGKILL : SIGTERM);
    const int code = waitExit(pid);
    SCOPED_TRACE(std::string(kill9 ? "SIGKILL" : "SIGTERM") + " trial " + std::to_string(trial));
    if (code == 0) continue;  // it finished first
    // A SIGTERM that arrives while the dynamic loader is still at work finds no handler yet.
    if (!kill9 && code == -SIGTERM) continue;
    EXPECT_EQ(code, kill9 ? -SIGKILL : 128 + SIGTERM);
    if (!std::filesystem::exists(ckpt)) {
      EXPECT_TRUE(kill9) << "SIGTERM must leave a checkpoint";
      continue;  // killed before its first checkpoint
    }
    ++resumedFromState;
    const test::CliResult r = test::runEmber("render --resume " + quoted(ckpt) + " -q");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_TRUE(sameImage(readImageRgb(out), reference));
  }
  EXPECT_GE(resumedFromState, 2) << "too few trials were interrupted in time to test anything";
}

TEST(CheckpointCli, SigtermWritesTheCompletedPassesAndTheirSpp) {
  test::TempDir dir;
  const std::string out = dir.file("part.exr");
  // The checkpoint written after every pass says when one is complete: a fixed sleep was too short
  // for the sanitizer build on a busy machine (no pass done, so no image).
  const std::string ckpt = dir.file("part.ckpt");
  const pid_t pid = spawnEmber("render " + quoted(kScene) + " -o " + quoted(out) +
                                   " --width 96 --height 96 --spp 100000 --pass-spp 1 -q --checkpoint " +
                                   quoted(ckpt) + " --checkpoint-every 0",
                               dir.file("log"));
  const auto started = std::chrono::steady_clock::now();
  while (!std::filesystem::exists(ckpt) &&
         std::chrono::steady_clock::now() - started < std::chrono::seconds(120))
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  ASSERT_TRUE(std::filesystem::exists(ckpt)) << "no pass completed in 120 s";
  const auto t0 = std::chrono::steady_clock::now();
  kill(pid, SIGTERM);
  EXPECT_EQ(waitExit(pid), 128 + SIGTERM);  // exited by itself, after writing the image
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 3.0);
  std::string spp;
  for (const auto& [k, v] : readStringMetadata(out))
    if (k == "ember:spp") spp = v;
  ASSERT_FALSE(spp.empty());
  EXPECT_GT(std::stoi(spp), 0);
  EXPECT_LT(std::stoi(spp), 100000);
}

// A second signal exits at once: whatever was being written is removed, and the last complete
// checkpoint stays readable.
TEST(CheckpointCli, ASecondSignalExitsAtOnceAndKeepsTheLastCheckpoint) {
  test::TempDir dir;
  const std::string ckpt = dir.file("s.ckpt");
  for (int delayMs : {0, 5, 20, 60}) {
    SCOPED_TRACE("second signal after " + std::to_string(delayMs) + " ms");
    const pid_t pid = spawnEmber("render " + quoted(kScene) + " -o " + quoted(dir.file("out.exr")) +
                                     " --width 256 --height 256 --spp 100000 --pass-spp 1 -q --checkpoint " +
                                     quoted(ckpt) + " --checkpoint-every 0",
                                 dir.file("log"));
    std::this_thread::sleep_for(std::chrono::milliseconds(1500));
    kill(pid, SIGTERM);
    std::this_thread::sleep_for(std::chrono::milliseconds(delayMs));
    kill(pid, SIGTERM);
    EXPECT_EQ(waitExit(pid), 128 + SIGTERM);
    ASSERT_TRUE(std::filesystem::exists(ckpt));
    EXPECT_NO_THROW(readCheckpoint(ckpt));
    for (const auto& entry : std::filesystem::directory_iterator(dir.path))
      EXPECT_EQ(entry.path().filename().string().find(".tmp"), std::string::npos)
          << "left behind: " << entry.path();
  }
}

TEST(CheckpointCli, TimeBudgetStopsAndRecordsTheSpp) {
  test::TempDir dir;
  const std::string out = dir.file("budget.exr");
  const auto t0 = std::chrono::steady_clock::now();
  const test::CliResult r = test::runEmber("render " + quoted(kScene) + " -o " + quoted(out) +
                                           " --width 64 --height 64 --spp 100000 --time 1s -q");
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_EQ(r.exitCode, 0) << r.output;
  EXPECT_NE(r.output.find("--time 1s: stopped after"), std::string::npos) << r.output;
  EXPECT_LT(s, 10.0);
  std::string spp;
  for (const auto& [k, v] : readStringMetadata(out))
    if (k == "ember:spp") spp = v;
  EXPECT_GT(std::stoi(spp), 0);
  EXPECT_LT(std::stoi(spp), 100000);
  EXPECT_EQ(test::runEmber("render " + quoted(kScene) + " -o " + quoted(out) + " --time 5min").exitCode, 1);
}

TEST(CheckpointCli, ResumeRefusesAChangedSceneAndForeignState) {
  test::TempDir dir;
  std::ifstream src(kScene);
  const std::string text((std::istreambuf_iterator<char>(src)), {});
  const std::string scene = dir.write("scene.json", text);
  const std::string ckpt = dir.file("s.ckpt");
  ASSERT_EQ(test::runEmber("render " + quoted(scene) + " -o " + quoted(dir.file("a.exr")) +
                           " --width 16 --height 16 --spp 4 -q --checkpoint " + quoted(ckpt))
                .exitCode,
            0);
  ASSERT_TRUE(std::filesystem::exists(ckpt));
  EXPECT_EQ(test::runEmber("render --resume " + quoted(ckpt) + " --spp 8 -q").exitCode, 0);
  dir.write("scene.json", text + " ");  // one byte more: another scene file
  const test::CliResult changed = test::runEmber("render --resume " + quoted(ckpt) + " --spp 12 -q");
  EXPECT_EQ(changed.exitCode, 1);
  EXPECT_NE(changed.output.find("has changed since the checkpoint"), std::string::npos) << changed.output;
  const test::CliResult foreign = test::runEmber("render --resume " + quoted(scene) + " -q");
  EXPECT_EQ(foreign.exitCode, 1);
  EXPECT_NE(foreign.output.find("not an Ember checkpoint"), std::string::npos) << foreign.output;
  const test::CliResult mixed = test::runEmber("render --resume " + quoted(ckpt) + " --seed 3 -q");
  EXPECT_EQ(mixed.exitCode, 1);
  EXPECT_NE(mixed.output.find("--seed cannot be given"), std::string::npos) << mixed.output;
}

TEST(MergeCli, SampleRangesMergeIntoTheirUnion) {
  test::TempDir dir;
  const std::string base = "render " + quoted(kScene) + " --width 32 --height 24 -q";
  ASSERT_EQ(test::runEmber(base + " --spp 24 -o " + quoted(dir.file("all.exr"))).exitCode, 0);
  ASSERT_EQ(test::runEmber(base + " --spp 8 -o " + quoted(dir.file("a.exr"))).exitCode, 0);
  ASSERT_EQ(test::runEmber(base + " --spp 12 --first-sample 8 -o " + quoted(dir.file("b.exr"))).exitCode, 0);
  ASSERT_EQ(test::runEmber(base + " --spp 4 --first-sample 20 -o " + quoted(dir.file("c.exr"))).exitCode, 0);
  const test::CliResult m =
      test::runEmber("merge " + quoted(dir.file("c.exr")) + " " + quoted(dir.file("a.exr")) + " " +
                     quoted(dir.file("b.exr")) + " -o " + quoted(dir.file("m.exr")));
  ASSERT_EQ(m.exitCode, 0) << m.output;
  const Image all = readImageRgb(dir.file("all.exr")), merged = readImageRgb(dir.file("m.exr"));
  ASSERT_EQ(all.rgb.size(), merged.rgb.size());
  double worst = 0.0;
  for (size_t i = 0; i < all.rgb.size(); ++i)
    worst = std::max(
        worst, std::abs(double(merged.rgb[i]) - all.rgb[i]) / std::max(1e-3, double(std::abs(all.rgb[i]))));
  EXPECT_LT(worst, 1e-6);
  std::string spp;
  for (const auto& [k, v] : readStringMetadata(dir.file("m.exr")))
    if (k == "ember:spp") spp = v;
  EXPECT_EQ(spp, "24");

  // Variance of the mean, merged from each part's mean and variance, against the one render's.
  ASSERT_EQ(test::runEmber(base + " --spp 24 -o " + quoted(dir.file("all2.exr")) + " --variance " +
                           quoted(dir.file("all_var.exr")))
                .exitCode,
            0);
  ASSERT_EQ(test::runEmber(base + " --spp 8 -o " + quoted(dir.file("a2.exr")) + " --variance " +
                           quoted(dir.file("a_var.exr")))
                .exitCode,
            0);
  ASSERT_EQ(test::runEmber(base + " --spp 16 --first-sample 8 -o " + quoted(dir.file("b2.exr")) +
                           " --variance " + quoted(dir.file("b_var.exr")))
                .exitCode,
            0);
  const test::CliResult mv =
      test::runEmber("merge " + quoted(dir.file("a2.exr")) + " " + quoted(dir.file("b2.exr")) + " -o " +
                     quoted(dir.file("m2.exr")) + " --variance " + quoted(dir.file("a_var.exr")) + " " +
                     quoted(dir.file("b_var.exr")) + " --variance-output " + quoted(dir.file("m_var.exr")));
  ASSERT_EQ(mv.exitCode, 0) << mv.output;
  const Image vAll = readImageRgb(dir.file("all_var.exr")), vMerged = readImageRgb(dir.file("m_var.exr"));
  double worstVar = 0.0, biggest = 0.0;
  for (float v : vAll.rgb) biggest = std::max(biggest, double(v));
  for (size_t i = 0; i < vAll.rgb.size(); ++i)
    worstVar = std::max(worstVar, std::abs(double(vMerged.rgb[i]) - vAll.rgb[i]) /
                                      std::max(double(vAll.rgb[i]), 1e-4 * biggest));
  EXPECT_LT(worstVar, 1e-3);

  // Overlapping ranges, another seed, another scene, and images not rendered by Ember.
  const test::CliResult overlap =
      test::runEmber("merge " + quoted(dir.file("a.exr")) + " " + quoted(dir.file("all.exr")) + " -o " +
                     quoted(dir.file("x.exr")));
  EXPECT_EQ(overlap.exitCode, 1);
  EXPECT_NE(overlap.output.find("overlap"), std::string::npos) << overlap.output;
  ASSERT_EQ(test::runEmber(base + " --spp 4 --first-sample 40 --seed 9 -o " + quoted(dir.file("seed.exr")))
                .exitCode,
            0);
  const test::CliResult seed =
      test::runEmber("merge " + quoted(dir.file("a.exr")) + " " + quoted(dir.file("seed.exr")) + " -o " +
                     quoted(dir.file("x.exr")));
  EXPECT_EQ(seed.exitCode, 1);
  EXPECT_NE(seed.output.find("ember:seed"), std::string::npos) << seed.output;
  ASSERT_EQ(test::runEmber("render " + quoted(test::sourcePath("scenes/shapes.json")) +
                           " --width 32 --height 24 -q --spp 4 --first-sample 40 -o " +
                           quoted(dir.file("shapes.exr")))
                .exitCode,
            0);
  const test::CliResult other =
      test::runEmber("merge " + quoted(dir.file("a.exr")) + " " + quoted(dir.file("shapes.exr")) + " -o " +
                     quoted(dir.file("x.exr")));
  EXPECT_EQ(other.exitCode, 1);
  EXPECT_NE(other.output.find("scene_hash"), std::string::npos) << other.output;
  writeExr(dir.file("plain.exr"), all);
  EXPECT_EQ(test::runEmber("merge " + quoted(dir.file("a.exr")) + " " + quoted(dir.file("plain.exr")) +
                           " -o " + quoted(dir.file("x.exr")))
                .exitCode,
            1);
  EXPECT_FALSE(std::filesystem::exists(dir.file("x.exr")));
}

}  // namespace
}  // namespace ember

namespace ember {
namespace {

// `ember render --until-relerr`: the EXR records the target and the estimate reached; a target
// that is not a positive number is refused, and nothing is written.
TEST(CheckpointCli, UntilRelerrRecordsTheEstimateAndRefusesBadTargets) {
  test::TempDir dir;
  const std::string scene = test::sourcePath("scenes/cornell-area.json");
  const std::string out = dir.file("until.exr");
  const test::CliResult r = test::runEmber("render '" + scene + "' -o '" + out +
                                           "' --width 32 --height 24 --until-relerr 0.08 -q --threads 2");
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_NE(r.output.find("--until-relerr 0.08: reached"), std::string::npos) << r.output;
  const Metadata meta = readStringMetadata(out);
  const auto value = [&](const std::string& key) {
    for (const auto& [k, v] : meta)
      if (k == key) return v;
    return std::string();
  };
  ASSERT_FALSE(value("ember:relerr").empty());
  EXPECT_LE(std::stod(value("ember:relerr")), 0.08);
  EXPECT_EQ(value("ember:spp_requested"), "65536");
  EXPECT_LT(std::stoi(value("ember:spp")), 65536);
  for (const char* bad : {"0", "-1", "nan", "x"}) {
    const std::string none = dir.file(std::string("bad") + bad + ".exr");
    EXPECT_NE(test::runEmber("render '" + scene + "' -o '" + none + "' --spp 4 --until-relerr=" + bad + " -q")
                  .exitCode,
              0)
        << bad;
    EXPECT_FALSE(std::filesystem::exists(none)) << bad;
  }
}

}  // namespace
}  // namespace ember
