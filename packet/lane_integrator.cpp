#include "packet/lane_integrator.h"

#include "core/sampling.h"
#include "core/warp_lanes.h"
#include "materials/lambertian.h"
#include "materials/specular.h"
#include "packet/next_event_lanes.h"
#include "packet/thread_wave.h"
#include "packet/timed_trace.h"
#include "renderer/sampler_lanes.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <memory>
#include <vector>

namespace ember {

namespace {

// One thread's wave, allocated on its first tile and reused: the bounce allocates nothing.
// Three index spaces: camera samples (i, the wave's lanes), paths in flight (slot s, compacted
// after every bounce) and the bounce's scattering vertices (v, in slot order).
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
  Row<uint16_t> owner;
  Row<Vec3> origin, dir, throughput, previousPoint;
  Row<float> previousPdf;
  Row<bool> previousDelta;
  Row<int> depth;
  Row<float> etaProduct;
  Row<bool> firstBounceNonDelta;
  // Vertices: NextEventArrays holds their points, normals, errors, directions back, reflectances
  // and throughputs beside their light samples; here the rest.
  NextEventArrays nee;
  Row<uint16_t> vertexOwner;
  Row<int> vertexDepth;
  Row<float> vertexEta;
  Row<bool> vertexFirstNonDelta;
  // A Dirac vertex's material (mirror, glass: no light sample) and its full hit record, which the
  // material's scalar sample() reads; null for a Lambertian vertex.
  Row<const Material*> dirac;
  Row<SurfaceHit> diracHit;
  Row<uint32_t> maskFront, maskBack;
  Row<const Light*> light;
  Row<Vec2> lightU;           // the light sample's numbers
  Row<uint16_t> lightVertex;  // the vertices that sample a light
  // Light queries (q), sorted by light where that makes runs: samplerIndex << 16 | vertex.
  Row<uint64_t> queryKey;
  // Sampler requests drawn together (renderer/sampler_lanes.h).
  Row<Sampler*> samplerOf;
  Row<float> drawn1D;
  Row<Vec2> drawn2D;
  Row<RequestUse> bsdfUse;
  CosineLanes cosine;
  Row<uint16_t> shadowVertex;
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

// AreaLight::sampleLanes for the vertices `keys` name (their low 16 bits), read from and written
// to the next-event arrays; a vertex without a sample keeps lightPdf -1.
void sampleAreaLight(const AreaLight& light, const uint64_t* keys, size_t n, NextEventArrays& nee,
                     const Vec2* lightU) {
  light.sampleBlocks(
      n, [&](size_t q) { return load3(nee.p, keys[q] & 0xffffu); },
      [&](size_t q) { return lightU[keys[q] & 0xffffu]; },
      [&](size_t q, const LightSample& ls) { storeSample(nee, keys[q] & 0xffffu, ls); });
}

// Samples every vertex's chosen light, one run of queries per light (sorted by light where that
// makes runs; PathIntegrator's light sample), into the next-event arrays; a vertex without a
// sample keeps lightPdf -1.
void sampleLights(LaneWave& wave, size_t queries, size_t lights) {
  const auto keys = wave.queryKey.begin(), keysEnd = keys + ptrdiff_t(queries);
  if (lights <= LaneWave::kSize / SolidAngleLanes::kMaxLanes && !std::is_sorted(keys, keysEnd))
    std::sort(keys, keysEnd);
  for (size_t first = 0; first < queries;) {
    const Light* light = wave.light[wave.queryKey[first] & 0xffffu];
    size_t end = first + 1;
    while (end < queries && (wave.queryKey[end] >> 16) == (wave.queryKey[first] >> 16)) ++end;
    if (const auto* area = dynamic_cast<const AreaLight*>(light)) {
      sampleAreaLight(*area, &wave.queryKey[first], end - first, wave.nee, wave.lightU.data());
    } else if (const auto* point = dynamic_cast<const PointLight*>(light)) {
      for (size_t q = first; q < end; ++q) {  // the next-event kernel takes the sample
        const size_t v = wave.queryKey[q] & 0xffffu;
        store3(wave.nee.lightP, v, point->position());
        store3(wave.nee.lightLi, v, point->intensity());
        store3(wave.nee.lightN, v, Vec3(0.0f));
        wave.nee.lightPError[v] = 0.0f;
        wave.nee.pointLight[v] = -1;
      }
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
    size_t active = 0;
    wave.closest.clear();
    for (size_t i = 0; i < count; ++i) {
      wave.radiance[i] = Color(0.0f);
      if (maxDepth == 0) continue;
      const Ray ray = cameraRay(scene, wave.x[i], wave.y[i], wave.drawn2D[i]);
      wave.owner[active] = uint16_t(i);
      wave.origin[active] = ray.origin;
      wave.dir[active] = ray.dir;
      wave.throughput[active] = Color(1.0f);
      wave.previousPoint[active] = ray.origin;
      wave.previousPdf[active] = 0.0f;
      wave.previousDelta[active] = true;
      wave.depth[active] = 1;
      wave.etaProduct[active] = 1.0f;
      wave.firstBounceNonDelta[active] = false;
      ++active;
      wave.closest.push(ray);
    }

    phases.mark(PathPhase::Camera);
    while (active > 0) {
      stats.rays += active;
      traceTimed(wave.closest, scene.accel(), BatchTraversal::Packets, stats);
      phases.mark(PathPhase::TraceClosest);

      // PathIntegrator::arrive for every path: its emission (no environment in the scenes
      // covered: a miss ends the path), and the vertices that scatter.
      wave.groups.group(wave.closest, active, scene.geometryCount());
      size_t vertices = 0, lightDraws = 0;
      for (size_t o = 0; o < active; ++o) {
        const size_t s = wave.groups.order()[o];
        RawHit raw;
        if (!wave.closest.hit(s, raw)) {
          // PathIntegrator::onMiss: the environment the ray sees, if any; the path ends.
          if (const EnvironmentLight* env = scene.environment()) {
            float weight = 1.0f;
            if (!wave.previousDelta[s])
              weight = powerHeuristic(wave.previousPdf[s], lights.pmf(env) * env->pdfDirection(wave.dir[s]));
            wave.radiance[wave.owner[s]] += wave.throughput[s] * env->radiance(wave.dir[s]) * weight;
          }
          continue;
        }
        ++stats.vertices;
        const Scene::GeometryRecord& rec = scene.record(raw.geomID);
        const Material* material = rec.material;
        const bool isDirac = rec.deltaLobes;
        const Vec3 wo = -wave.dir[s];
        const uint16_t owner = wave.owner[s];
        Vec3 p;
        float pError;
        SurfaceHit* hit = nullptr;
        if (isDirac) {
          // The whole record, for the material's sample(); and the medium the ray crossed.
          hit = &wave.diracHit[vertices];
          scene.surfaceHit(Ray{wave.origin[s], wave.dir[s]}, raw, *hit);
          p = hit->p;
          pError = hit->pError;
          if (glm::dot(wave.dir[s], raw.ng) > 0.0f) {
            wave.throughput[s] *= material->interiorTransmittance(raw.t);
            if (isBlack(wave.throughput[s])) continue;
          }
        } else {
          // Scene::surfaceHit for an analytic shape, without the parts a Lambertian vertex never
          // reads (the shading normal equals ng; texture coordinates only for the reflectance).
          // A Lambertian surface has no interior to attenuate.
          const Vec3 p0 = wave.origin[s] + raw.t * wave.dir[s];
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
        // PathIntegrator::arrive's emission; a caustic path's is the light tracer's.
        const bool caustic = tracesCaustics && wave.previousDelta[s] && wave.firstBounceNonDelta[s] &&
                             rec.light && rec.light->causticTraced;
        if (!isBlack(rec.emission) && (rec.twoSidedEmission || glm::dot(wo, raw.ng) > 0.0f) && !caustic) {
          float weight = 1.0f;
          if (!wave.previousDelta[s]) {
            const float lightPdf =
                rec.light ? lights.pmf(rec.light) * rec.light->pdf(wave.previousPoint[s], p, raw.ng) : 0.0f;
            weight = powerHeuristic(wave.previousPdf[s], lightPdf);
          }
          wave.radiance[owner] += wave.throughput[s] * rec.emission * weight;
        }
        if ((maxDepth >= 0 && wave.depth[s] >= maxDepth) || !material) continue;
        const size_t v = vertices;
        if (isDirac) {
          if (material->absorbsAt(*hit)) continue;
          wave.dirac[v] = material;
        } else {
          const auto* lambertian = static_cast<const Lambertian*>(material);
          const Color* constant = lambertian->constantReflectance();
          const Color albedo =
              constant ? *constant
                       : lambertian->reflectanceAt(rec.shape->surfaceUv(LocalHit{raw.t, raw.ng, raw.uv}));
          if (isBlack(albedo)) continue;  // Material::absorbsAt: black only where the texture may be
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
        store3(nee.throughput, v, wave.throughput[s]);
        nee.lightPdf[v] = -1.0f;
        nee.pointLight[v] = 0;
        nee.infinite[v] = 0;
        wave.vertexOwner[v] = owner;
        wave.vertexDepth[v] = wave.depth[s];
        wave.vertexEta[v] = wave.etaProduct[s];
        wave.vertexFirstNonDelta[v] = wave.firstBounceNonDelta[s];
        wave.maskFront[v] = rec.maskFront;
        wave.maskBack[v] = rec.maskBack;
      }
      phases.mark(PathPhase::Arrival);

      // The light choice at the Lambertian vertices (pickLight: its 1D, then its 2D request) and
      // the lights' samples.
      for (size_t j = 0; j < lightDraws; ++j)
        wave.samplerOf[j] = &wave.samplers[wave.vertexOwner[wave.lightVertex[j]]];
      draw1DThen2DLanes(wave.samplerOf.data(), lightDraws, wave.drawn1D.data(), wave.drawn2D.data(),
                        lightUse);
      size_t queries = 0;
      for (size_t j = 0; j < lightDraws; ++j) {
        LightPick pick;
        if (!PathIntegrator::pickLightWith(scene, wave.drawn1D[j], wave.drawn2D[j], pick)) continue;
        const size_t v = wave.lightVertex[j];
        wave.light[v] = pick.light;
        wave.lightU[v] = pick.u;
        nee.pmf[v] = pick.pmf;
        wave.queryKey[queries++] = uint64_t(pick.light->samplerIndex) << 16 | v;
      }
      phases.mark(PathPhase::LightChoice);
      sampleLights(wave, queries, lights.size());
      phases.mark(PathPhase::LightSamples);

      nextEventLanes(nee, vertices);
      wave.shadows.clear();
      for (size_t v = 0; v < vertices; ++v) {
        if (!nee.shadow[v]) continue;
        const Ray ray{load3(nee.origin, v), load3(nee.dir, v), nee.tMax[v]};
        const uint32_t surface =
            nee.clear[v] ? (nee.front[v] ? wave.maskFront[v] : wave.maskBack[v]) : kAllRayMask;
        wave.shadowVertex[wave.shadows.size()] = uint16_t(v);
        wave.shadows.push(ray, surface & wave.light[v]->shadowMask);
        ++stats.shadowRays;
      }
      phases.mark(PathPhase::NextEvent);

      // PathIntegrator::drawBsdfSample: its 2D, then its 1D request.
      for (size_t v = 0; v < vertices; ++v) wave.samplerOf[v] = &wave.samplers[wave.vertexOwner[v]];
      draw2DThen1DLanes(wave.samplerOf.data(), vertices, wave.drawn2D.data(), wave.drawn1D.data(),
                        wave.bsdfUse.data());
      phases.mark(PathPhase::BsdfSamples);

      // The BSDF samples (Lambertian::sample in blocks of the cosine kernel, a Dirac material's
      // own sample()), then followBsdfSample: the next ray, Russian roulette, and the survivors
      // compacted into the slots.
      wave.closest.clear();  // its hits are all read
      size_t next = 0;
      for (size_t block = 0; block < vertices; block += CosineLanes::kMaxLanes) {
        const unsigned n = unsigned(std::min<size_t>(CosineLanes::kMaxLanes, vertices - block));
        for (unsigned i = 0; i < n; ++i) {
          const size_t v = block + i;
          const Vec3 ng = load3(nee.ng, v), wo = load3(nee.wo, v);
          wave.cosine.set(i, glm::dot(wo, ng) >= 0.0f ? ng : -ng, wave.drawn2D[v]);
        }
        sampleCosineLanes(wave.cosine, wave.cosine.padFrom(n));
        for (unsigned i = 0; i < n; ++i) {
          const size_t v = block + i;
          const Vec3 ng = load3(nee.ng, v), wo = load3(nee.wo, v);
          BsdfSample bs;
          if (const Material* material = wave.dirac[v]) {
            if (!material->sample(wave.diracHit[v], wo, wave.drawn2D[v], wave.drawn1D[v], bs)) continue;
          } else {
            bs.wi = wave.cosine.direction(i);
            bs.pdf = wave.cosine.pdf[i];
            if (bs.pdf <= 0.0f || !(glm::dot(wo, ng) * glm::dot(bs.wi, ng) > 0.0f)) continue;
            bs.weight = load3(nee.albedo, v);
          }
          Color throughput = load3(nee.throughput, v) * bs.weight;
          if (isBlack(throughput)) continue;
          const Vec3 p = load3(nee.p, v);
          const bool front = frontSide(ng, bs.wi);
          const int depth = wave.vertexDepth[v];
          const float eta = wave.vertexEta[v] * bs.eta;
          if (depth >= rrDepth) {
            const float q = std::min(maxComponent(throughput) * eta * eta, 0.95f);
            if (wave.samplers[wave.vertexOwner[v]].get1D() >= q) continue;
            throughput /= q;
          }
          const Ray ray{offsetAlongNormal(p, ng, nee.pError[v], front), bs.wi};
          wave.owner[next] = wave.vertexOwner[v];
          wave.origin[next] = ray.origin;
          wave.dir[next] = bs.wi;
          wave.throughput[next] = throughput;
          wave.previousPoint[next] = p;
          wave.previousPdf[next] = bs.pdf;
          wave.previousDelta[next] = bs.delta;
          wave.depth[next] = depth + 1;
          wave.etaProduct[next] = eta;
          wave.firstBounceNonDelta[next] = depth == 1 ? !bs.delta : wave.vertexFirstNonDelta[v];
          ++next;
          wave.closest.push(ray, front ? wave.maskFront[v] : wave.maskBack[v]);
        }
      }
      phases.mark(PathPhase::Continuation);

      traceTimed(wave.shadows, scene.accel(), BatchTraversal::Packets, stats);
      for (size_t j = 0; j < wave.shadows.size(); ++j) {
        if (wave.shadows.occluded(j)) continue;
        const size_t v = wave.shadowVertex[j];
        wave.radiance[wave.vertexOwner[v]] += load3(nee.contribution, v);
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
