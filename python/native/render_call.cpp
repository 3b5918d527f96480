#include "python/native/render_call.h"

#include "io/filtered_texture.h"
#include "io/input_error.h"
#include "packet/wave_integrator.h"
#include "python/native/numpy_arrays.h"
#include "renderer/render.h"

#include <nanobind/stl/string.h>

#include <chrono>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <thread>

namespace nb = nanobind;

namespace ember::python {

namespace {

// An AOV layer's key in the returned dict, from its first channel's name (renderer/aov.h).
std::string aovKey(const std::string& channel) {
  const std::string prefix = channel.substr(0, channel.find('.'));
  if (prefix == "N") return "normal";
  if (prefix == "Z") return "depth";
  if (prefix == "P") return "position";
  return prefix;  // albedo, uv, coverage, variance, spp
}

// The next wait of the calling thread: short enough that Ctrl-C and progress are seen within
// a tenth of a second, long enough to cost nothing.
constexpr auto kPoll = std::chrono::milliseconds(100);

}  // namespace

nb::tuple renderScene(SceneHandle& handle, const RenderRequest& request) {
  if (handle.busy) throw std::runtime_error("this scene is rendering in another thread; wait for it");
  Scene& scene = handle.scene();
  RenderSettings settings = scene.settings;
  if (request.strategy) {
    const std::optional<Strategy> strategy = parseStrategy(*request.strategy);
    if (!strategy)
      throw nb::value_error(
          ("strategy '" + *request.strategy + "': valid are " + std::string(kStrategyNames)).c_str());
    settings.strategy = *strategy;
  }
  AovSet aovs;
  if (!request.aovs.empty()) {
    std::string list, error;
    for (const std::string& a : request.aovs) list += (list.empty() ? "" : ",") + a;
    const std::optional<AovSet> parsed = parseAovs(list, error);
    if (!parsed) throw nb::value_error(("aovs: " + error).c_str());
    aovs = *parsed;
  }
  if (aovs.has(Aov::Uv) && !scene.uvOnEveryHit) {
    // Every hit then works out its uv (a rebuild where shapes skipped it), from now on: switching
    // back would rebuild again at the next render that asks for uv.
    scene.uvOnEveryHit = true;
    scene.update();
  }
  RenderOptions options;
  options.spp = request.spp.value_or(settings.spp);
  options.seed = request.seed.value_or(settings.seed);
  options.threads = request.threads;
  options.firstSample = request.firstSample;
  options.sampler = settings.sampler;
  options.passSpp = request.passSpp;
  if (options.spp < 1) throw nb::value_error("spp must be at least 1");
  if (options.passSpp < 1) throw nb::value_error("pass_spp must be at least 1");
  if (options.threads < 0) throw nb::value_error("threads must be 0 (all cores) or more");

  const std::unique_ptr<Integrator> integrator = makeIntegrator(settings, Kernel::Wave);
  Film film(settings.width, settings.height, aovs);
  std::atomic<bool> stop{false};
  std::atomic<int> passes{0};
  options.stop = &stop;
  options.onPass = [&passes](const Film&, int done) { passes = done; };
  RenderStats stats;
  std::exception_ptr failure;
  std::mutex mutex;
  std::condition_variable finished;
  bool done = false;
  std::optional<nb::python_error> raised;  // Ctrl-C, or the progress callback's exception

  handle.busy = true;
  std::thread worker;
  // However this call ends, the render is stopped and joined and the scene freed for edits.
  struct Finally {
    SceneHandle& handle;
    std::atomic<bool>& stop;
    std::thread& worker;
    ~Finally() {
      stop = true;
      if (worker.joinable()) {
        nb::gil_scoped_release release;
        worker.join();
      }
      handle.busy = false;
    }
  } finally{handle, stop, worker};
  worker = std::thread([&] {
    try {
      stats = render(scene, *integrator, options, film);
    } catch (...) {
      failure = std::current_exception();
    }
    std::lock_guard<std::mutex> lock(mutex);
    done = true;
    finished.notify_all();
  });
  const int total = options.spp;
  int reported = -1;
  for (;;) {
    bool over;
    {
      nb::gil_scoped_release release;
      std::unique_lock<std::mutex> lock(mutex);
      over = finished.wait_for(lock, kPoll, [&] { return done; });
    }
    if (over) break;
    if (raised) continue;  // stopping: wait for the pass to be taken back
    if (PyErr_CheckSignals() != 0) {
      raised.emplace();  // fetches the KeyboardInterrupt (or whatever the handler raised)
      stop = true;
      continue;
    }
    if (!request.progress.is_none() && passes != reported) {
      reported = passes;
      try {
        request.progress(std::min(total, reported * options.passSpp), total);
      } catch (nb::python_error& e) {
        raised.emplace(std::move(e));
        stop = true;
      }
    }
  }
  {
    nb::gil_scoped_release release;
    worker.join();
  }
  if (failure) std::rethrow_exception(failure);
  const bool interrupted = raised && raised->matches(PyExc_KeyboardInterrupt);
  if (raised && !interrupted) throw std::move(*raised);
  if (const std::string error = takeFilteredTextureFailure(); !error.empty()) throw InputError(error);
  if (!interrupted && !request.progress.is_none() &&
      std::min(total, reported * options.passSpp) != stats.sppDone)
    request.progress(stats.sppDone, total);

  nb::dict aovArrays;
  for (ImageLayer& layer : film.aovLayers()) {
    const std::string key = aovKey(layer.channels.front());
    aovArrays[key.c_str()] =
        pixelArray(std::move(layer.pixels), film.height(), film.width(), layer.channels.size());
  }
  nb::dict info;
  info["spp"] = stats.sppDone;
  info["spp_requested"] = total;
  info["passes"] = stats.passes;
  info["seconds"] = stats.seconds;
  info["threads"] = stats.threads;
  info["samples_per_second"] = stats.seconds > 0.0 ? double(stats.samples) / stats.seconds : 0.0;
  info["non_finite_samples"] = stats.nonFinite;
  info["interrupted"] = interrupted;
  info["strategy"] = std::string(strategyName(settings.strategy));
  info["seed"] = options.seed;
  info["first_sample"] = options.firstSample;
  return nb::make_tuple(pixelArray(film.mean().rgb, film.height(), film.width(), 3), aovArrays, info);
}

}  // namespace ember::python
