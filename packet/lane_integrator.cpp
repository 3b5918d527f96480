#include "packet/lane_integrator.h"

#include "core/sampling.h"
#include "core/warp_lanes.h"
#include "materials/lambertian.h"
#include "materials/specular.h"
#include "packet/arrival_lanes.h"
#include "packet/continuation_lanes.h"
#include "packet/next_event_lanes.h"
#include "packet/packet_fields.h"
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
struct LaneWave {
  static constexpr size_t kSize = LaneIntegrator::kWaveSize;
  static_assert(kSize <= NextEventArrays::kCapacity);
  // Rows one cache line longer than the wave, for the reason NextEventArrays::kStride gives.
  template <class T>
  using Row = std::array<T, kSize + 64 / sizeof(T) + 1>;

  // Camera samples: the pixel, the sample's index within the tile's pass, the sampler and the
  // radiance gathered.
  Row<int> x, y, sample;
  std::vector<Sampler> samplers = std::vector<Sampler>(kSize, Sampler(SamplerType::Independent, 0, 0, 0));
  Row<Color> radiance;
  // Paths in flight: the ray cast and what its next vertex needs.
  PathArrays paths;
  // Vertices: NextEventArrays holds their points, normals, errors, directions back, reflectances
  // and throughputs beside their light samples, ContinuationArrays their BSDF samples and paths.
  NextEventArrays nee;
  ContinuationArrays cont;
  // A Dirac vertex's material (mirror, glass: no light sample) and its full hit record, which the
  // material's scalar sample() reads; null for a Lambertian vertex.
  Row<const Material*> dirac;
  Row<SurfaceHit> diracHit;
  Row<const Light*> light;
  Row<Vec2> lightU;           // the light sample's numbers
  Row<uint16_t> lightVertex;  // the vertices that sample a light
  // Light queries (q), sorted by light where that makes runs: samplerIndex << 16 | vertex.
  Row<uint64_t> queryKey;
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

// The constant reflectance of a shape whose hits the arrival kernel takes: a Lambertian material
// without a texture. Null for any other (a Dirac material, a textured one, none).
const Color* constantLambertian(const Scene::GeometryRecord& rec) {
  if (rec.deltaLobes || !rec.material || !rec.shape) return nullptr;
  const auto* lambertian = dynamic_cast<const Lambertian*>(rec.material);
  return lambertian ? lambertian->constantReflectance() : nullptr;
}

// A row triple as the pointers ClosestHitBatch::assign takes.
std::array<const float*, 3> rowsOf(const float (&rows)[3][NextEventArrays::kStride]) {
  return {rows[0], rows[1], rows[2]};
}

void storeSample(NextEventArrays& nee, size_t v, const LightSample& ls) {
  store3(nee.lightP, v, ls.p);
  store3(nee.lightN, v, ls.n);
  store3(nee.lightWi, v, ls.wi);
  store3(nee.lightLi, v, ls.Li);
  nee.lightPError[v] = ls.pError;
  nee.lightPdf[v] = ls.pdf;
  nee.delta[v] = ls.delta ? -1 : 0;
  nee.infinite[v] = std::isfinite(ls.dist) ? 0 : -1;
}

// Light queries are kept as keys (a light's index << 16 | vertex). Within a light's run they rise
// with the vertex, and one shape's vertices are consecutive, so most of a run falls into blocks of
// kSampleBlock queries on consecutive vertices, which read and write the next-event rows as whole
// vectors. (Any order is correct; a block is found only where the keys rise one by one.)
constexpr size_t kSampleBlock = SolidAngleLanes::kMaxLanes;
bool consecutiveBlock(const uint64_t* keys, size_t q, size_t n) {
  if (q + kSampleBlock > n) return false;
  for (size_t i = 1; i < kSampleBlock; ++i)
    if (keys[q + i] != keys[q] + i) return false;
  return true;
}

// An area light's samples for the vertices `keys` name (their low 16 bits), read from
// and written to the next-event arrays; a vertex without a sample keeps lightPdf -1. Blocks of
// queries on consecutive vertices (the vertices of one shape's run are consecutive) take
// AreaLight::sampleRows, which reads and writes the rows as whole vectors; the rest take
// sampleBlocks, lane by lane.
void sampleAreaLight(const AreaLight& light, const uint64_t* keys, size_t n, NextEventArrays& nee,
                     const Vec2* lightU) {
  const float* const refRows[3] = {nee.p[0], nee.p[1], nee.p[2]};
  const LightSampleRows rows{{nee.lightP[0], nee.lightP[1], nee.lightP[2]},
                             {nee.lightN[0], nee.lightN[1], nee.lightN[2]},
                             {nee.lightWi[0], nee.lightWi[1], nee.lightWi[2]},
                             {nee.lightLi[0], nee.lightLi[1], nee.lightLi[2]},
                             nee.lightPError,
                             nee.lightPdf,
                             nee.delta,
                             nee.infinite};
  const auto consecutive = [&](size_t q) { return consecutiveBlock(keys, q, n); };
  for (size_t q = 0; q < n;) {
    size_t end = q;
    while (end < n && !consecutive(end)) ++end;
    if (end > q)
      light.sampleBlocks(
          end - q, [&](size_t i) { return load3(nee.p, keys[q + i] & 0xffffu); },
          [&](size_t i) { return lightU[keys[q + i] & 0xffffu]; },
          [&](size_t i, const LightSample& ls) { storeSample(nee, keys[q + i] & 0xffffu, ls); });
    for (; consecutive(end); end += kSampleBlock)
      light.sampleRows(refRows, lightU, size_t(keys[end] & 0xffffu), rows);
    q = end;
  }
}

// A point light's samples for the vertices `keys` name: the next-event kernel takes each from the
// light's position and intensity (renderer/light.cpp, samplePosition), which the vertices' rows
// repeat. A block of queries on consecutive vertices is filled as whole vectors: the rows from
// the block's first vertex on, seen as one packet of kSampleBlock lanes (packet/packet_fields.h).
void samplePointLight(const PointLight& light, const uint64_t* keys, size_t n, NextEventArrays& nee) {
  const Vec3 p = light.position();
  const Color intensity = light.intensity();
  const auto row = [](size_t offsetInBytes, int c = 0) {
    return offsetInBytes / sizeof(float) + size_t(c) * NextEventArrays::kStride;
  };
  const PacketFieldSource fields[] = {
      {row(offsetof(NextEventArrays, lightP), 0), nullptr, p.x},
      {row(offsetof(NextEventArrays, lightP), 1), nullptr, p.y},
      {row(offsetof(NextEventArrays, lightP), 2), nullptr, p.z},
      {row(offsetof(NextEventArrays, lightLi), 0), nullptr, intensity.x},
      {row(offsetof(NextEventArrays, lightLi), 1), nullptr, intensity.y},
      {row(offsetof(NextEventArrays, lightLi), 2), nullptr, intensity.z},
      {row(offsetof(NextEventArrays, lightN), 0), nullptr, 0.0f},
      {row(offsetof(NextEventArrays, lightN), 1), nullptr, 0.0f},
      {row(offsetof(NextEventArrays, lightN), 2), nullptr, 0.0f},
      {row(offsetof(NextEventArrays, lightPError)), nullptr, 0.0f},
      {row(offsetof(NextEventArrays, pointLight)), nullptr, std::bit_cast<float>(int32_t(-1))}};
  float* const rows = reinterpret_cast<float*>(&nee);
  for (size_t q = 0; q < n;) {
    const size_t v = keys[q] & 0xffffu;
    if (consecutiveBlock(keys, q, n)) {
      fillPacketFields(rows + v, /*stride=*/0, kSampleBlock, kSampleBlock, fields,
                       std::size(fields));  // one packet
      q += kSampleBlock;
      continue;
    }
    store3(nee.lightP, v, p);
    store3(nee.lightLi, v, intensity);
    store3(nee.lightN, v, Vec3(0.0f));
    nee.lightPError[v] = 0.0f;
    nee.pointLight[v] = -1;
    ++q;
  }
}

// Samples every vertex's chosen light, one run of queries per light (sorted by light where that
// makes runs; PathIntegrator's light sample), into the next-event arrays; a vertex without a
// sample keeps lightPdf -1. Never inlined, so that the lights' small helpers inline into it: as
// part of renderLanes, which is large, GCC's profile-guided link once left them calls (3% of
// cornell-area's render).
[[gnu::noinline]] void sampleLights(LaneWave& wave, size_t queries, size_t lights) {
  const auto keys = wave.queryKey.begin(), keysEnd = keys + ptrdiff_t(queries);
  if (lights <= LaneWave::kSize / SolidAngleLanes::kMaxLanes && !std::is_sorted(keys, keysEnd))
    std::sort(keys, keysEnd);
  for (size_t first = 0; first < queries;) {
    const Light* light = wave.light[wave.queryKey[first] & 0xffffu];
    size_t end = first + 1;
    while (end < queries && (wave.queryKey[end] >> 16) == (wave.queryKey[first] >> 16)) ++end;
    if (const auto* area = dynamic_cast<const AreaLight*>(light)) {
      sampleAreaLight(*area, &wave.queryKey[first], end - first, wave.nee, wave.lightU.data());
    } else if (const auto* point = dynamic_cast<const PointLight*>(light); point && !point->ranged()) {
      samplePointLight(*point, &wave.queryKey[first], end - first, wave.nee);
    } else {
      for (size_t q = first; q < end; ++q) {
        const size_t v = wave.queryKey[q] & 0xffffu;
        LightSample ls;
        if (light->sample(load3(wave.nee.p, v), wave.lightU[v], ls)) storeSample(wave.nee, v, ls);
      }
    }
    first = end;
  }
}

}  // namespace

