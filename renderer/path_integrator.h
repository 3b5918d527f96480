// Unidirectional path tracer with next-event estimation and multiple importance sampling, the
// estimator of Mitsuba 3's `path` integrator and PBRT4 section 13.4:
//  - at every non-specular vertex one light is chosen in proportion to its power and sampled
//    (LightSampler, Light::sample), and its contribution is weighted by the power heuristic against
//    the BSDF's density for the same direction (Veach 1997, eq. 9.13);
//  - the BSDF-sampled continuation adds emission it hits, weighted by the power heuristic against
//    the light-sampling density; after a Dirac lobe, or for a light that is never sampled, that
//    weight is 1; delta lights (point lights) are reached by light sampling alone.
//  - Russian roulette (Arvo & Kirk 1990) from segment `rrDepth` on: continue with probability
//    q = min(max_channel(throughput * eta^2), 0.95) and divide the throughput by q. The eta^2 undoes
//    the radiance scaling of refraction, so a path inside glass is not killed for it. Unbiased: a
//    surviving path is reweighted by exactly the inverse of its survival probability.
// maxDepth counts path segments (the camera ray is segment 1); -1 means unbounded.
#pragma once

#include "renderer/integrator.h"

namespace ember {

class PathIntegrator final : public Integrator {
 public:
  PathIntegrator(int maxDepth, int rrDepth) : maxDepth_(maxDepth), rrDepth_(rrDepth) {}
  Color Li(const Scene& scene, Ray ray, Sampler& sampler, PathStats& stats) const override;

 private:
  Color sampleLight(const Scene& scene, const SurfaceHit& hit, const Vec3& wo, Sampler& sampler,
                    PathStats& stats) const;

  int maxDepth_;
  int rrDepth_;
};

}  // namespace ember
