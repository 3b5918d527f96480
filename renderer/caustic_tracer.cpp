#include "renderer/caustic_tracer.h"

#include "core/sampling.h"
#include "renderer/integrator.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <pmmintrin.h>
#include <xmmintrin.h>

#include <algorithm>
#include <cmath>
#include <mutex>

namespace ember {
namespace {

// Light paths draw from a stream of their own: sample s of light path j must not repeat the
// numbers of sample s of pixel j.
constexpr uint64_t kSeedSalt = 0x6a09e667f3bcc909ull;
// Light paths per task: enough to amortise the scheduling, few enough to balance two threads.
constexpr uint64_t kPathsPerTask = 1024;
// A direction counts as inside a cone when its sine to the axis is within this relative margin
// of the cone's, so that rounding never puts a sampled direction outside the cone it came from.
constexpr float kRimMargin = 1.0f + 2e-5f;

// Veach's correction for shading normals in importance transport (Veach 1997, eq. 5.19; PBRT3
// sec. 16.1.3): wo towards the light side, wi the direction importance arrives from.
float shadingCorrection(const SurfaceHit& hit, const Vec3& wo, const Vec3& wi) {
  if (hit.ns == hit.ng) return 1.0f;
  const float den = std::abs(glm::dot(wo, hit.ng) * glm::dot(wi, hit.ns));
  return den > 0.0f ? std::abs(glm::dot(wo, hit.ns) * glm::dot(wi, hit.ng)) / den : 0.0f;
}

}  // namespace

void CausticSplats::reset(int indices, int width, int height, double pathFraction) {
  pathFraction_ = pathFraction;
  const size_t size = size_t(indices) * size_t(width) * size_t(height) * 3;
  if (size > capacity_) {  // a pass's last, shorter batch reuses the cells
    cells_ = std::make_unique<std::atomic<int64_t>[]>(size);
    capacity_ = size;
  }
  size_ = size;
  indices_ = indices;
  width_ = width;
  height_ = height;
  for (size_t i = 0; i < size_; ++i) cells_[i].store(0, std::memory_order_relaxed);
}

bool CausticSplats::add(int index, int x, int y, const Color& c) {
  // At most 2^32 per splat (2^56 in fixed point): a pixel holds 2^7 of the largest before its
  // 64-bit sum could wrap. A light path's splat that large is a non-finite sample in all but name.
  constexpr double kLimit = 4294967296.0;  // 2^32
  for (int k = 0; k < 3; ++k)
    if (!(std::abs(double(c[k])) < kLimit)) return false;
  const size_t i = ((size_t(index) * size_t(height_) + size_t(y)) * size_t(width_) + size_t(x)) * 3;
  for (int k = 0; k < 3; ++k) {
    // Rounded half away from zero by truncating: a conversion instruction, where llround is a call.
    const double scaled = double(c[k]) * kScale;
    cells_[i + size_t(k)].fetch_add(int64_t(scaled + std::copysign(0.5, scaled)), std::memory_order_relaxed);
  }
  return true;
}

Color CausticSplats::at(int index, int x, int y) const {
  const size_t i = ((size_t(index) * size_t(height_) + size_t(y)) * size_t(width_) + size_t(x)) * 3;
  Color c;
  for (int k = 0; k < 3; ++k)
    c[k] = float(double(cells_[i + size_t(k)].load(std::memory_order_relaxed)) / kScale);
  return c;
}

CausticTracer::CausticTracer(std::vector<CausticCaster> casters, std::vector<const Light*> lights,
                             bool perspective, float pathsPerPixel)
    : casters_(std::move(casters)), lights_(std::move(lights)), pathsPerPixel_(pathsPerPixel) {
  whyDisabled_ = casters_.empty()                ? "no mirror or glass"
                 : casters_.size() > kMaxCasters ? "more specular objects than it aims at (64)"
                 : lights_.empty()               ? "no light to trace from"
                 : !perspective                  ? "not a perspective camera"
                                                 : "";
  enabled_ = *whyDisabled_ == '\0';
  if (!enabled_) return;
  std::vector<double> weights;
  double total = 0.0;
  for (const Light* light : lights_) {
    weights.push_back(std::max(0.0, double(maxComponent(light->power(0.0f)))));
    total += weights.back();
  }
  if (!(total > 0.0) || !std::isfinite(total)) {
    enabled_ = false;
    whyDisabled_ = "no light emits";
    return;
  }
  lightChoice_ = AliasTable(weights);
  for (double w : weights) lightPmf_.push_back(float(w / total));
}

CausticTracer::Cone CausticTracer::cone(size_t i, const Vec3& from) const {
  const CausticCaster& c = casters_[i];
  const Vec3 toCenter = c.center - from;
  const float dist2 = glm::dot(toCenter, toCenter);
  const float r2 = c.radius * c.radius;
  if (!(dist2 > r2 * 1.0001f)) return {Vec3(0.0f, 0.0f, 1.0f), 2.0f, 1.0f};  // inside: every direction
  const float sin2Max = r2 / dist2;
  const float cosMax = std::sqrt(1.0f - sin2Max);
  return {toCenter / std::sqrt(dist2), sin2Max / (1.0f + cosMax), sin2Max};
}

float CausticTracer::directionPdf(const Vec3& from, const Vec3& dir) const {
  float sum = 0.0f;
  for (size_t i = 0; i < casters_.size(); ++i) {
    const Cone c = cone(i, from);
    if (c.oneMinusCosMax < 2.0f) {
      if (glm::dot(dir, c.axis) <= 0.0f) continue;
      // The sine from the cross product: precise for the narrow cones of distant casters.
      const Vec3 cr = glm::cross(dir, c.axis);
      if (glm::dot(cr, cr) > c.sin2Max * kRimMargin) continue;
    }
    sum += 1.0f / (2.0f * kPi * c.oneMinusCosMax);
  }
  return sum / float(casters_.size());
}

Vec3 CausticTracer::sampleDirection(const Vec3& from, float uPick, Vec2 u) const {
  const size_t i = std::min(size_t(uPick * float(casters_.size())), casters_.size() - 1);
  const Cone c = cone(i, from);
  if (c.oneMinusCosMax >= 2.0f) return sampleUniformSphere(u);
  // Uniform in the cone (PBRT4 eq. A.12), sin^2 as t (2 - t) with t = 1 - cos, precise for small cones.
  const float t = u.x * c.oneMinusCosMax;
  const float sinTheta = std::sqrt(std::max(0.0f, t * (2.0f - t)));
  const float phi = 2.0f * kPi * u.y;
  return Frame(c.axis).toWorld(Vec3(sinTheta * std::cos(phi), sinTheta * std::sin(phi), 1.0f - t));
}

Sampler CausticTracer::samplerFor(SamplerType type, uint64_t seed, uint64_t path, uint64_t sampleIndex) {
  return Sampler(type, seed ^ kSeedSalt, path, sampleIndex);
}

void CausticTracer::traceAlone(const Scene& scene, int maxDepth, int rrDepth, uint64_t seed, SamplerType type,
                               uint64_t firstIndex, int count, CausticSplats& splats,
                               PathStats& stats) const {
  if (!enabled_ || count <= 0 || !reachesCaustics(maxDepth)) return;
  // Plain variables, not a structured binding: Clang 14 cannot capture those in the lambda.
  const CausticTracer::Batch batch = batchFor(scene.camera(), splats.pathFraction());
  const uint64_t paths = batch.paths;
  const float pathsPerPixel = batch.pathsPerPixel;
  std::mutex statsMutex;
  tbb::parallel_for(tbb::blocked_range<uint64_t>(0, paths * uint64_t(count), kPathsPerTask),
                    [&](const tbb::blocked_range<uint64_t>& range) {
                      // As in the tile tasks: the same floating-point mode on every thread.
                      _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
                      _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
                      PathStats local;
                      for (uint64_t k = range.begin(); k != range.end(); ++k) {
                        const uint64_t index = k / paths;
                        Sampler sampler = samplerFor(type, seed, k % paths, firstIndex + index);
                        PathState path;
                        if (!start(sampler, int(index), pathsPerPixel, maxDepth, path)) continue;
                        for (bool continues = true; continues;) {
                          SurfaceHit hit;
                          ++local.rays;
                          if (!scene.intersect(path.ray, hit, path.rayMask)) break;
                          Splat splat;
                          if (onHit(scene, maxDepth, rrDepth, path, hit, sampler, splat, continues)) {
                            ++local.shadowRays;
                            const bool blocked = scene.occluded(splat.ray, splat.mask);
                            if (!blocked && !splats.add(path.index, splat.x, splat.y, splat.value))
                              ++local.nonFinite;
                          }
                        }
                      }
                      std::lock_guard<std::mutex> lock(statsMutex);
                      stats += local;
                    });
}

bool CausticTracer::start(Sampler& sampler, int index, float pathsPerPixel, int maxDepth,
                          PathState& path) const {
  EmissionNumbers u;
  u.light = sampler.get1D();
  u.area = sampler.get2D();
  u.pick = sampler.get1D();
  u.direction = sampler.get2D();
  return startWith(u, index, pathsPerPixel, maxDepth, path);
}

bool CausticTracer::startWith(const EmissionNumbers& u, int index, float pathsPerPixel, int maxDepth,
                              PathState& path) const {
  // Segments counted as the path tracer counts them, the camera's included: a connection from
  // the vertex at the end of light segment n makes a path of n + 1.
  if (!reachesCaustics(maxDepth)) return false;
  // A light by power, a point on it (uniform by area, or a point light's position), a direction
  // towards a caster.
  const size_t li = lightChoice_.sample(u.light);
  const Light& light = *lights_[li];
  EmissionPoint y;
  if (!light.sampleEmission(u.area, y)) return false;
  const Vec3 dir = sampleDirection(y.p, u.pick, u.direction);
  const Color emitted = light.emittedToward(y, dir);
  if (isBlack(emitted)) return false;
  const float pdfDir = directionPdf(y.p, dir);
  if (!(pdfDir > 0.0f)) return false;
  // Le |cos| / (p_light p_area p_dir) on a surface, I / (p_light p_dir) from a point.
  path.beta = emitted / (lightPmf_[li] * y.pdfArea * pdfDir);
  path.scattering = Color(1.0f);
  path.segments = 1;
  path.index = index;
  path.pathsPerPixel = pathsPerPixel;
  path.range = y.range;
  // A surface's point pushed off it to the side the ray leaves by; a point light's is exact.
  path.ray = Ray{glm::dot(y.n, y.n) > 0.0f ? offsetAlongNormal(y.p, y.n, y.pError, dir) : y.p, dir};
  path.rayMask = light.shadowMask;  // leaving the light, it cannot meet a flat one again
  return true;
}

bool CausticTracer::onHit(const Scene& scene, int maxDepth, int rrDepth, PathState& path,
                          const SurfaceHit& hit, Sampler& sampler, Splat& splat, bool& continues) const {
  continues = false;
  bool scatters;
  const bool connects = connect(scene, maxDepth, path, hit, splat, scatters);
  if (!scatters) return connects;
  const Vec3 wo = -path.ray.dir;
  const Vec2 u = sampler.get2D();
  const float uLobe = sampler.get1D();
  BsdfSample bs;
  const bool sampled = hit.material->sample(hit, wo, u, uLobe, bs);
  continues = follow(rrDepth, path, hit, wo, bs, sampled, sampler);
  return connects;
}

bool CausticTracer::connect(const Scene& scene, int maxDepth, PathState& path, const SurfaceHit& hit,
                            Splat& splat, bool& scatters) const {
  scatters = false;
  if (!hit.material) return false;
  const Material& m = *hit.material;
  if (glm::dot(path.ray.dir, hit.ng) > 0.0f) path.beta *= m.interiorTransmittance(hit.t);
  const Vec3 wo = -path.ray.dir;  // towards the light side
  const bool first = path.segments == 1;
  // A ranged punctual light's window over the first segment's length, as next-event estimation
  // applies it over the distance to the light.
  if (first && path.range > 0.0f) path.beta *= rangeWindow(hit.t, path.range);
  if (first && !m.hasDeltaLobes()) return false;  // the path tracer's: no Dirac vertex next to the light

  // The connection to the camera: the path camera -> hit -> ... -> light of segments + 1 segments.
  bool connects = false;
  const Camera& camera = scene.camera();
  Vec2 raster;
  float cosCamera;
  if (!first && m.hasNonDeltaLobes() && camera.project(hit.p, raster, cosCamera)) {
    const Vec3 toCamera = camera.origin() - hit.p;
    const float dist2 = glm::dot(toCamera, toCamera);
    const Vec3 wi = toCamera / std::sqrt(dist2);
    // f(wo, wi) |cos wi|; every non-Dirac lobe Ember has is symmetric in its two directions.
    Color f = m.eval(hit, wo, wi) * shadingCorrection(hit, wo, wi);
    if (glm::dot(wi, hit.ng) < 0.0f) f *= m.interiorTransmittance(std::sqrt(dist2));
    if (!isBlack(f)) {
      // The pixel's importance is pixels / (A cos^4) per unit solid angle (A: the image plane's
      // area at unit distance; PBRT3 sec. 16.1.1); with the camera's cos / d^2 and the paths per
      // pixel of this sample index, each splat is beta f / (A cos^3 d^2 paths/pixel).
      const float we =
          1.0f / (camera.imagePlaneArea() * cosCamera * cosCamera * cosCamera * dist2 * path.pathsPerPixel);
      const bool front = frontSide(hit.ng, camera.origin() - hit.p);
      splat.ray = spawnRayTo(hit.p, hit.ng, hit.pError, camera.origin(), Vec3(0.0f), 0.0f, front);
      splat.mask = hit.maskToward(camera.origin(), 0.0f, front);
      splat.x = std::min(int(raster.x), camera.width() - 1);
      splat.y = std::min(int(raster.y), camera.height() - 1);
      splat.value = path.beta * f * we;
      connects = true;
    }
  }
  // The next connection would make a path of segments + 2.
  scatters = !(maxDepth >= 0 && path.segments + 2 > maxDepth);
  return connects;
}

bool CausticTracer::follow(int rrDepth, PathState& path, const SurfaceHit& hit, const Vec3& wo,
                           const BsdfSample& bs, bool sampled, Sampler& sampler) const {
  if (!sampled) return false;
  if (path.segments == 1 && !bs.delta) return false;  // a non-Dirac lobe next to the light: the path tracer's
  // Importance is not scaled by refraction as radiance is (Veach 1997, sec. 5.2): undo the
  // material's 1 / eta^2.
  const Color w = bs.weight * (bs.eta * bs.eta * shadingCorrection(hit, wo, bs.wi));
  path.beta *= w;
  path.scattering *= w;
  if (isBlack(path.beta)) return false;
  if (path.segments >= rrDepth) {
    const float q = std::min(maxComponent(path.scattering), 0.95f);
    if (sampler.get1D() >= q) return false;
    path.beta /= q;
    path.scattering /= q;
  }
  const bool front = frontSide(hit.ng, bs.wi);
  path.ray = Ray{hit.offsetOrigin(front), bs.wi};
  path.rayMask = hit.maskFor(front);
  ++path.segments;
  return true;
}

}  // namespace ember