std::string LaneIntegrator::uncovered(const Scene& scene, Strategy strategy) {
  if (strategy != Strategy::Mis) return "strategy " + std::string(strategyName(strategy));
  if (!scene.meshes.empty()) return "triangle meshes";
  for (const Scene::ShapeEntry& entry : scene.shapes) {
    const Material* m = entry.material;
    if (m && !dynamic_cast<const Lambertian*>(m) && !dynamic_cast<const Mirror*>(m) &&
        !dynamic_cast<const Refraction*>(m) && !dynamic_cast<const Dielectric*>(m))
      return "a " + std::string(m->typeName()) + " material";
  }
  return "";
}

bool LaneIntegrator::coversOnce(const Scene& scene) const {
  const uint64_t last = lastCovered_.load(std::memory_order_relaxed);
  if (last >> 1 == scene.buildSerial()) return last & 1u;
  const bool answer = covers(scene, path_.strategy());
  lastCovered_.store(scene.buildSerial() << 1 | uint64_t(answer), std::memory_order_relaxed);
  return answer;
}

void LaneIntegrator::renderTile(const Scene& scene, const TileWork& work, Film& film,
                                PathStats& stats) const {
  if (coversOnce(scene))
    renderLanes(scene, work, film, stats);
  else
    wavefront_.renderTile(scene, work, film, stats);
}

