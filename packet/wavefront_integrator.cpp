#include "packet/wavefront_integrator.h"

#include "accel/sampling_lanes.h"
#include "packet/bsdf_batch.h"
#include "packet/caustic_wave.h"
#include "packet/hit_prefetch.h"
#include "packet/lane_integrator.h"
#include "packet/thread_wave.h"
#include "packet/timed_trace.h"
#include "renderer/sampler_lanes.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

namespace ember {

namespace {

// One thread's paths in flight and their ray batches, allocated on the thread's first tile and
// reused: the bounce loop allocates nothing.
struct Wave {
  static constexpr size_t kSize = WavefrontIntegrator::kWaveSize;
  struct Lane {
    int x, y;
    Sampler sampler{SamplerType::Independent, 0, 0, 0};
    PathState path;
  };
  std::array<Lane, kSize> lanes;
  std::array<uint16_t, kSize> active, next, shadowOwner;
  std::array<Color, kSize> shadowContribution;
  GeometryGroups groups;  // the bounce's batch indices, grouped by geometry
  // The bounce's scattering vertices (index s), in shading order.
  std::array<uint16_t, kSize> vertexLane;
  std::array<SurfaceHit, kSize> hits;
  std::array<LightPick, kSize> picks;
  std::array<int16_t, kSize> queryOf;  // each vertex's light query, -1 if it samples no light
  // The light queries (index q), sorted by light in scenes of few lights (sampleLights): each
  // light samples its run at once.
  std::array<uint64_t, kSize> queryKey;  // samplerIndex << 16 | vertex
  std::array<Vec3, kSize> queryRef;
  std::array<Vec2, kSize> queryU;
  std::array<LightSample, kSize> querySample;
  std::array<bool, kSize> querySampled;
  BsdfBatch bsdfs;  // each vertex's BSDF sample: inputs, then what its material returned
  static_assert(kSize <= BsdfBatch::kMaxVertices);
  // Samplers whose next request the bounce draws together (renderer/sampler_lanes.h), and the
  // numbers drawn; for the light choice, the vertex each belongs to.
  std::array<Sampler*, kSize> samplerOf;
  std::array<float, kSize> drawn1D;
  std::array<Vec2, kSize> drawn2D;
  std::array<uint16_t, kSize> lightVertex;
  std::array<RequestUse, kSize> bsdfUse;  // which of its BSDF sample's numbers a vertex's material reads
  ClosestHitBatch closest{kSize};
  ShadowBatch shadows{kSize};
};

// Samples every query's light, one Light::sampleLanes call per run of queries of the same light.
void sampleLights(Wave& wave, size_t queries, size_t lights) {
  // Sorted by light, the runs fill the lanes of the lights' kernels. Queries are made in vertex
  // order, so with one light (or lights met in order) they are sorted already; with more lights
  // than a wave has vectors of queries, runs would stay short, and sorting would cost more than
  // it saves (2.5% of a render with 10,000 emitters).
  const auto keys = wave.queryKey.begin(), keysEnd = keys + ptrdiff_t(queries);
  if (lights <= Wave::kSize / SolidAngleLanes::kMaxLanes && !std::is_sorted(keys, keysEnd))
    std::sort(keys, keysEnd);
  for (size_t q = 0; q < queries; ++q) {
    const size_t v = wave.queryKey[q] & 0xffffu;
    wave.queryOf[v] = int16_t(q);
    wave.queryRef[q] = wave.hits[v].p;
    wave.queryU[q] = wave.picks[v].u;
  }
  for (size_t first = 0; first < queries;) {
    const Light* light = wave.picks[wave.queryKey[first] & 0xffffu].light;
    size_t end = first + 1;
    while (end < queries && (wave.queryKey[end] >> 16) == (wave.queryKey[first] >> 16)) ++end;
    light->sampleLanes(&wave.queryRef[first], &wave.queryU[first], end - first, &wave.querySample[first],
                       &wave.querySampled[first]);
    first = end;
  }
}

}  // namespace

void WavefrontIntegrator::traceCaustics(const Scene& scene, uint64_t seed, SamplerType sampler,
                                        uint64_t firstIndex, int count, CausticSplats& splats,
                                        PathStats& stats) const {
  traceCausticsInWaves(scene, maxDepth(), rrDepth(), seed, sampler, firstIndex, count, splats, stats,
                       traversal_);
}

void WavefrontIntegrator::renderTile(const Scene& scene, const TileWork& work, Film& film,
                                     PathStats& stats) const {
  Wave& wave = threadWave<Wave>();
  wave.closest.setWidth(scene.accel().packetWidth());
  wave.shadows.setWidth(scene.accel().packetWidth());
  const int tileWidth = work.x1 - work.x0;
  const uint64_t pixels = uint64_t(tileWidth) * uint64_t(work.y1 - work.y0);
  const uint64_t total = pixels * uint64_t(work.spp);
  const uint64_t width = uint64_t(film.width());
  // The light choice reads its number only among several lights, and the light's sample its two
  // only where some light is not a point, spot or directional light; numbers no one reads are
  // passed over, not computed (renderer/sampler_lanes.h).
  const LightSampler& lights = scene.lightSampler();
  const RequestUse lightUse{lights.size() > 1, lights.deltaLightCount() < lights.size()};

  // Camera samples are taken sample index by sample index, each over all of the tile's pixels.
  for (uint64_t first = 0; first < total; first += Wave::kSize) {
    const size_t count = size_t(std::min<uint64_t>(Wave::kSize, total - first));
    PhaseClock phases(work.timePhases, stats.phaseNanoseconds);
    size_t active = 0;
    // Each ray goes into the next batch where it is made, while its path is in cache.
    wave.closest.clear();
    for (size_t i = 0; i < count; ++i) {
      const uint64_t k = first + i;
      const uint64_t s = k / pixels, inTile = k % pixels;
      Wave::Lane& lane = wave.lanes[i];
      lane.x = work.x0 + int(inTile % uint64_t(tileWidth));
      lane.y = work.y0 + int(inTile / uint64_t(tileWidth));
      lane.sampler =
          Sampler(work.sampler, work.seed, uint64_t(lane.y) * width + uint64_t(lane.x), work.firstSample + s);
      wave.samplerOf[i] = &lane.sampler;
    }
    draw2DLanes(wave.samplerOf.data(), count, wave.drawn2D.data());  // the pixel jitter
    for (size_t i = 0; i < count; ++i) {
      Wave::Lane& lane = wave.lanes[i];
      if (path_.start(cameraRay(scene, lane.x, lane.y, wave.drawn2D[i]), lane.path)) {
        wave.active[active++] = uint16_t(i);
        wave.closest.push(lane.path.ray);
      }
    }

    phases.mark(PathPhase::Camera);
    while (active > 0) {
      stats.rays += active;
      traceTimed(wave.closest, scene.accel(), traversal_, stats);
      phases.mark(PathPhase::TraceClosest);

      // The steps of PathIntegrator::onHit, each for the whole bounce: arrival and the light
      // choice, then the lights' samples, then shadow rays and scattering.
      wave.groups.group(wave.closest, active, scene.geometryCount());
      size_t vertices = 0, lightDraws = 0, queries = 0;
      const bool prefetch = scene.prefetchesMeshHits();
      for (size_t o = 0; o < active; ++o) {
        if (prefetch) prefetchGroupedHits(scene, wave.closest, wave.groups, o, active);
        const size_t a = wave.groups.order()[o];
        Wave::Lane& lane = wave.lanes[wave.active[a]];
        RawHit raw;
        if (!wave.closest.hit(a, raw)) {
          path_.onMiss(scene, lane.path);
          continue;
        }
        SurfaceHit& hit = wave.hits[vertices];
        scene.surfaceHit(lane.path.ray, raw, hit);
        if (!path_.arrive(scene, lane.path, hit, stats)) continue;
        wave.vertexLane[vertices] = wave.active[a];
        wave.queryOf[vertices] = -1;
        if (path_.samplesLights(scene, hit)) {
          wave.lightVertex[lightDraws] = uint16_t(vertices);
          wave.samplerOf[lightDraws++] = &lane.sampler;
        }
        ++vertices;
      }
      phases.mark(PathPhase::Arrival);
      // pickLight for the bounce: its 1D, then its 2D request, then the choice.
      draw1DThen2DLanes(wave.samplerOf.data(), lightDraws, wave.drawn1D.data(), wave.drawn2D.data(),
                        lightUse);
      for (size_t j = 0; j < lightDraws; ++j) {
        const size_t v = wave.lightVertex[j];
        if (PathIntegrator::pickLightWith(scene, wave.drawn1D[j], wave.drawn2D[j], wave.picks[v]))
          wave.queryKey[queries++] = uint64_t(wave.picks[v].light->samplerIndex) << 16 | v;
      }
      phases.mark(PathPhase::LightChoice);
      sampleLights(wave, queries, lights.size());
      phases.mark(PathPhase::LightSamples);

      wave.shadows.clear();
      size_t next = 0;
      for (size_t v = 0; v < vertices; ++v) {
        Wave::Lane& lane = wave.lanes[wave.vertexLane[v]];
        const int q = wave.queryOf[v];
        ShadowRequest shadow;
        if (q >= 0 && path_.shadowFor(wave.hits[v], lane.path, wave.picks[v], wave.querySample[size_t(q)],
                                      wave.querySampled[size_t(q)], stats, shadow)) {
          wave.shadowOwner[wave.shadows.size()] = wave.vertexLane[v];
          wave.shadowContribution[wave.shadows.size()] = shadow.contribution;
          wave.shadows.push(shadow.ray, shadow.mask);
        }
        wave.bsdfs.hit[v] = &wave.hits[v];
        wave.bsdfs.wo[v] = -lane.path.ray.dir;
        wave.samplerOf[v] = &lane.sampler;
        const Material& material = *wave.hits[v].material;
        wave.bsdfUse[v] = {material.usesDirectionSample(), material.usesLobeSample()};
      }
      phases.mark(PathPhase::NextEvent);
      // PathIntegrator::drawBsdfSample for the bounce: its 2D, then its 1D request.
      draw2DThen1DLanes(wave.samplerOf.data(), vertices, wave.bsdfs.u.data(), wave.bsdfs.uLobe.data(),
                        wave.bsdfUse.data());
      wave.bsdfs.sampleAll(vertices);
      phases.mark(PathPhase::BsdfSamples);
      wave.closest.clear();  // its hits are all read
      for (size_t v = 0; v < vertices; ++v) {
        Wave::Lane& lane = wave.lanes[wave.vertexLane[v]];
        if (path_.followBsdfSample(lane.path, wave.hits[v], wave.bsdfs.sample[v], wave.bsdfs.sampled[v],
                                   lane.sampler)) {
          wave.next[next++] = wave.vertexLane[v];
          wave.closest.push(lane.path.ray, lane.path.rayMask);
        }
      }

      phases.mark(PathPhase::Continuation);
      traceTimed(wave.shadows, scene.accel(), traversal_, stats);
      for (size_t j = 0; j < wave.shadows.size(); ++j)
        if (!wave.shadows.occluded(j))
          wave.lanes[wave.shadowOwner[j]].path.radiance += wave.shadowContribution[j];
      std::swap(wave.active, wave.next);
      active = next;
      phases.mark(PathPhase::TraceShadows);
    }

    for (size_t i = 0; i < count; ++i)
      addToFilm(film, work, wave.lanes[i].x, wave.lanes[i].y, int((first + i) / pixels),
                wave.lanes[i].path.radiance, stats);
    phases.mark(PathPhase::Camera);  // the film, with the pixels' other work
  }
}

}  // namespace ember

namespace ember {

std::optional<Kernel> parseKernel(std::string_view name) {
  if (name == "wavefront") return Kernel::Wavefront;
  if (name == "stream") return Kernel::Stream;
  if (name == "scalar") return Kernel::Scalar;
  if (name == "lanes") return Kernel::Lanes;
  return std::nullopt;
}

std::unique_ptr<Integrator> makeIntegrator(const RenderSettings& settings, Kernel kernel) {
  switch (kernel) {
    case Kernel::Scalar:
      return std::make_unique<PathIntegrator>(settings);
    case Kernel::Stream:
      return std::make_unique<WavefrontIntegrator>(settings, BatchTraversal::Stream);
    case Kernel::Lanes:
      return std::make_unique<LaneIntegrator>(settings);
    case Kernel::Wavefront:
      break;
  }
  return std::make_unique<WavefrontIntegrator>(settings, BatchTraversal::Packets);
}

}  // namespace ember
