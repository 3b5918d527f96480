// The interface every material implements: evaluate, sample and pdf, as next-event estimation with
// multiple importance sampling needs them (Veach 1997, ch. 9). Directions point away from the
// surface: wo towards the previous path vertex, wi towards the next one.
#pragma once

#include "core/surface_hit.h"

#include <string_view>

namespace ember {

struct BsdfSample {
  Vec3 wi;
  Color weight;        // f(wo, wi) |cos theta_i| / pdf: what the path throughput is multiplied by
  float pdf = 0.0f;    // solid-angle density of wi; for a delta lobe, the lobe's discrete probability
  bool delta = false;  // wi came from a Dirac lobe (mirror, refraction): no MIS with light sampling
  float eta = 1.0f;    // relative index of refraction crossed (eta_t / eta_i), 1 for reflection
};

class Material {
 public:
  virtual ~Material() = default;
  virtual std::string_view typeName() const = 0;

  // f(wo, wi) |cos theta_i| of the non-delta lobes; Dirac lobes contribute nothing here.
  virtual Color eval(const SurfaceHit& hit, const Vec3& wo, const Vec3& wi) const = 0;
  // Solid-angle density with which sample() produces wi through its non-delta lobes.
  virtual float pdf(const SurfaceHit& hit, const Vec3& wo, const Vec3& wi) const = 0;
  // eval and pdf together, for next-event estimation, which needs both; materials whose two share
  // most of their work (a microfacet model) override it to do that work once.
  virtual Color evalPdf(const SurfaceHit& hit, const Vec3& wo, const Vec3& wi, float& pdfOut) const {
    pdfOut = pdf(hit, wo, wi);
    return eval(hit, wo, wi);
  }
  // Samples wi; uLobe picks among lobes, u the direction within one. False: the path is absorbed.
  virtual bool sample(const SurfaceHit& hit, const Vec3& wo, Vec2 u, float uLobe, BsdfSample& out) const = 0;
  // sample() for n vertices of this material at once: ok[i] = sample(*hits[i], wo[i], u[i],
  // uLobe[i], out[i]), bit for bit. The default goes vertex by vertex; materials with a lane
  // kernel (core/warp_lanes.h) override it.
  virtual void sampleLanes(const SurfaceHit* const* hits, const Vec3* wo, const Vec2* u, const float* uLobe,
                           size_t n, BsdfSample* out, bool* ok) const {
    for (size_t i = 0; i < n; ++i) ok[i] = sample(*hits[i], wo[i], u[i], uLobe[i], out[i]);
  }

  // The batched driver's vector kernels (packet/next_event_lanes.h, continuation_lanes.h) evaluate
  // and follow one BSDF inline: a Lambertian reflector shaded with the geometric normal, with its
  // reflectance in a row. A material that is exactly that at `hit` says so and gives the
  // reflectance; every other vertex is evaluated and sampled by its material's own methods. The
  // answer is a fact about the BSDF, not a speed switch: the image is the same either way.
  virtual bool lambertianAt(const SurfaceHit& /*hit*/, Color& /*reflectance*/) const { return false; }
  // The same for every hit on an analytic shape (whose shading normal is its geometric normal),
  // where the reflectance is also the same everywhere: the driver then settles a whole run of such
  // hits in one kernel (packet/arrival_lanes.h). Null otherwise.
  virtual const Color* uniformLambertian() const { return nullptr; }

  // Whether eval can be non-zero, i.e. light sampling is worth a shadow ray. A flag each material
  // sets where it is made: the bounce asks at every vertex.
  bool hasNonDeltaLobes() const { return nonDeltaLobes_; }
  // Whether sample() can return a Dirac lobe (a mirror or a smooth refraction): such surfaces
  // cast caustics (renderer/caustic_tracer.h).
  virtual bool hasDeltaLobes() const { return false; }

  // Whether sample() and sampleLanes read the direction numbers u, and the lobe number uLobe: a
  // caller drawing the numbers of many vertices together passes over the ones a material never
  // reads (renderer/sampler_lanes.h, RequestUse), and the sampler's later numbers stay the same.
  // False only where both return the same for any value (tests/test_materials.cpp).
  bool usesDirectionSample() const { return usesDirection_; }
  bool usesLobeSample() const { return usesLobe_; }

  // Whether any of its parameters is a texture, i.e. its hits need texture coordinates. Hits on
  // analytic shapes skip the UV (the sphere's inverse trigonometry) when the material reads none.
  virtual bool readsUv() const { return true; }

  // Whether every lobe is black at this hit, so that the path ends here after its emission: its
  // light sample and every continuation would carry exactly zero, and skipping them changes no
  // pixel (Cycles likewise ends a path at a surface whose closures all have zero weight). A black
  // texel of a diffuse texture is such a hit: on a black-and-white checkerboard 3% of the render
  // (docs/performance.md). Only materials that can absorb somewhere check.
  bool absorbsAt(const SurfaceHit& hit) const { return mayAbsorb_ && absorbsEverythingAt(hit); }

  // Fraction of radiance surviving `distance` through the medium this surface encloses (Beer-Lambert;
  // 1 for surfaces without an absorbing interior). Applied to path segments that reach the surface
  // from inside, i.e. against its outward geometric normal: correct for closed, non-nested objects.
  virtual Color interiorTransmittance(float /*distance*/) const { return Color(1.0f); }

 protected:
  // absorbsAt for a material that sets mayAbsorb_.
  virtual bool absorbsEverythingAt(const SurfaceHit& /*hit*/) const { return false; }
  bool mayAbsorb_ = false;                       // some hit may be black in every lobe
  bool usesDirection_ = true, usesLobe_ = true;  // see usesDirectionSample
  bool nonDeltaLobes_ = true;                    // see hasNonDeltaLobes
};

// wo and wi on the same geometric side of the surface (a reflection, not a transmission).
inline bool sameSide(const SurfaceHit& hit, const Vec3& wo, const Vec3& wi) {
  return glm::dot(wo, hit.ng) * glm::dot(wi, hit.ng) > 0.0f;
}

// The shading normal turned to the side of wo: two-sided materials shade both sides alike.
inline Vec3 facingNormal(const SurfaceHit& hit, const Vec3& wo) {
  return glm::dot(wo, hit.ng) >= 0.0f ? hit.ns : -hit.ns;
}

}  // namespace ember