void LaneIntegrator::renderLanes(const Scene& scene, const TileWork& work, Film& film,
                                 PathStats& stats) const {
  LaneWave& wave = threadWave<LaneWave>();
  NextEventArrays& nee = wave.nee;
  wave.closest.setWidth(scene.accel().packetWidth());
  wave.shadows.setWidth(scene.accel().packetWidth());
  const uint64_t pixels = uint64_t(work.x1 - work.x0) * uint64_t(work.y1 - work.y0);
  const uint64_t total = pixels * uint64_t(work.spp);
  const uint64_t width = uint64_t(film.width());
  const LightSampler& lights = scene.lightSampler();
  const RequestUse lightUse{lights.size() > 1, lights.deltaLightCount() < lights.size()};
  const int maxDepth = path_.maxDepth(), rrDepth = path_.rrDepth();
  const bool tracesCaustics = path_.tracesCaustics();

  // Camera sample k of the tile is pixel k % pixels (row by row) of sample k / pixels; the wave
  // steps through them in that order, counting instead of dividing.
  int x = work.x0, y = work.y0, sample = 0;
  for (uint64_t first = 0; first < total; first += LaneWave::kSize) {
    const size_t count = size_t(std::min<uint64_t>(LaneWave::kSize, total - first));
    PhaseClock phases(work.timePhases, stats.phaseNanoseconds);
    for (size_t i = 0; i < count; ++i) {
      wave.x[i] = x;
      wave.y[i] = y;
      wave.sample[i] = sample;
      wave.samplers[i] = Sampler(work.sampler, work.seed, uint64_t(y) * width + uint64_t(x),
                                 work.firstSample + uint64_t(sample));
      wave.samplerOf[i] = &wave.samplers[i];
      if (++x == work.x1) {
        x = work.x0;
        if (++y == work.y1) y = work.y0, ++sample;
      }
    }
    draw2DLanes(wave.samplerOf.data(), count, wave.drawn2D.data());  // the pixel jitter
    // PathIntegrator::start: paths of zero segments carry no light.
    PathArrays& paths = wave.paths;
    ContinuationArrays& cont = wave.cont;
    std::fill_n(wave.radiance.begin(), count, Color(0.0f));
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
      traceTimed(wave.closest, scene.accel(), BatchTraversal::Packets, stats);
      phases.mark(PathPhase::TraceClosest);

      // PathIntegrator::arrive for every path: its emission, or the environment's where it left
      // the scene, and the vertices that scatter. At unbounded depth (where every path goes on
      // from a Lambertian vertex) a run of hits on a shape with a constant Lambertian reflectance
      // arrives in the vector kernel (packet/arrival_lanes.h), every other hit one at a time.
      wave.groups.group(wave.closest, active, scene.geometryCount());
      size_t vertices = 0, lightDraws = 0;
      // PathIntegrator::arrive's emission at vertex point p, normal ng, for the path in slot s; a
      // caustic path's is the light tracer's.
      const auto addEmission = [&](const Scene::GeometryRecord& rec, size_t s, const Vec3& p, const Vec3& ng,
                                   const Vec3& wo, const Color& throughput) {
        const bool previousDelta = paths.previousDelta[s] != 0;
        const bool caustic = tracesCaustics && previousDelta && paths.firstBounceNonDelta[s] != 0 &&
                             rec.light && rec.light->causticTraced;
        if (isBlack(rec.emission) || !(rec.twoSidedEmission || glm::dot(wo, ng) > 0.0f) || caustic) return;
        float weight = 1.0f;
        if (!previousDelta) {
          const float lightPdf =
              rec.light ? lights.pmf(rec.light) * rec.light->pdf(load3(paths.previousPoint, s), p, ng) : 0.0f;
          weight = powerHeuristic(paths.previousPdf[s], lightPdf);
        }
        wave.radiance[size_t(paths.owner[s])] += throughput * rec.emission * weight;
      };
      const auto arriveOne = [&](size_t s) {
        const Vec3 dir = load3(paths.dir, s);
        Color throughput = load3(paths.throughput, s);
        const int32_t owner = paths.owner[s];
        const bool previousDelta = paths.previousDelta[s] != 0;
        RawHit raw;
        if (!wave.closest.hit(s, raw)) {
          // PathIntegrator::onMiss: the environment the ray sees, if any; the path ends.
          if (const EnvironmentLight* env = scene.environment()) {
            float weight = 1.0f;
            if (!previousDelta)
              weight = powerHeuristic(paths.previousPdf[s], lights.pmf(env) * env->pdfDirection(dir));
            wave.radiance[owner] += throughput * env->radiance(dir) * weight;
          }
          return;
        }
        ++stats.vertices;
        const Scene::GeometryRecord& rec = scene.record(raw.geomID);
        const Material* material = rec.material;
        const bool isDirac = rec.deltaLobes;
        const Vec3 origin = load3(paths.origin, s);
        const Vec3 wo = -dir;
        Vec3 p;
        float pError;
        SurfaceHit* hit = nullptr;
        if (isDirac) {
          // The whole record, for the material's sample(); and the medium the ray crossed.
          hit = &wave.diracHit[vertices];
          scene.surfaceHit(Ray{origin, dir}, raw, *hit);
          p = hit->p;
          pError = hit->pError;
          if (glm::dot(dir, raw.ng) > 0.0f) {
            throughput *= material->interiorTransmittance(raw.t);
            if (isBlack(throughput)) return;
          }
        } else {
          // Scene::surfaceHit for an analytic shape, without the parts a Lambertian vertex never
          // reads (the shading normal equals ng; texture coordinates only for the reflectance).
          // A Lambertian surface has no interior to attenuate.
          const Vec3 p0 = origin + raw.t * dir;
          const float magnitude = maxAbsComponent(p0);
          p = p0;
          if (raw.t > magnitude) {
            const SurfacePoint onSurface = rec.shape->projectToSurface(p0, LocalHit{raw.t, raw.ng, raw.uv});
            p = onSurface.p;
            pError = onSurface.error;
          } else {
            pError = roundingErrorBound(magnitude + raw.t);
          }
        }
        addEmission(rec, s, p, raw.ng, wo, throughput);
        if ((maxDepth >= 0 && paths.depth[s] >= maxDepth) || !material) return;
        const size_t v = vertices;
        if (isDirac) {
          if (material->absorbsAt(*hit)) return;
          wave.dirac[v] = material;
        } else {
          const auto* lambertian = static_cast<const Lambertian*>(material);
          const Color* constant = lambertian->constantReflectance();
          const Color albedo =
              constant ? *constant
                       : lambertian->reflectanceAt(rec.shape->surfaceUv(LocalHit{raw.t, raw.ng, raw.uv}));
          if (isBlack(albedo)) return;  // Material::absorbsAt: black only where the texture may be
          store3(nee.albedo, v, albedo);
          wave.dirac[v] = nullptr;
          if (!lights.empty()) wave.lightVertex[lightDraws++] = uint16_t(v);
        }
        wave.bsdfUse[v] = RequestUse{material->usesDirectionSample(), material->usesLobeSample()};
        ++vertices;
        store3(nee.p, v, p);
        store3(nee.ng, v, raw.ng);
        nee.pError[v] = pError;
        store3(nee.wo, v, wo);
        store3(nee.throughput, v, throughput);
        nee.lightPdf[v] = -1.0f;
        nee.pointLight[v] = 0;
        nee.infinite[v] = 0;
        cont.dirac[v] = isDirac ? -1 : 0;
        cont.sampledDelta[v] = 0;
        cont.etaProduct[v] = paths.etaProduct[s];
        cont.owner[v] = owner;
        cont.depth[v] = paths.depth[s];
        cont.firstBounceNonDelta[v] = paths.firstBounceNonDelta[s];
        cont.maskFront[v] = rec.maskFront;
        cont.maskBack[v] = rec.maskBack;
      };
      const HitFields hitFields = wave.closest.hitFields();
      for (size_t r = 0; r < wave.groups.runCount(); ++r) {
        const GeometryGroups::Run run = wave.groups.runs()[r];
        const uint16_t* slots = wave.groups.order() + run.begin;
        const size_t count = size_t(run.end - run.begin);
        const Color* albedo = run.geometry == RTC_INVALID_GEOMETRY_ID
                                  ? nullptr
                                  : constantLambertian(scene.record(run.geometry));
        if (maxDepth >= 0 || !albedo || isBlack(*albedo)) {
          for (size_t j = 0; j < count; ++j) arriveOne(slots[j]);
          continue;
        }
        // Every path of the run scatters at its vertex: the depth is unbounded and the
        // reflectance not black.
        const Scene::GeometryRecord& rec = scene.record(run.geometry);
        const size_t first = vertices;
        const size_t far = arriveLambertianLanes(
            hitFields, paths, LambertianRun{slots, count, first, *albedo, rec.maskFront, rec.maskBack}, nee,
            cont, wave.project.data());
        for (size_t j = 0; j < far; ++j) {  // the scalar arrival's projection branch
          const size_t v = size_t(wave.project[j]);
          RawHit raw;
          wave.closest.hit(slots[v - first], raw);
          const SurfacePoint onSurface =
              rec.shape->projectToSurface(load3(nee.p, v), LocalHit{raw.t, raw.ng, raw.uv});
          store3(nee.p, v, onSurface.p);
          nee.pError[v] = onSurface.error;
        }
        if (!isBlack(rec.emission))
          for (size_t j = 0; j < count; ++j) {
            const size_t v = first + j;
            addEmission(rec, slots[j], load3(nee.p, v), load3(nee.ng, v), load3(nee.wo, v),
                        load3(nee.throughput, v));
          }
        std::fill_n(&wave.dirac[first], count, nullptr);
        std::fill_n(&wave.bsdfUse[first], count,
                    RequestUse{rec.material->usesDirectionSample(), rec.material->usesLobeSample()});
        if (!lights.empty())
          for (size_t j = 0; j < count; ++j) wave.lightVertex[lightDraws++] = uint16_t(first + j);
        vertices += count;
        stats.vertices += count;
      }
      phases.mark(PathPhase::Arrival);

      // The light choice at the Lambertian vertices (pickLight: its 1D, then its 2D request) and
      // the lights' samples.
      for (size_t j = 0; j < lightDraws; ++j)
        wave.samplerOf[j] = &wave.samplers[size_t(cont.owner[wave.lightVertex[j]])];
      draw1DThen2DLanes(wave.samplerOf.data(), lightDraws, wave.drawn1D.data(), wave.drawn2D.data(),
                        lightUse);
      size_t queries = 0;
      for (size_t j = 0; j < lightDraws; ++j) {
        LightPick pick;
        if (!PathIntegrator::pickLightWith(scene, wave.drawn1D[j], wave.drawn2D[j], pick)) continue;
        const size_t v = wave.lightVertex[j];
        wave.light[v] = pick.light;
        nee.lightMask[v] = pick.light->shadowMask;
        wave.lightU[v] = pick.u;
        nee.pmf[v] = pick.pmf;
        wave.queryKey[queries++] = uint64_t(pick.light->samplerIndex) << 16 | v;
      }
      phases.mark(PathPhase::LightChoice);
      sampleLights(wave, queries, lights.size());
      phases.mark(PathPhase::LightSamples);

      const size_t shadowRays = nextEventLanes(nee, cont.maskFront, cont.maskBack, vertices);
      wave.shadows.assign(rowsOf(nee.shadowOrigin), rowsOf(nee.shadowDir), nee.shadowTMax, nee.shadowMask,
                          shadowRays);
      stats.shadowRays += shadowRays;
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

      // The BSDF samples (Lambertian::sample in blocks of the cosine kernel, a Dirac material's
      // own sample()) into the continuation's rows, then followBsdfSample for all vertices in one
      // kernel, which writes the paths that go on into the slots, and their rays as the next batch.
      for (size_t block = 0; block < vertices; block += CosineLanes::kMaxLanes) {
        const unsigned n = unsigned(std::min<size_t>(CosineLanes::kMaxLanes, vertices - block));
        for (unsigned i = 0; i < n; ++i) {
          const size_t v = block + i;
          const Vec3 ng = load3(nee.ng, v), wo = load3(nee.wo, v);
          wave.cosine.set(i, glm::dot(wo, ng) >= 0.0f ? ng : -ng, wave.drawn2D[v]);
        }
        sampleCosineLanes(wave.cosine, wave.cosine.padFrom(n));
        // Whole blocks, so that the continuation kernel's vector loads find whole stores.
        for (int c = 0; c < 3; ++c) std::copy_n(wave.cosine.wi[c], n, &cont.wi[c][block]);
        std::copy_n(wave.cosine.pdf, n, &cont.pdf[block]);
        for (unsigned i = 0; i < n; ++i) {
          const size_t v = block + i;
          const Material* material = wave.dirac[v];
          if (!material) continue;
          BsdfSample bs;
          const bool sampled =
              material->sample(wave.diracHit[v], load3(nee.wo, v), wave.drawn2D[v], wave.drawn1D[v], bs);
          cont.diracSampled[v] = sampled ? -1 : 0;
          if (!sampled) continue;
          store3(cont.wi, v, bs.wi);
          store3(cont.weight, v, bs.weight);
          cont.pdf[v] = bs.pdf;
          cont.eta[v] = bs.eta;
          cont.sampledDelta[v] = bs.delta ? -1 : 0;
        }
      }
      const size_t next = continuationLanes(nee, cont, vertices, rrDepth, paths);
      wave.closest.assign(rowsOf(paths.origin), rowsOf(paths.dir), paths.mask, next);
      phases.mark(PathPhase::Continuation);

      traceTimed(wave.shadows, scene.accel(), BatchTraversal::Packets, stats);
      for (size_t j = 0; j < wave.shadows.size(); ++j) {
        if (wave.shadows.occluded(j)) continue;
        const size_t v = size_t(nee.shadowVertex[j]);
        wave.radiance[size_t(cont.owner[v])] += load3(nee.contribution, v);
      }
      active = next;
      phases.mark(PathPhase::TraceShadows);
    }

    for (size_t i = 0; i < count; ++i)
      addToFilm(film, work, wave.x[i], wave.y[i], wave.sample[i], wave.radiance[i], stats);
    phases.mark(PathPhase::Camera);
  }
}

}  // namespace ember
