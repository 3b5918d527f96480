// The wave driver: the path tracer that renders every scene, with a tile's paths advancing together,
// one bounce at a time, and the bounce's state in arrays (structure of arrays) indexed by path and
// by vertex. Each bounce casts all closest-hit rays, then all shadow rays, as Embree packets of
// its native width (packet/ray_batch.h).
//
// The driver owns only the integrator's part of a bounce: grouping hits by geometry, the light
// choice, the MIS weights and shadow rays of next-event estimation (packet/next_event_lanes.h), and
// the continuation: throughput, Russian roulette and compaction (packet/continuation_lanes.h).
// The physics belongs to the types and runs as their run-level operations:
//  - arrival, emission and the environment: PathIntegrator::arrive and onMiss, the reference's own
//    steps, on each path's state gathered from its slot; a run of hits on an analytic shape with
//    a uniform Lambertian reflectance settles in one kernel (packet/arrival_lanes.h);
//  - lights: Light::sampleLanes per run of one light (area and point lights fill the next-event
//    rows directly);
//  - materials: Material::sampleLanes per run of one material, Material::evalPdf through
//    PathIntegrator::shadowFor. A vertex where the material is a Lambertian reflector about the
//    geometric normal (Material::lambertianAt) is evaluated and sampled inline by the kernels.
// Every path takes PathIntegrator's steps with its own sampler, so the image equals the scalar
// reference's bit for bit (tests/test_wavefront.cpp) and is the same for any thread count.
#pragma once

#include "renderer/path_integrator.h"

#include <memory>
#include <optional>
#include <string_view>

namespace ember {

class WaveIntegrator final : public Integrator {
 public:
  // Paths in flight per wave: a 16x16 tile's pixels at four sample indices (fewer when a pass
  // has fewer samples: --pass-spp 1 gives waves of 256). Four times the tile's pixels fill the
  // late bounces' packets better and lengthen the runs of one shape, material and light.
  // Indices into the wave are 16-bit (and packed below bit 16 in sort keys).
  static constexpr size_t kWaveSize = 1024;
  static_assert(kWaveSize <= (1u << 15), "wave indices are uint16_t / int16_t");

  explicit WaveIntegrator(const RenderSettings& s) : path_(s) {}

  Color Li(const Scene& scene, Ray ray, Sampler& sampler, PathStats& stats) const override {
    return path_.Li(scene, ray, sampler, stats);
  }
  Color LiWithAovs(const Scene& scene, Ray ray, Sampler& sampler, PathStats& stats,
                   AovSample& aov) const override {
    return path_.LiWithAovs(scene, ray, sampler, stats, aov);
  }
  void renderTile(const Scene& scene, const TileWork& work, Film& film, PathStats& stats) const override;
  bool tracesCaustics() const override { return path_.tracesCaustics(); }
  // The light paths in waves too (packet/caustic_wave.h).
  void traceCaustics(const Scene& scene, uint64_t seed, SamplerType sampler, uint64_t firstIndex, int count,
                     CausticSplats& splats, PathStats& stats) const override;
  int maxDepth() const override { return path_.maxDepth(); }
  int rrDepth() const override { return path_.rrDepth(); }

 private:
  PathIntegrator path_;
};

// How `render` and `bench` run the path tracer (--kernel). Both give the same image bit for bit.
//  - wave:   WaveIntegrator (the default);
//  - scalar: PathIntegrator::Li, one ray at a time: the reference implementation.
enum class Kernel { Wave, Scalar };
inline constexpr const char* kKernelNames = "wave, scalar";
// Also takes "lanes" and "wavefront", the names of the wave driver's two predecessors.
std::optional<Kernel> parseKernel(std::string_view name);
std::unique_ptr<Integrator> makeIntegrator(const RenderSettings& settings, Kernel kernel);

}  // namespace ember
