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
//
// The strategy (renderer/strategy.h) chooses how direct light is estimated. Each one is a choice of
// weights w_light + w_bsdf = 1 for every direction either technique can produce (Veach 1997,
// eq. 9.3), which is what keeps all three unbiased:
//  - mis:   both techniques, power-heuristic weights;
//  - bsdf:  w_bsdf = 1: no shadow rays; emitters (and the environment) count when paths hit them.
//           Delta lights cannot be hit, so they contribute nothing;
//  - light: w_light = 1 wherever light sampling can produce the direction (light pdf > 0); emission
//           found by BSDF sampling counts only where it cannot: after a Dirac lobe, from the
//           camera, or on an emitter the light sampler never picks.
#pragma once

#include "core/ray_spawn.h"
#include "renderer/integrator.h"
#include "renderer/strategy.h"

#include <string>

namespace ember {

// One path between two ray casts: the ray it casts next and what it has gathered so far.
struct PathState {
  Ray ray;
  Color radiance{0.0f};
  Color throughput{1.0f};
  float etaProduct = 1.0f;
  bool previousDelta = true;  // camera rays count as specular: emitters they see get weight 1
  float previousPdf = 0.0f;
  Vec3 previousPoint{0.0f};
  // The Embree mask of `ray`: SurfaceHit::maskFor of the surface it leaves, on its side.
  uint32_t rayMask = kAllRayMask;
  int depth = 1;                     // segments cast so far, counting the one in flight
  bool firstBounceNonDelta = false;  // the camera vertex scattered through a non-Dirac lobe
  // Where the sample's AOVs go (renderer/aov.h), for the one-path-at-a-time steps (Li, onHit,
  // scatter, onMiss); null when the render asks for none. The batched driver keeps its own.
  AovSample* aov = nullptr;
};

// Next-event estimation's shadow ray: if nothing blocks it, `contribution` (throughput included)
// is added to its path's radiance.
struct ShadowRequest {
  Ray ray;
  Color contribution;
  uint32_t mask = kAllRayMask;  // its Embree mask: the surface's (SurfaceHit) and the light's shadowMask
};

// The light next-event estimation chose at a vertex, with the random numbers for its sample.
struct LightPick {
  const Light* light = nullptr;
  float pmf = 0.0f;
  Vec2 u{0.0f};
};

class PathIntegrator final : public Integrator {
 public:
  // traceCaustics: leave the caustic paths of the scene's light tracer to it (render() runs it);
  // off, the path tracer estimates every path alone, as Li does for a caller outside render().
  PathIntegrator(int maxDepth, int rrDepth, Strategy strategy = Strategy::Mis, bool traceCaustics = false)
      : maxDepth_(maxDepth), rrDepth_(rrDepth), strategy_(strategy), traceCaustics_(traceCaustics) {}
  explicit PathIntegrator(const RenderSettings& s)
      : PathIntegrator(s.maxDepth, s.rrDepth, s.strategy, s.traceCaustics) {}

  bool tracesCaustics() const override { return traceCaustics_; }
  int maxDepth() const override { return maxDepth_; }
  int rrDepth() const override { return rrDepth_; }
  Strategy strategy() const { return strategy_; }

  // The scalar reference: casts each ray of the path alone, as soon as it is known.
  Color Li(const Scene& scene, Ray ray, Sampler& sampler, PathStats& stats) const override;
  Color LiWithAovs(const Scene& scene, Ray ray, Sampler& sampler, PathStats& stats,
                   AovSample& aov) const override;

  // The path as a state machine, for Li and for loops that cast the rays of many paths together
  // (packet/wave_integrator.h). Both call the same steps in the same order per path, so
  // they estimate the same value bit for bit.
  // A path starting with a camera ray; false if it can carry no light (max depth 0).
  bool start(const Ray& cameraRay, PathState& path) const;
  // The path's ray left the scene: adds the environment it sees. The path ends.
  void onMiss(const Scene& scene, PathState& path) const;
  // Whether onMiss can add anything at all: only an environment shines on a path that leaves.
  static bool missAddsLight(const Scene& scene) { return scene.environment() != nullptr; }
  // The path's ray found `hit`: adds its emission, asks for a shadow ray (returns true and fills
  // `shadow`) and samples the next ray into path.ray. `continues` says whether the path goes on.
  // The shadow ray's contribution must be added before the path's next step.
  bool onHit(const Scene& scene, PathState& path, const SurfaceHit& hit, Sampler& sampler, PathStats& stats,
             ShadowRequest& shadow, bool& continues) const;

