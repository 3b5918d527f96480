#include "renderer/path_integrator.h"

#include "core/sampling.h"

namespace ember {

Color PathIntegrator::sampleLight(const Scene& scene, const SurfaceHit& hit, const Vec3& wo, Sampler& sampler,
                                  PathStats& stats) const {
  float pick;
  const Light* light = scene.lightSampler().sample(sampler.get1D(), pick);
  const Vec2 u = sampler.get2D();
  LightSample ls;
  if (!light || !light->sample(hit.p, u, ls) || ls.pdf <= 0.0f || isBlack(ls.Li)) return Color(0.0f);
  float bsdfPdf = 0.0f;
  const Color f = hit.material->evalPdf(hit, wo, ls.wi, bsdfPdf);
  if (isBlack(f)) return Color(0.0f);

  // Lights at a finite distance: a segment between the two points that neither surface blocks.
  const Ray shadow = std::isfinite(ls.dist) ? spawnRayTo(hit.p, hit.ng, hit.pError, ls.p, ls.n, ls.pError)
                                            : Ray{hit.offsetOrigin(ls.wi), ls.wi, kInfinity};
  ++stats.shadowRays;
  if (scene.occluded(shadow)) return Color(0.0f);

  const float lightPdf = pick * ls.pdf;
  const float weight = ls.delta || strategy_ == Strategy::Light ? 1.0f : powerHeuristic(lightPdf, bsdfPdf);
  return f * ls.Li * (weight / lightPdf);
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

Color PathIntegrator::Li(const Scene& scene, Ray ray, Sampler& sampler, PathStats& stats) const {
  Color radiance(0.0f);
  Color throughput(1.0f);
  float etaProduct = 1.0f;
  bool previousDelta = true;  // camera rays count as specular: emitters they see get weight 1
  float previousPdf = 0.0f;
  Vec3 previousPoint = ray.origin;
  const LightSampler& lights = scene.lightSampler();
  if (maxDepth_ == 0) return radiance;  // paths of zero segments carry no light (as in Mitsuba)

  for (int depth = 1;; ++depth) {
    SurfaceHit hit;
    ++stats.rays;
    if (!scene.intersect(ray, hit)) {
      if (const EnvironmentLight* env = scene.environment()) {
        float weight = 1.0f;
        if (!previousDelta)
          weight = emissionWeight(previousPdf, lights.pmf(env) * env->pdfDirection(ray.dir));
        radiance += throughput * env->radiance(ray.dir) * weight;
      }
      break;
    }
    ++stats.vertices;
    const Vec3 wo = -ray.dir;
    if (hit.material && glm::dot(ray.dir, hit.ng) > 0.0f) {
      throughput *= hit.material->interiorTransmittance(hit.t);
      if (isBlack(throughput)) break;
    }

    const Color emitted = hit.emitted(wo);
    if (!isBlack(emitted)) {
      float weight = 1.0f;
      if (!previousDelta) {
        const float lightPdf =
            hit.light ? lights.pmf(hit.light) * hit.light->pdf(previousPoint, hit.p, hit.ng) : 0.0f;
        weight = emissionWeight(previousPdf, lightPdf);
      }
      radiance += throughput * emitted * weight;
    }

    if ((maxDepth_ >= 0 && depth >= maxDepth_) || !hit.material) break;

    if (strategy_ != Strategy::Bsdf && hit.material->hasNonDeltaLobes() && !lights.empty())
      radiance += throughput * sampleLight(scene, hit, wo, sampler, stats);

    BsdfSample bs;
    const Vec2 u = sampler.get2D();
    if (!hit.material->sample(hit, wo, u, sampler.get1D(), bs)) break;
    throughput *= bs.weight;
    if (isBlack(throughput)) break;
    previousDelta = bs.delta;
    previousPdf = bs.pdf;
    previousPoint = hit.p;
    etaProduct *= bs.eta;
    ray = Ray{hit.offsetOrigin(bs.wi), bs.wi};

    if (depth >= rrDepth_) {
      const float q = std::min(maxComponent(throughput) * etaProduct * etaProduct, 0.95f);
      if (sampler.get1D() >= q) break;
      throughput /= q;
    }
  }
  return radiance;
}

std::string unreachableLightsWarning(const Scene& scene, Strategy strategy) {
  const size_t delta = scene.lightSampler().deltaLightCount();
  if (strategy != Strategy::Bsdf || delta == 0) return "";
  return "strategy bsdf cannot reach the scene's " + std::to_string(delta) +
         " point, spot or directional light(s); they contribute nothing";
}

}  // namespace ember
