// The path tracer with the bounce's state in arrays, the structure-of-arrays design of
// docs/architecture.md ("How the plan should land"): the wave of packet/wavefront_integrator.h,
// whose paths in flight, vertices and light samples live in arrays indexed by path and by vertex
// instead of per-path records, so that the bounce's steps run as vector kernels over them
// (next-event estimation, packet/next_event_lanes.h; the continuation and the compaction,
// packet/continuation_lanes.h; the camera rays, renderer/camera_lanes.h).
//
// It covers a closed set of scenes and grows step by step: analytic shapes with Lambertian
// materials (constant or textured), mirrors and smooth glass (Mirror, Refraction, Dielectric:
// sampled by their scalar sample()), or none; lights of every kind an analytic scene has (point,
// spot, directional, area, the environment); the `mis` strategy (LaneIntegrator::covers). That
// holds all four shared scenes. Any other scene is rendered by the wavefront kernel. Within the
// set every path takes PathIntegrator's steps with its own sampler, so the image equals the
// scalar reference's bit for bit (tests/test_wavefront.cpp) and is the same for any thread count.
#pragma once

#include "packet/wavefront_integrator.h"

#include <atomic>
#include <string>

namespace ember {

class LaneIntegrator final : public Integrator {
 public:
  static constexpr size_t kWaveSize = WavefrontIntegrator::kWaveSize;

  explicit LaneIntegrator(const RenderSettings& s) : path_(s), wavefront_(path_) {}

  // Whether the lane kernel renders `scene` with `strategy`; otherwise renderTile hands the tile to
  // the wavefront kernel. uncovered says why not (`ember info`), an empty string where it does.
  static std::string uncovered(const Scene& scene, Strategy strategy);
  static bool covers(const Scene& scene, Strategy strategy) { return uncovered(scene, strategy).empty(); }

  Color Li(const Scene& scene, Ray ray, Sampler& sampler, PathStats& stats) const override {
    return path_.Li(scene, ray, sampler, stats);
  }
  void renderTile(const Scene& scene, const TileWork& work, Film& film, PathStats& stats) const override;
  bool tracesCaustics() const override { return path_.tracesCaustics(); }
  void traceCaustics(const Scene& scene, uint64_t seed, SamplerType sampler, uint64_t firstIndex, int count,
                     CausticSplats& splats, PathStats& stats) const override {
    wavefront_.traceCaustics(scene, seed, sampler, firstIndex, count, splats, stats);
  }
  int maxDepth() const override { return path_.maxDepth(); }
  int rrDepth() const override { return path_.rrDepth(); }

 private:
  void renderLanes(const Scene& scene, const TileWork& work, Film& film, PathStats& stats) const;
  bool coversOnce(const Scene& scene) const;

  PathIntegrator path_;
  WavefrontIntegrator wavefront_;
  // covers() of the last scene asked about, so that a render decides once, not per tile: its
  // Scene::buildSerial() << 1 | covers, in one word so that two threads asking about two scenes
  // never pair one scene's serial with the other's answer. It starts as a word no serial makes
  // (even a never-built scene's, 0).
  mutable std::atomic<uint64_t> lastCovered_{~uint64_t(0)};
};

}  // namespace ember