  // Widens a filtered texture's footprint at `hit` (Scene::filteredTextures; otherwise nothing)
  // by the spread of the BSDF lobe the path left its previous vertex through. A lobe of
  // solid-angle density p covers about 1 / p steradians, a cone 2 / sqrt(pi p) radians wide,
  // which has spread that much per unit of the segment's length when it reaches `hit` (a
  // direction's spread sized from its pdf, as Suykens & Willems 2001's path differentials do for
  // sampled directions). Camera rays and Dirac lobes add nothing to the camera's own footprint
  // (Camera::footprintAt). So a footprint grows with distance and with roughness. The drivers call
  // it on every hit before onHit or arrive.
  static void widenFootprint(const Scene& scene, const PathState& path, SurfaceHit& hit) {
    if (scene.filteredTextures) widenFilteredFootprint(scene, path, hit);
  }
  // onHit in its steps, for loops that sample the lights of many vertices together
  // (Light::sampleLanes): arrive, then pickLight, the light's sample, shadowFor, and scatter.
  // Emission and absorption on arrival; false if the path ends here without scattering.
  bool arrive(const Scene& scene, PathState& path, const SurfaceHit& hit, PathStats& stats) const;
  // Chooses the light to sample and draws its random numbers; false if the vertex samples none.
  // In steps: whether the vertex samples a light at all (then it draws a 1D and a 2D request),
  // and the choice from those numbers.
  bool pickLight(const Scene& scene, const SurfaceHit& hit, Sampler& sampler, LightPick& pick) const;
  bool samplesLights(const Scene& scene, const SurfaceHit& hit) const;
  static bool pickLightWith(const Scene& scene, float uPick, Vec2 u, LightPick& pick);
  // The shadow ray for the light's sample `ls` (valid when `sampled`); false if there is none.
  bool shadowFor(const SurfaceHit& hit, const PathState& path, const LightPick& pick, const LightSample& ls,
                 bool sampled, PathStats& stats, ShadowRequest& shadow) const;
  // Samples the path's next ray and applies Russian roulette; false if the path ends. In steps:
  // the BSDF's random numbers, the material's sample (Material::sample, or sampleLanes for many
  // vertices), then followBsdfSample.
  bool scatter(PathState& path, const SurfaceHit& hit, Sampler& sampler) const;
  static void drawBsdfSample(Sampler& sampler, Vec2& u, float& uLobe) {
    u = sampler.get2D();
    uLobe = sampler.get1D();
  }
  bool followBsdfSample(PathState& path, const SurfaceHit& hit, const BsdfSample& bs, bool sampled,
                        Sampler& sampler) const;

  // The AOVs' steps (docs/aovs.md), taken by both drivers at the same points of a path:
  //  - on arrival at a hit, after arrive() (`scatters` is what it returned): the camera ray's hit
  //    gives depth, position and uv; the first vertex with a non-Dirac lobe (or no material, or
  //    where a Dirac chain ends) gives the normal, and the albedo is then the chain's weight (the
  //    throughput so far, clamped to [0, 1]) times that vertex's;
  //  - on the BSDF sample there: the vertex's albedo is the sample's weight f |cos| / pdf, clamped
  //    to [0, 1] (0 when nothing was sampled): its directional albedo's one-sample estimate, which
  //    the film's mean makes the albedo itself (for a Lambertian surface, the reflectance exactly);
  //  - on a miss before that vertex: no normal, and the environment's radiance (clamped) times the
  //    chain's weight as albedo;
  //  - where the path ends at that vertex (an emitter without a material, the depth limit, a black
  //    texel), the albedo is settled on arrival.
  static void aovOnArrival(const PathState& path, const SurfaceHit& hit, bool scatters, AovSample& aov);
  static void aovOnSample(bool sampled, const Color& weight, AovSample& aov);
  static void aovOnMiss(const Scene& scene, const PathState& path, AovSample& aov);

 private:
  // Weight of emission that a BSDF-sampled direction (density bsdfPdf) found, where light sampling
  // would have produced it with density lightPdf.
  float emissionWeight(float bsdfPdf, float lightPdf) const;
  // Li's loop, from a started path.
  Color trace(const Scene& scene, PathState& path, Sampler& sampler, PathStats& stats) const;

  int maxDepth_;
  int rrDepth_;
  Strategy strategy_;
  static void widenFilteredFootprint(const Scene& scene, const PathState& path, SurfaceHit& hit);

  bool traceCaustics_;
};

// The warning to print when `strategy` cannot reach some of a built scene's lights (bsdf and its
// point, spot and directional lights), or an empty string.
std::string unreachableLightsWarning(const Scene& scene, Strategy strategy);

}  // namespace ember
