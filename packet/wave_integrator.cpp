#include "packet/wave_integrator.h"

#include "materials/lambertian.h"

#include "core/sampling.h"
#include "core/warp_lanes.h"
#include "packet/arrival_lanes.h"
#include "packet/bsdf_batch.h"
#include "packet/caustic_wave.h"
#include "packet/continuation_lanes.h"
#include "packet/geometry_groups.h"
#include "packet/hit_prefetch.h"
#include "packet/next_event_lanes.h"
#include "packet/ray_batch.h"
#include "packet/thread_wave.h"
#include "packet/timed_trace.h"
#include "renderer/sampler_lanes.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <numeric>
#include <vector>

namespace ember {

namespace {

// One thread's wave, allocated on its first tile and reused: the bounce allocates nothing.
// Three index spaces: camera samples (i, the wave's lanes), paths in flight (slot s, compacted
// after every bounce) and the bounce's scattering vertices (v, in geometry order).
struct Wave {
  static constexpr size_t kSize = WaveIntegrator::kWaveSize;
  static_assert(kSize <= GeometryGroups::kMaxLanes);
  static_assert(kSize <= NextEventArrays::kCapacity);
  // Rows one cache line longer than the wave, for the reason NextEventArrays::kStride gives.
  template <class T>
  using Row = std::array<T, kSize + 64 / sizeof(T) + 1>;

