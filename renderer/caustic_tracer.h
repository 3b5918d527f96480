// Caustics by light tracing. A caustic is light that leaves an emitter, meets a mirror or glass
// surface (a Dirac lobe) and then lights a diffuse or glossy surface the camera sees. A path
// tracer finds such a path only when a BSDF-sampled direction happens to reach the emitter's image
// in the specular object: rarely, and then very brightly. On cornell-area these paths are 97% of
// the path tracer's squared error at 64 spp (docs/performance.md). Traced from the light, the
// same paths are easy: aim at the specular object, follow its Dirac lobe, and connect every
// diffuse or glossy vertex after it to the camera (Veach 1997, sec. 10.2; PBRT3 sec. 16.3's
// t = 1 strategy).
//
// The two estimators split path space between them, so their sum is unbiased without weights:
//  - the light tracer takes the paths camera -> x1 ... xk -> emitter whose camera vertex x1 scatters
//    through a non-Dirac lobe and whose emitter-side vertex xk through a Dirac one, for the area
//    lights it traces (AreaLight::causticTraced);
//  - the path tracer takes everything else: it drops emission it reaches after a Dirac bounce when
//    its first bounce was not a Dirac one (PathIntegrator::arrive).
// Emission directions are drawn only towards the casters (the shapes and meshes with a Dirac
// lobe), uniformly in the cones of their bounding spheres: every path the light tracer owns
// starts with a segment that ends on a caster, so this density covers all of them.
//
// Each sample index s gets its own batch of light paths (render.caustic_paths_per_pixel times the
// pixel count), splatted into
// an image of its own; a pixel's sample s is then the path tracer's sample plus that image's
// pixel. Samples stay independent across indices, so the film's per-pixel variance (and the
// z-tests built on it) still holds, and a render is the same for any thread count: each light
// path has its own sampler, and splats are summed in fixed point, where addition is associative.
#pragma once

#include "core/alias_table.h"
#include "core/math.h"
#include "core/ray_spawn.h"
#include "renderer/camera.h"
#include "renderer/sampler.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <memory>
#include <vector>

namespace ember {

class Light;
class Scene;
struct BsdfSample;
struct PathStats;
struct SurfaceHit;

// A caster's bounding sphere.
struct CausticCaster {
  Vec3 center;
  float radius;
};

// Splat images, one per sample index of a pass, summed in 64-bit fixed point (2^-24 steps, up to
// 2^39 per pixel; one splat at most 2^32) so that the order of the additions cannot change the
// result.
class CausticSplats {
 public:
  // pathFraction: the share of the usual light paths to trace for each index (batchFor), below 1
  // where adaptive sampling leaves most pixels without samples to splat into.
  void reset(int indices, int width, int height, double pathFraction = 1.0);
  int indices() const { return indices_; }
  double pathFraction() const { return pathFraction_; }
  // Thread-safe. False (and nothing added) for a non-finite or out-of-range colour.
  bool add(int index, int x, int y, const Color& c);
  Color at(int index, int x, int y) const;

 private:
  static constexpr double kScale = 16777216.0;  // 2^24
  int indices_ = 0, width_ = 0, height_ = 0;
  double pathFraction_ = 1.0;
  size_t size_ = 0, capacity_ = 0;
  std::unique_ptr<std::atomic<int64_t>[]> cells_;
};

class CausticTracer {
 public:
  // Scenes with more casters than this are left to the path tracer alone: each emission sample
  // evaluates every caster's cone.
  static constexpr size_t kMaxCasters = 64;
  CausticTracer() = default;
  // Enabled when there are casters (at most kMaxCasters), area lights and a perspective camera.
  CausticTracer(std::vector<CausticCaster> casters, std::vector<const Light*> lights, bool perspective,
                float pathsPerPixel = 0.5f);

  bool enabled() const { return enabled_; }
  // Why it does not run, in words ("" when it does).
  const char* whyDisabled() const { return whyDisabled_; }
  const std::vector<CausticCaster>& casters() const { return casters_; }

  // Light paths per sample index for the camera's image (at least one), and the paths per pixel
  // that are, which each splat is divided by.
  struct Batch {
    uint64_t paths;
    float pathsPerPixel;
  };
  // `fraction` of them (CausticSplats::pathFraction): each splat is still divided by the paths
  // per pixel actually traced, so the estimate stays unbiased with fewer.
  Batch batchFor(const Camera& camera, double fraction = 1.0) const {
    const uint64_t pixels = uint64_t(camera.width()) * uint64_t(camera.height());
    const uint64_t paths =
        std::max<uint64_t>(1, uint64_t(std::ceil(double(pixels) * double(pathsPerPixel_) * fraction)));
    return {paths, float(double(paths) / double(pixels))};
  }

