// The path tracer run as a wavefront: a tile's camera samples advance together, one bounce at a
// time, and each bounce casts all their closest-hit rays, then all their shadow rays, as batches
// of 16-wide Embree packets (packet/ray_batch.h). Between the casts every path takes exactly the
// steps PathIntegrator::Li takes (PathIntegrator::onHit's steps, onMiss), with its own sampler;
// each step runs for the whole bounce, its hits grouped by geometry, and the lights sample their
// vertices together (Light::sampleLanes, a SIMD kernel for quads). A lane's result never depends
// on its neighbours, and a pixel's samples reach the film in the order of their indices, so the
// image equals the scalar reference's bit for bit (tests/test_wavefront.cpp) and is the same for
// any thread count.
#pragma once

#include "packet/geometry_groups.h"
#include "packet/ray_batch.h"
#include "renderer/path_integrator.h"

namespace ember {

class WavefrontIntegrator final : public Integrator {
 public:
  // Paths in flight per wave: a 16x16 tile's pixels at four sample indices (fewer when a pass
  // has fewer samples: --pass-spp 1 gives waves of 256). Four times the tile's pixels fill the
  // late bounces' packets better and lengthen the runs of one shape, material and light;
  // measured 0.90-0.96x the wall time of one sample index per wave (docs/performance.md,
  // optimisation log). Indices into the wave are 16-bit (and packed below bit 16 in sort keys).
  static constexpr size_t kWaveSize = 1024;
  static_assert(kWaveSize <= (1u << 15), "wave indices are uint16_t / int16_t");
  // Above this many geometries the bounce's hits are grouped by sorting their keys rather than
  // by a counting sort (packet/geometry_groups.h).
  static constexpr size_t kMaxCountingSortBuckets = GeometryGroups::kMaxCountingSortBuckets;
  static_assert(kWaveSize <= GeometryGroups::kMaxLanes);

  explicit WavefrontIntegrator(const RenderSettings& s, BatchTraversal traversal = BatchTraversal::Packets)
      : path_(s), traversal_(traversal) {}
  WavefrontIntegrator(const PathIntegrator& path, BatchTraversal traversal = BatchTraversal::Packets)
      : path_(path), traversal_(traversal) {}

  Color Li(const Scene& scene, Ray ray, Sampler& sampler, PathStats& stats) const override {
    return path_.Li(scene, ray, sampler, stats);
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
  BatchTraversal traversal_;
};

}  // namespace ember

#include <memory>
#include <optional>
#include <string_view>

namespace ember {

// How `render` and `bench` run the path tracer (--kernel). All give the same image bit for bit;
// they differ in speed (docs/performance.md).
//  - lanes:     LaneIntegrator (packet/lane_integrator.h), the bounce's state in arrays, where it
//               covers the scene; the wavefront kernel elsewhere (the default);
//  - wavefront: WavefrontIntegrator with one rtcIntersect16 / rtcOccluded16 call per packet (8
//               where that is Embree's native width: EmbreeAccel::packetWidth);
//  - stream:    WavefrontIntegrator handing each batch to Embree as one ray stream;
//  - scalar:    PathIntegrator::Li, one ray at a time (the reference implementation).
enum class Kernel { Wavefront, Stream, Scalar, Lanes };
inline constexpr const char* kKernelNames = "lanes, wavefront, stream, scalar";
std::optional<Kernel> parseKernel(std::string_view name);
std::unique_ptr<Integrator> makeIntegrator(const RenderSettings& settings, Kernel kernel);

}  // namespace ember
