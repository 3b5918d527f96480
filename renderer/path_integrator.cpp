#include "renderer/path_integrator.h"

#include "core/sampling.h"

namespace ember {

bool PathIntegrator::samplesLights(const Scene& scene, const SurfaceHit& hit) const {
  return strategy_ != Strategy::Bsdf && hit.material->hasNonDeltaLobes() && !scene.lightSampler().empty();
}

bool PathIntegrator::pickLightWith(const Scene& scene, float uPick, Vec2 u, LightPick& pick) {
  pick.light = scene.lightSampler().sample(uPick, pick.pmf);
  pick.u = u;
  return pick.light != nullptr;
}

bool PathIntegrator::pickLight(const Scene& scene, const SurfaceHit& hit, Sampler& sampler,
                               LightPick& pick) const {
  if (!samplesLights(scene, hit)) return false;
  const float uPick = sampler.get1D();
  return pickLightWith(scene, uPick, sampler.get2D(), pick);
}

bool PathIntegrator::shadowFor(const SurfaceHit& hit, const PathState& path, const LightPick& pick,
                               const LightSample& ls, bool sampled, PathStats& stats,
                               ShadowRequest& shadow) const {
  if (!sampled || ls.pdf <= 0.0f || isBlack(ls.Li)) return false;
  float bsdfPdf = 0.0f;
  const Vec3 wo = -path.ray.dir;
  const Color f = hit.material->evalPdf(hit, wo, ls.wi, bsdfPdf);
  if (isBlack(f)) return false;

  // Lights at a finite distance: a segment between the two points that neither surface blocks.
  const bool finite = std::isfinite(ls.dist);
  const bool front = frontSide(hit.ng, finite ? ls.p - hit.p : ls.wi);
  const Ray ray = finite ? spawnRayTo(hit.p, hit.ng, hit.pError, ls.p, ls.n, ls.pError, front)
                         : Ray{hit.offsetOrigin(front), ls.wi, kInfinity};
  // Field by field: copied whole, GCC built the Ray in a temporary with narrow stores and moved it
  // with wide loads, which waited on those stores (`perf annotate`: a quarter of this function).
  static_assert(sizeof(Ray) == 2 * sizeof(Vec3) + sizeof(float), "copy every field of Ray");
  shadow.ray.origin = ray.origin;
  shadow.ray.dir = ray.dir;
  shadow.ray.tMax = ray.tMax;
  const float lightPdf = pick.pmf * ls.pdf;
  const float weight = ls.delta || strategy_ == Strategy::Light ? 1.0f : powerHeuristic(lightPdf, bsdfPdf);
  shadow.contribution = path.throughput * (f * ls.Li * (weight / lightPdf));
  shadow.mask =
      (finite ? hit.maskToward(ls.p, ls.pError, front) : hit.maskFor(front)) & pick.light->shadowMask;
  ++stats.shadowRays;
  return true;
}

float PathIntegrator::emissionWeight(float bsdfPdf, float lightPdf) const {
  switch (strategy_) {
    case Strategy::Bsdf:
      return 1.0f;
    case Strategy::Light:
      return lightPdf > 0.0f ? 0.0f : 1.0f;
    case Strategy::Mis:
      break;
  }
  return powerHeuristic(bsdfPdf, lightPdf);
}

bool PathIntegrator::start(const Ray& cameraRay, PathState& path) const {
  path = PathState{};
  path.ray = cameraRay;
  path.previousPoint = cameraRay.origin;
  return maxDepth_ != 0;  // paths of zero segments carry no light (as in Mitsuba)
}

void PathIntegrator::onMiss(const Scene& scene, PathState& path) const {
  if (path.aov) aovOnMiss(scene, path, *path.aov);
  if (const EnvironmentLight* env = scene.environment()) {
    float weight = 1.0f;
    if (!path.previousDelta)
      weight =
          emissionWeight(path.previousPdf, scene.lightSampler().pmf(env) * env->pdfDirection(path.ray.dir));
    path.radiance += path.throughput * env->radiance(path.ray.dir) * weight;
  }
}

void PathIntegrator::widenFilteredFootprint(const Scene& scene, const PathState& path, SurfaceHit& hit) {
  if (path.previousDelta || !(path.previousPdf > 0.0f) || !(hit.uvFootprint > 0.0f)) return;
  const float camera = scene.camera().footprintAt(hit.p, hit.ng);
  if (!(camera > 0.0f)) return;
  const float spread = 2.0f / std::sqrt(kPi * path.previousPdf);
  const float cosine = std::abs(glm::dot(path.ray.dir, hit.ng));
  // The cone's width at the hit, seen obliquely as the camera's footprint is (1 / sqrt|cos|).
  const float width = spread * hit.t / std::sqrt(std::max(cosine, 1e-3f));
  hit.uvFootprint *= (camera + width) / camera;
}

bool PathIntegrator::onHit(const Scene& scene, PathState& path, const SurfaceHit& hit, Sampler& sampler,
                           PathStats& stats, ShadowRequest& shadow, bool& continues) const {
  continues = false;
  const bool scatters = arrive(scene, path, hit, stats);
  if (path.aov) aovOnArrival(path, hit, scatters, *path.aov);
  if (!scatters) return false;
  LightPick pick;
  bool hasShadow = false;
  if (pickLight(scene, hit, sampler, pick)) {
    LightSample ls;
    const bool sampled = pick.light->sample(hit.p, pick.u, ls);
    hasShadow = shadowFor(hit, path, pick, ls, sampled, stats, shadow);
  }
  continues = scatter(path, hit, sampler);
  return hasShadow;
}

bool PathIntegrator::arrive(const Scene& scene, PathState& path, const SurfaceHit& hit,
                            PathStats& stats) const {
  ++stats.vertices;
  const Ray& ray = path.ray;
  const Vec3 wo = -ray.dir;
  if (hit.material && glm::dot(ray.dir, hit.ng) > 0.0f) {
    path.throughput *= hit.material->interiorTransmittance(hit.t);
    if (isBlack(path.throughput)) return false;
  }

  if (!isBlack(hit.emission)) {  // most vertices emit nothing: then there is nothing to weigh
    const Color emitted = hit.emitted(wo);
    // Emission after a Dirac bounce, on a path whose first bounce was not one, is a caustic the
    // light tracer estimates (renderer/caustic_tracer.h): counting it here too would count it twice.
    const bool caustic = traceCaustics_ && path.previousDelta && path.firstBounceNonDelta && hit.light &&
                         hit.light->causticTraced;
    if (!isBlack(emitted) && !caustic) {
      float weight = 1.0f;
      if (!path.previousDelta) {
        const LightSampler& lights = scene.lightSampler();
        const float lightPdf =
            hit.light ? lights.pmf(hit.light) * hit.light->pdf(path.previousPoint, hit.p, hit.ng) : 0.0f;
        weight = emissionWeight(path.previousPdf, lightPdf);
      }
      path.radiance += path.throughput * emitted * weight;
    }
  }

  return !(maxDepth_ >= 0 && path.depth >= maxDepth_) && hit.material && !hit.material->absorbsAt(hit);
}

bool PathIntegrator::scatter(PathState& path, const SurfaceHit& hit, Sampler& sampler) const {
  Vec2 u;
  float uLobe;
  drawBsdfSample(sampler, u, uLobe);
  BsdfSample bs;
  const bool sampled = hit.material->sample(hit, -path.ray.dir, u, uLobe, bs);
  if (path.aov) aovOnSample(sampled, bs.weight, *path.aov);
  return followBsdfSample(path, hit, bs, sampled, sampler);
}

bool PathIntegrator::followBsdfSample(PathState& path, const SurfaceHit& hit, const BsdfSample& bs,
                                      bool sampled, Sampler& sampler) const {
  if (!sampled) return false;
  path.throughput *= bs.weight;
  if (isBlack(path.throughput)) return false;
  path.previousDelta = bs.delta;
  path.previousPdf = bs.pdf;
  path.previousPoint = hit.p;
  if (path.depth == 1) path.firstBounceNonDelta = !bs.delta;
  path.etaProduct *= bs.eta;
  const bool front = frontSide(hit.ng, bs.wi);
  path.ray = Ray{hit.offsetOrigin(front), bs.wi};
  path.rayMask = hit.maskFor(front);

  if (path.depth >= rrDepth_) {
    const float q = std::min(maxComponent(path.throughput) * path.etaProduct * path.etaProduct, 0.95f);
    if (sampler.get1D() >= q) return false;
    path.throughput /= q;
  }
  ++path.depth;
  return true;
}

namespace {

Color clamp01(const Color& c) {
  return glm::clamp(c, Color(0.0f), Color(1.0f));
}

}  // namespace

void PathIntegrator::aovOnArrival(const PathState& path, const SurfaceHit& hit, bool scatters,
                                  AovSample& aov) {
  if (path.depth == 1) {
    aov.hit = true;
    aov.position = hit.p;
    aov.depth = glm::length(hit.p - path.ray.origin);
    aov.uv = hit.uv;
  }
  if (aov.surfaceFound) return;
  // A Dirac-only surface is followed through to what it shows.
  if (scatters && !hit.material->hasNonDeltaLobes()) return;
  const Vec3 wo = -path.ray.dir;
  aov.surfaceFound = true;
  aov.normal = hit.material ? facingNormal(hit, wo) : (glm::dot(wo, hit.ng) >= 0.0f ? hit.ng : -hit.ng);
  aov.albedo = clamp01(path.throughput);
  if (scatters) return;  // the BSDF sample gives the rest (aovOnSample)
  aov.albedoKnown = true;
  // A surface without a material is an emitter alone: its colour stands for its albedo.
  if (!hit.material) {
    aov.albedo *= clamp01(hit.emitted(wo));
    return;
  }
  // A vertex where the path ends at the depth limit (it would scatter otherwise) still has an
  // albedo: one BSDF sample at fixed numbers gives it (the reflectance exactly for a Lambertian
  // surface), so that --max-depth 1 leaves the denoiser its guide. One that absorbs has none.
  BsdfSample bs;
  const bool sampled = !hit.material->absorbsAt(hit) && hit.material->hasNonDeltaLobes() &&
                       hit.material->sample(hit, wo, Vec2(0.5f), 0.5f, bs);
  aov.albedo = sampled ? aov.albedo * clamp01(bs.weight) : Color(0.0f);
}

void PathIntegrator::aovOnSample(bool sampled, const Color& weight, AovSample& aov) {
  if (!aov.surfaceFound || aov.albedoKnown) return;
  aov.albedo = sampled ? aov.albedo * clamp01(weight) : Color(0.0f);
  aov.albedoKnown = true;
}

void PathIntegrator::aovOnMiss(const Scene& scene, const PathState& path, AovSample& aov) {
  if (aov.surfaceFound) return;
  aov.surfaceFound = aov.albedoKnown = true;
  const EnvironmentLight* env = scene.environment();
  aov.albedo = env ? clamp01(path.throughput) * clamp01(env->radiance(path.ray.dir)) : Color(0.0f);
}

Color PathIntegrator::LiWithAovs(const Scene& scene, Ray ray, Sampler& sampler, PathStats& stats,
                                 AovSample& aov) const {
  PathState path;
  if (!start(ray, path)) return path.radiance;
  path.aov = &aov;
  return trace(scene, path, sampler, stats);
}

Color PathIntegrator::Li(const Scene& scene, Ray ray, Sampler& sampler, PathStats& stats) const {
  PathState path;
  if (!start(ray, path)) return path.radiance;
  return trace(scene, path, sampler, stats);
}

Color PathIntegrator::trace(const Scene& scene, PathState& path, Sampler& sampler, PathStats& stats) const {
  for (;;) {
    SurfaceHit hit;
    ++stats.rays;
    if (!scene.intersect(path.ray, hit, path.rayMask)) {
      onMiss(scene, path);
      break;
    }
    widenFootprint(scene, path, hit);
    ShadowRequest shadow;
    bool continues;
    if (onHit(scene, path, hit, sampler, stats, shadow, continues) &&
        !scene.occluded(shadow.ray, shadow.mask))
      path.radiance += shadow.contribution;
    if (!continues) break;
  }
  return path.radiance;
}

std::string unreachableLightsWarning(const Scene& scene, Strategy strategy) {
  const size_t delta = scene.lightSampler().deltaLightCount();
  if (strategy != Strategy::Bsdf || delta == 0) return "";
  return "strategy bsdf cannot reach the scene's " + std::to_string(delta) +
         " point, spot or directional light(s); they contribute nothing";
}

}  // namespace ember