  // One light path as a state machine, for the scalar driver (traceAlone) and for drivers that
  // cast the rays of many paths together (packet/caustic_wave.h). Both take the same steps in the
  // same order per path, so they splat the same values bit for bit.
  struct PathState {
    Ray ray;
    Color beta{0.0f};        // the flux the path carries, over the densities that drew it
    Color scattering{1.0f};  // the product of the scattering weights (Russian roulette reads it)
    int segments = 1;        // light segments cast so far, counting the one in flight
    int index = 0;           // the splat image (sample index within the pass)
    float pathsPerPixel = 1.0f;
    uint32_t rayMask = kAllRayMask;  // the Embree mask of `ray` (SurfaceHit::maskFor, Light::shadowMask)
    float range = 0.0f;              // the first segment's light range (EmissionPoint::range); 0: none
  };
  // A connection to the camera: `value` goes to pixel (x, y) if `ray` is unblocked.
  struct Splat {
    Ray ray;
    uint32_t mask = kAllRayMask;  // the Embree mask of `ray` (SurfaceHit::maskToward)
    int x = 0, y = 0;
    Color value{0.0f};
  };
  // Whether a light path can make a caustic within maxDepth segments, the camera's counted: the
  // shortest (light -> caster -> receiver -> camera) has 3. The drivers trace none otherwise.
  static bool reachesCaustics(int maxDepth) { return maxDepth < 0 || maxDepth >= 3; }
  // The path's emission: false if it carries nothing (its direction leaves the emitting side).
  bool start(Sampler& sampler, int index, float pathsPerPixel, int maxDepth, PathState& path) const;
  // start in its steps, for drivers that draw many samplers' numbers together: the numbers, in
  // the order start requests them (1D, 2D, 1D, 2D), then the emission they choose.
  struct EmissionNumbers {
    float light;     // which light
    Vec2 area;       // where on it
    float pick;      // which caster's cone
    Vec2 direction;  // where in the cone
  };
  bool startWith(const EmissionNumbers& u, int index, float pathsPerPixel, int maxDepth,
                 PathState& path) const;
  // The path's ray found `hit`: asks for a camera connection (returns true and fills `splat`)
  // and samples the next ray into path.ray; `continues` says whether the path goes on.
  bool onHit(const Scene& scene, int maxDepth, int rrDepth, PathState& path, const SurfaceHit& hit,
             Sampler& sampler, Splat& splat, bool& continues) const;
  // onHit in its steps, for drivers that sample the BSDFs of many vertices together
  // (Material::sampleLanes): connect (arrival and the camera connection; `scatters` says whether
  // the vertex samples a BSDF), then the BSDF's numbers (2D, then 1D) and sample for
  // wo = -path.ray.dir as it was on arrival, then follow (false if the path ends).
  bool connect(const Scene& scene, int maxDepth, PathState& path, const SurfaceHit& hit, Splat& splat,
               bool& scatters) const;
  bool follow(int rrDepth, PathState& path, const SurfaceHit& hit, const Vec3& wo, const BsdfSample& bs,
              bool sampled, Sampler& sampler) const;

  // The light paths of sample indices firstIndex + [0, count) (batch i into splats' image i),
  // each ray cast alone, counting at most maxDepth segments with the camera's (-1: unbounded).
  // Runs in parallel on the calling thread's task arena.
  void traceAlone(const Scene& scene, int maxDepth, int rrDepth, uint64_t seed, SamplerType sampler,
                  uint64_t firstIndex, int count, CausticSplats& splats, PathStats& stats) const;
  // The sampler of light path `path` of sample index `sampleIndex`.
  static Sampler samplerFor(SamplerType type, uint64_t seed, uint64_t path, uint64_t sampleIndex);

  // The emission-direction density from `from` (uniform in the union of the casters' cones, as a
  // mixture with equal weights), and a direction from it; exposed for the sampling tests.
  float directionPdf(const Vec3& from, const Vec3& dir) const;
  Vec3 sampleDirection(const Vec3& from, float uPick, Vec2 u) const;

 private:
  struct Cone {
    Vec3 axis;
    float oneMinusCosMax;  // 2: the whole sphere (from inside the caster's bounds)
    float sin2Max;
  };
  Cone cone(size_t i, const Vec3& from) const;

  std::vector<CausticCaster> casters_;
  std::vector<const Light*> lights_;
  AliasTable lightChoice_;  // by power
  std::vector<float> lightPmf_;
  float pathsPerPixel_ = 0.5f;
  bool enabled_ = false;
  const char* whyDisabled_ = "no mirror or glass";
};

}  // namespace ember
