// Scene.render: the render() and wave driver of `ember render` on a worker thread, while the
// calling thread, without the GIL but for moments, reports progress and polls for Ctrl-C.
#pragma once

#include "python/native/scene_handle.h"

#include <nanobind/nanobind.h>

#include <optional>
#include <string>
#include <vector>

namespace ember::python {

struct RenderRequest {
  std::optional<int> spp;
  std::optional<uint64_t> seed;
  int threads = 0;
  uint64_t firstSample = 0;
  std::optional<std::string> strategy;
  std::vector<std::string> aovs;
  nanobind::object progress;  // None, or called as progress(spp_done, spp) between passes
  int passSpp = 4;
};

// (image, aovs, stats): image a float32 numpy (H, W, 3) owning the film's mean; aovs a dict of
// numpy arrays by AOV name; stats a dict (spp, passes, seconds, interrupted, ...). A Ctrl-C stops
// the render within about 0.1 s of its pass, returning the completed passes with stats
// ["interrupted"] set (the Python layer raises ember.RenderInterrupted with them).
nanobind::tuple renderScene(SceneHandle& handle, const RenderRequest& request);

}  // namespace ember::python