  // Camera samples: the pixel, the sample's index within the tile's pass, the sampler and the
  // radiance gathered.
  Row<int> x, y, sample;
  std::vector<Sampler> samplers = std::vector<Sampler>(kSize, Sampler(SamplerType::Independent, 0, 0, 0));
  Row<Color> radiance;
  // Each camera sample's AOVs (renderer/aov.h), when the film has any.
  Row<AovSample> aov;
  // Paths in flight: the ray cast and what its next vertex needs.
  PathArrays paths;
  // Vertices: NextEventArrays holds their points, normals, errors, directions back, reflectances
  // and throughputs beside their light samples, ContinuationArrays their BSDF samples and paths.
  NextEventArrays nee;
  ContinuationArrays cont;
  // A vertex the kernels do not evaluate inline (Material::lambertianAt is false there): its
  // material, whose own methods evaluate and sample it, and its full hit record; null for a
  // vertex in the kernels' Lambertian form.
  Row<const Material*> general;
  Row<SurfaceHit> hit;
  Row<const Light*> light;
  Row<Vec2> lightU;           // the light sample's numbers
  Row<uint16_t> lightVertex;  // the vertices that sample a light
  // Light queries (q), sorted by light where that makes runs: samplerIndex << 16 | vertex. Those of
  // the kernels' Lambertian vertices fill the next-event rows; the general vertices' come back as
  // LightSamples (Light::sampleLanes), for PathIntegrator::shadowFor.
  Row<uint64_t> queryKey, generalKey;
  Row<Vec3> generalRef;
  Row<Vec2> generalU;
  Row<LightSample> generalSample;
  Row<bool> generalSampled;
  // The general vertices' BSDF samples (Material::sampleLanes, one call per run of a material).
  BsdfBatch bsdfs;
  Row<uint16_t> generalVertex;
  // Sampler requests drawn together (renderer/sampler_lanes.h).
  Row<Sampler*> samplerOf;
  Row<float> drawn1D, roulette;
  Row<Vec2> drawn2D;
  Row<RequestUse> bsdfUse;
  CosineLanes cosine;
  Row<uint16_t> rouletteVertex;  // the vertices deep enough for Russian roulette
  Row<int32_t> project;          // the vertices whose points the arrival kernel leaves to project
  // The bounce's hits in order of geometry: the vertices then run one shape's code at a time, and
  // their shadow rays and next rays, made in that order, fill packets with coherent rays (which
  // Embree traces 1.1-1.7x faster than rays in pixel order, measured on shapes.json).
  GeometryGroups groups;
  ClosestHitBatch closest{kSize};
  ShadowBatch shadows{kSize};
};

void store3(float (&rows)[3][NextEventArrays::kStride], size_t v, const Vec3& value) {
  rows[0][v] = value.x, rows[1][v] = value.y, rows[2][v] = value.z;
}
Vec3 load3(const float (&rows)[3][NextEventArrays::kStride], size_t v) {
  return {rows[0][v], rows[1][v], rows[2][v]};
}

// A row triple as the pointers ClosestHitBatch::assign takes.
std::array<const float*, 3> rowsOf(const float (&rows)[3][NextEventArrays::kStride]) {
  return {rows[0], rows[1], rows[2]};
}

// Sorts light queries (samplerIndex << 16 | vertex) by light where that makes runs, and calls
// sample(first, count) once per run of one light. Queries are made in vertex order, so with one
// light (or lights met in order) they are sorted already; with more lights than a wave has vectors
// of queries, runs would stay short, and sorting would cost more than it saves.
template <class SampleRun>
void forEachLightRun(uint64_t* keys, size_t queries, size_t lights, SampleRun&& sample) {
  if (lights <= Wave::kSize / SolidAngleLanes::kMaxLanes && !std::is_sorted(keys, keys + queries))
    std::sort(keys, keys + queries);
  for (size_t first = 0; first < queries;) {
    size_t end = first + 1;
    while (end < queries && (keys[end] >> 16) == (keys[first] >> 16)) ++end;
    sample(first, end - first);
    first = end;
  }
}

// Samples the chosen lights of the vertices in the kernels' Lambertian form into the next-event
// arrays (Light::sampleRun, PathIntegrator's light sample in row form); a vertex without a sample
// keeps lightPdf -1.
[[gnu::noinline]] void sampleLights(Wave& wave, size_t queries, size_t lights) {
  NextEventArrays& nee = wave.nee;
  const float* const refRows[3] = {nee.p[0], nee.p[1], nee.p[2]};
  const LightSampleRows rows{{nee.lightP[0], nee.lightP[1], nee.lightP[2]},
                             {nee.lightN[0], nee.lightN[1], nee.lightN[2]},
                             {nee.lightWi[0], nee.lightWi[1], nee.lightWi[2]},
                             {nee.lightLi[0], nee.lightLi[1], nee.lightLi[2]},
                             nee.lightPError,
                             nee.lightPdf,
                             nee.delta,
                             nee.infinite,
                             nee.pointLight};
  const uint64_t* keys = wave.queryKey.data();
  forEachLightRun(wave.queryKey.data(), queries, lights, [&](size_t first, size_t n) {
    wave.light[keys[first] & 0xffffu]->sampleRun(&keys[first], n, refRows, wave.lightU.data(), rows);
  });
}

// Samples the general vertices' chosen lights into LightSamples (Light::sampleLanes), for
// PathIntegrator::shadowFor.
void sampleGeneralLights(Wave& wave, size_t queries, size_t lights) {
  forEachLightRun(wave.generalKey.data(), queries, lights, [&](size_t first, size_t n) {
    for (size_t q = first; q < first + n; ++q) {
      const size_t v = wave.generalKey[q] & 0xffffu;
      wave.generalRef[q] = wave.hit[v].p;
      wave.generalU[q] = wave.lightU[v];
    }
    wave.light[wave.generalKey[first] & 0xffffu]->sampleLanes(&wave.generalRef[first], &wave.generalU[first],
                                                              n, &wave.generalSample[first],
                                                              &wave.generalSampled[first]);
  });
}

}  // namespace

void WaveIntegrator::traceCaustics(const Scene& scene, uint64_t seed, SamplerType sampler,
                                   uint64_t firstIndex, int count, CausticSplats& splats,
                                   PathStats& stats) const {
  traceCausticsInWaves(scene, maxDepth(), rrDepth(), seed, sampler, firstIndex, count, splats, stats);
}

void WaveIntegrator::renderTile(const Scene& scene, const TileWork& work, Film& film,
                                PathStats& stats) const {
  Wave& wave = threadWave<Wave>();
  NextEventArrays& nee = wave.nee;
  wave.closest.setWidth(scene.accel().packetWidth());
  wave.shadows.setWidth(scene.accel().packetWidth());
  const uint64_t pixels = uint64_t(work.x1 - work.x0) * uint64_t(work.y1 - work.y0);
  const uint64_t total = pixels * uint64_t(work.spp);
  const uint64_t width = uint64_t(film.width());
  const LightSampler& lights = scene.lightSampler();
  const RequestUse lightUse{lights.size() > 1, lights.deltaLightCount() < lights.size()};
  const int maxDepth = path_.maxDepth(), rrDepth = path_.rrDepth();
  const bool aovs = film.aovs().perSample();

  // Camera sample k of the tile is pixel k % pixels (row by row) of sample k / pixels; the wave
  // steps through them in that order, counting instead of dividing.
  // Under adaptive sampling the samples beyond a pixel's budget are passed over (TileWork::wants).
  int x = work.x0, y = work.y0, sample = 0;
  for (uint64_t next = 0; next < total;) {
    PhaseClock phases(work.timePhases, stats.phaseNanoseconds);
    size_t count = 0;
    for (; count < Wave::kSize && next < total; ++next) {
      if (work.wants(x, y, sample)) {
        const size_t i = count++;
        wave.x[i] = x;
        wave.y[i] = y;
        wave.sample[i] = sample;
        wave.samplers[i] = Sampler(work.sampler, work.seed, uint64_t(y) * width + uint64_t(x),
                                   work.firstSample + uint64_t(sample));
        wave.samplerOf[i] = &wave.samplers[i];
      }
      if (++x == work.x1) {
        x = work.x0;
        if (++y == work.y1) y = work.y0, ++sample;
      }
    }
    if (count == 0) break;
    draw2DLanes(wave.samplerOf.data(), count, wave.drawn2D.data());  // the pixel jitter
    // PathIntegrator::start: paths of zero segments carry no light.
    PathArrays& paths = wave.paths;
    ContinuationArrays& cont = wave.cont;
    std::fill_n(wave.radiance.begin(), count, Color(0.0f));
    if (aovs) std::fill_n(wave.aov.begin(), count, AovSample{});
    size_t active = maxDepth == 0 ? 0 : count;  // camera sample i is slot i
    const Camera& camera = scene.camera();
    if (camera.perspective()) {
      // The camera rays in lanes (Camera::generateRay's directions, bit for bit), all from its origin.
      perspectiveDirections(camera.perspectiveFrame(), wave.x.data(), wave.y.data(), wave.drawn2D.data(),
                            active, {paths.dir[0], paths.dir[1], paths.dir[2]});
      for (int k = 0; k < 3; ++k) std::fill_n(paths.origin[k], active, camera.origin()[k]);
    } else {
      for (size_t i = 0; i < active; ++i) {
        const Ray ray = cameraRay(scene, wave.x[i], wave.y[i], wave.drawn2D[i]);
        store3(paths.origin, i, ray.origin);
        store3(paths.dir, i, ray.dir);
      }
    }
    for (int k = 0; k < 3; ++k) {
      std::fill_n(paths.throughput[k], active, 1.0f);
      std::copy_n(paths.origin[k], active, paths.previousPoint[k]);
    }
    std::fill_n(paths.previousPdf, active, 0.0f);
    std::fill_n(paths.etaProduct, active, 1.0f);
    std::iota(paths.owner, paths.owner + active, 0);
    std::fill_n(paths.depth, active, 1);
    std::fill_n(paths.previousDelta, active, -1);  // the camera's is a Dirac "lobe"
    std::fill_n(paths.firstBounceNonDelta, active, 0);
    std::fill_n(paths.mask, active, kAllRayMask);
    wave.closest.assign(rowsOf(paths.origin), rowsOf(paths.dir), paths.mask, active);

    phases.mark(PathPhase::Camera);
    while (active > 0) {
      stats.rays += active;
      traceTimed(wave.closest, scene.accel(), stats);
      phases.mark(PathPhase::TraceClosest);

      // PathIntegrator::arrive for every path, and onMiss for those that left the scene: the
      // reference's own steps, on the path's state gathered from its slot. A run of hits on an
      // analytic shape with a uniform Lambertian reflectance and no emission, at unbounded depth
      // (where every such path scatters), arrives in the vector kernel instead
      // (packet/arrival_lanes.h).
      wave.groups.group(wave.closest, active, scene.geometryCount());
      size_t vertices = 0, lightDraws = 0;
      const auto gather = [&](size_t s) {
        PathState path;
        path.ray = Ray{load3(paths.origin, s), load3(paths.dir, s)};
        path.radiance = wave.radiance[size_t(paths.owner[s])];
        path.throughput = load3(paths.throughput, s);
        path.etaProduct = paths.etaProduct[s];
        path.previousDelta = paths.previousDelta[s] != 0;
        path.previousPdf = paths.previousPdf[s];
        path.previousPoint = load3(paths.previousPoint, s);
        path.rayMask = paths.mask[s];
        path.depth = paths.depth[s];
        path.firstBounceNonDelta = paths.firstBounceNonDelta[s] != 0;
        return path;
      };
      const bool prefetch = scene.prefetchesMeshHits();
      const auto arriveOne = [&](size_t o) {
        if (prefetch) prefetchGroupedHits(scene, wave.closest, wave.groups, o, active);
        const size_t s = wave.groups.order()[o];
        const int32_t owner = paths.owner[s];
        RawHit raw;
        if (!wave.closest.hit(s, raw)) {
          if (aovs && !wave.aov[size_t(owner)].surfaceFound)
            PathIntegrator::aovOnMiss(scene, gather(s), wave.aov[size_t(owner)]);
          if (!PathIntegrator::missAddsLight(scene)) return;  // no state to gather
          PathState path = gather(s);
          path_.onMiss(scene, path);
          wave.radiance[size_t(owner)] = path.radiance;
          return;
        }
        PathState path = gather(s);
        SurfaceHit& hit = wave.hit[vertices];
        scene.surfaceHit(path.ray, raw, hit);
        PathIntegrator::widenFootprint(scene, path, hit);
        const bool scatters = path_.arrive(scene, path, hit, stats);
        wave.radiance[size_t(owner)] = path.radiance;
        if (aovs) PathIntegrator::aovOnArrival(path, hit, scatters, wave.aov[size_t(owner)]);
        if (!scatters) return;
        const size_t v = vertices++;
        Color reflectance;
        const bool inline_ = hit.material->lambertianAt(hit, reflectance);
        wave.general[v] = inline_ ? nullptr : hit.material;
        if (inline_) store3(nee.albedo, v, reflectance);
        cont.general[v] = inline_ ? 0 : -1;
        wave.bsdfUse[v] = RequestUse{hit.material->usesDirectionSample(), hit.material->usesLobeSample()};
        if (path_.samplesLights(scene, hit)) wave.lightVertex[lightDraws++] = uint16_t(v);
        store3(nee.p, v, hit.p);
        store3(nee.ng, v, hit.ng);
        nee.pError[v] = hit.pError;
        store3(nee.wo, v, -path.ray.dir);
        store3(nee.throughput, v, path.throughput);
        nee.lightPdf[v] = -1.0f;
        nee.pointLight[v] = 0;
        nee.infinite[v] = 0;
        cont.sampledDelta[v] = 0;
        cont.etaProduct[v] = path.etaProduct;
        cont.owner[v] = owner;
        cont.depth[v] = path.depth;
        cont.firstBounceNonDelta[v] = path.firstBounceNonDelta ? -1 : 0;
        cont.maskFront[v] = hit.maskFront;
        cont.maskBack[v] = hit.maskBack;
      };
      const bool runsSampleLights = path_.strategy() != Strategy::Bsdf && !lights.empty();
      const HitFields hitFields = wave.closest.hitFields();
      for (size_t r = 0; r < wave.groups.runCount(); ++r) {
        const GeometryGroups::Run run = wave.groups.runs()[r];
        const uint16_t* slots = wave.groups.order() + run.begin;
        const size_t count = size_t(run.end - run.begin);
        const Scene::GeometryRecord* rec =
            run.geometry == RTC_INVALID_GEOMETRY_ID ? nullptr : &scene.record(run.geometry);
        const Color* albedo = rec && rec->shape && rec->material && isBlack(rec->emission)
                                  ? rec->material->uniformLambertian()
                                  : nullptr;
        // A camera sample still looking for its AOVs' vertex takes the general steps, which record
        // them (the image is the same either way).
        const auto seeksAovs = [&] {
          for (size_t j = 0; j < count; ++j)
            if (!wave.aov[size_t(paths.owner[slots[j]])].surfaceFound) return true;
          return false;
        };
        if (maxDepth >= 0 || !albedo || isBlack(*albedo) || (aovs && seeksAovs())) {
          for (size_t o = run.begin; o < run.end; ++o) arriveOne(o);
          continue;
        }
        // Every path of the run scatters at its vertex: the depth is unbounded, the reflectance
        // not black, and the surface emits nothing.
        const size_t first = vertices;
        const size_t far = arriveLambertianLanes(
            hitFields, paths, LambertianRun{slots, count, first, *albedo, rec->maskFront, rec->maskBack}, nee,
            cont, wave.project.data());
        for (size_t j = 0; j < far; ++j) {  // Scene::surfaceHit's projection branch
          const size_t v = size_t(wave.project[j]);
          RawHit raw;
          wave.closest.hit(slots[v - first], raw);
          const SurfacePoint onSurface =
              rec->shape->projectToSurface(load3(nee.p, v), LocalHit{raw.t, raw.ng, raw.uv});
          store3(nee.p, v, onSurface.p);
          nee.pError[v] = onSurface.error;
        }
        std::fill_n(&wave.general[first], count, nullptr);
        std::fill_n(&wave.bsdfUse[first], count,
                    RequestUse{rec->material->usesDirectionSample(), rec->material->usesLobeSample()});
        if (runsSampleLights)
          for (size_t j = 0; j < count; ++j) wave.lightVertex[lightDraws++] = uint16_t(first + j);
        vertices += count;
        stats.vertices += count;
      }
      phases.mark(PathPhase::Arrival);

      // The light choice (pickLight: its 1D, then its 2D request) and the lights' samples.
      for (size_t j = 0; j < lightDraws; ++j)
        wave.samplerOf[j] = &wave.samplers[size_t(cont.owner[wave.lightVertex[j]])];
      draw1DThen2DLanes(wave.samplerOf.data(), lightDraws, wave.drawn1D.data(), wave.drawn2D.data(),
                        lightUse);
      size_t queries = 0, generalQueries = 0;
      for (size_t j = 0; j < lightDraws; ++j) {
        LightPick pick;
        if (!PathIntegrator::pickLightWith(scene, wave.drawn1D[j], wave.drawn2D[j], pick)) continue;
        const size_t v = wave.lightVertex[j];
        wave.light[v] = pick.light;
        nee.lightMask[v] = pick.light->shadowMask;
        wave.lightU[v] = pick.u;
        nee.pmf[v] = pick.pmf;
        const uint64_t key = uint64_t(pick.light->samplerIndex) << 16 | v;
        if (wave.general[v])
          wave.generalKey[generalQueries++] = key;
        else
          wave.queryKey[queries++] = key;
      }
      phases.mark(PathPhase::LightChoice);
      sampleLights(wave, queries, lights.size());
      sampleGeneralLights(wave, generalQueries, lights.size());
      phases.mark(PathPhase::LightSamples);

      // PathIntegrator::shadowFor: the kernel's Lambertian vertices together, then the general
      // vertices' own, appended to the compacted shadow rows.
      size_t shadowRays =
          nextEventLanes(nee, cont.maskFront, cont.maskBack, vertices, path_.strategy() == Strategy::Mis);
      stats.shadowRays += shadowRays;
      for (size_t q = 0; q < generalQueries; ++q) {
        const size_t v = wave.generalKey[q] & 0xffffu;
        PathState path;
        path.ray.dir = -load3(nee.wo, v);
        path.throughput = load3(nee.throughput, v);
        const LightPick pick{wave.light[v], nee.pmf[v], wave.lightU[v]};
        ShadowRequest shadow;
        if (!path_.shadowFor(wave.hit[v], path, pick, wave.generalSample[q], wave.generalSampled[q], stats,
                             shadow))
          continue;
        store3(nee.contribution, v, shadow.contribution);
        store3(nee.shadowOrigin, shadowRays, shadow.ray.origin);
        store3(nee.shadowDir, shadowRays, shadow.ray.dir);
        nee.shadowTMax[shadowRays] = shadow.ray.tMax;
        nee.shadowMask[shadowRays] = shadow.mask;
        nee.shadowVertex[shadowRays++] = int32_t(v);
      }
      wave.shadows.assign(rowsOf(nee.shadowOrigin), rowsOf(nee.shadowDir), nee.shadowTMax, nee.shadowMask,
                          shadowRays);
      phases.mark(PathPhase::NextEvent);

      // PathIntegrator::drawBsdfSample: its 2D, then its 1D request; then Russian roulette's
      // number where the path is deep enough to play. (A path that ends at this vertex draws its
      // number too, which nothing reads: its sampler is not asked again.)
      for (size_t v = 0; v < vertices; ++v) wave.samplerOf[v] = &wave.samplers[size_t(cont.owner[v])];
      draw2DThen1DLanes(wave.samplerOf.data(), vertices, wave.drawn2D.data(), wave.drawn1D.data(),
                        wave.bsdfUse.data());
      size_t plays = 0;
      for (size_t v = 0; v < vertices; ++v)
        if (cont.depth[v] >= rrDepth) {
          wave.samplerOf[plays] = wave.samplerOf[v];
          wave.rouletteVertex[plays++] = uint16_t(v);
        }
      draw1DLanes(wave.samplerOf.data(), plays, wave.roulette.data());
      for (size_t j = 0; j < plays; ++j) cont.roulette[wave.rouletteVertex[j]] = wave.roulette[j];
      phases.mark(PathPhase::BsdfSamples);

      // The BSDF samples: the Lambertian vertices' in blocks of the cosine kernel
      // (Lambertian::sample's), the general vertices' from their materials (Material::sampleLanes,
      // one call per run of a material), into the continuation's rows; then followBsdfSample for
      // all vertices in one kernel, which writes the paths that go on into the slots, and their
      // rays as the next batch.
      size_t generals = 0;
      for (size_t block = 0; block < vertices; block += CosineLanes::kMaxLanes) {
        const unsigned n = unsigned(std::min<size_t>(CosineLanes::kMaxLanes, vertices - block));
        for (unsigned i = 0; i < n; ++i) {
          const size_t v = block + i;
          const Vec3 ng = load3(nee.ng, v), wo = load3(nee.wo, v);
          wave.cosine.set(i, glm::dot(wo, ng) >= 0.0f ? ng : -ng, wave.drawn2D[v]);
          if (!wave.general[v]) continue;
          wave.bsdfs.hit[generals] = &wave.hit[v];
          wave.bsdfs.wo[generals] = wo;
          wave.bsdfs.u[generals] = wave.drawn2D[v];
          wave.bsdfs.uLobe[generals] = wave.drawn1D[v];
          wave.generalVertex[generals++] = uint16_t(v);
        }
        sampleCosineLanes(wave.cosine, wave.cosine.padFrom(n));
        // Whole blocks, so that the continuation kernel's vector loads find whole stores.
        for (int c = 0; c < 3; ++c) std::copy_n(wave.cosine.wi[c], n, &cont.wi[c][block]);
        std::copy_n(wave.cosine.pdf, n, &cont.pdf[block]);
      }
      wave.bsdfs.sampleAll(generals);
      for (size_t g = 0; g < generals; ++g) {
        const size_t v = wave.generalVertex[g];
        const bool sampled = wave.bsdfs.sampled[g];
        cont.generalSampled[v] = sampled ? -1 : 0;
        if (!sampled) continue;
        const BsdfSample& bs = wave.bsdfs.sample[g];
        store3(cont.wi, v, bs.wi);
        store3(cont.weight, v, bs.weight);
        cont.pdf[v] = bs.pdf;
        cont.eta[v] = bs.eta;
        cont.sampledDelta[v] = bs.delta ? -1 : 0;
      }
      if (aovs)
        for (size_t v = 0; v < vertices; ++v) {
          AovSample& aov = wave.aov[size_t(cont.owner[v])];
          if (!aov.surfaceFound || aov.albedoKnown) continue;
          if (wave.general[v]) {
            PathIntegrator::aovOnSample(cont.generalSampled[v] != 0, load3(cont.weight, v), aov);
          } else {  // Lambertian::sample's test, and its weight: the reflectance
            const bool sampled =
                Lambertian::keepsSample(load3(nee.ng, v), load3(nee.wo, v), load3(cont.wi, v), cont.pdf[v]);
            PathIntegrator::aovOnSample(sampled, load3(nee.albedo, v), aov);
          }
        }
      const size_t next = continuationLanes(nee, cont, vertices, rrDepth, paths);
      wave.closest.assign(rowsOf(paths.origin), rowsOf(paths.dir), paths.mask, next);
      phases.mark(PathPhase::Continuation);

      traceTimed(wave.shadows, scene.accel(), stats);
      for (size_t j = 0; j < wave.shadows.size(); ++j) {
        if (wave.shadows.occluded(j)) continue;
        const size_t v = size_t(nee.shadowVertex[j]);
        wave.radiance[size_t(cont.owner[v])] += load3(nee.contribution, v);
      }
      active = next;
      phases.mark(PathPhase::TraceShadows);
    }

    if (aovs)
      for (size_t i = 0; i < count; ++i)
        addToFilm(film, work, wave.x[i], wave.y[i], wave.sample[i], wave.radiance[i], wave.aov[i], stats);
    else
      for (size_t i = 0; i < count; ++i)
        addToFilm(film, work, wave.x[i], wave.y[i], wave.sample[i], wave.radiance[i], stats);
    phases.mark(PathPhase::Camera);
  }
}

}  // namespace ember

namespace ember {

std::optional<Kernel> parseKernel(std::string_view name) {
  if (name == "wave" || name == "lanes" || name == "wavefront") return Kernel::Wave;
  if (name == "scalar") return Kernel::Scalar;
  return std::nullopt;
}

std::unique_ptr<Integrator> makeIntegrator(const RenderSettings& settings, Kernel kernel) {
  if (kernel == Kernel::Scalar) return std::make_unique<PathIntegrator>(settings);
  return std::make_unique<WaveIntegrator>(settings);
}

}  // namespace ember
