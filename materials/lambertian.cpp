#include "materials/lambertian.h"

#include "core/sampling.h"
#include "core/warp_lanes.h"

#include <algorithm>

namespace ember {

Color Lambertian::eval(const SurfaceHit& hit, const Vec3& wo, const Vec3& wi) const {
  if (!sameSide(hit, wo, wi)) return Color(0.0f);
  const float cosI = glm::dot(wi, facingNormal(hit, wo));
  if (cosI <= 0.0f) return Color(0.0f);
  return reflectanceAt(hit) * (cosI * kInvPi);
}

float Lambertian::pdf(const SurfaceHit& hit, const Vec3& wo, const Vec3& wi) const {
  if (!sameSide(hit, wo, wi)) return 0.0f;
  return cosineHemispherePdf(glm::dot(wi, facingNormal(hit, wo)));
}

Color Lambertian::evalPdf(const SurfaceHit& hit, const Vec3& wo, const Vec3& wi, float& pdfOut) const {
  if (!sameSide(hit, wo, wi)) {
    pdfOut = 0.0f;
    return Color(0.0f);
  }
  const float cosI = glm::dot(wi, facingNormal(hit, wo));
  pdfOut = cosineHemispherePdf(cosI);
  if (cosI <= 0.0f) return Color(0.0f);
  return reflectanceAt(hit) * (cosI * kInvPi);
}

// One live lane of the kernel, so that one vertex and a wave of them get the same direction.
bool Lambertian::sample(const SurfaceHit& hit, const Vec3& wo, Vec2 u, float, BsdfSample& out) const {
  CosineLanes lanes;
  lanes.set(0, facingNormal(hit, wo), u);
  sampleCosineLanes(lanes, lanes.padFrom(1));
  return finishSample(hit, wo, lanes.direction(0), lanes.pdf[0], out);
}

void Lambertian::sampleLanes(const SurfaceHit* const* hits, const Vec3* wo, const Vec2* u, const float*,
                             size_t n, BsdfSample* out, bool* ok) const {
  CosineLanes lanes;
  for (size_t first = 0; first < n; first += CosineLanes::kMaxLanes) {
    const unsigned count = unsigned(std::min<size_t>(CosineLanes::kMaxLanes, n - first));
    for (unsigned i = 0; i < count; ++i)
      lanes.set(i, facingNormal(*hits[first + i], wo[first + i]), u[first + i]);
    sampleCosineLanes(lanes, lanes.padFrom(count));
    for (unsigned i = 0; i < count; ++i)
      ok[first + i] =
          finishSample(*hits[first + i], wo[first + i], lanes.direction(i), lanes.pdf[i], out[first + i]);
  }
}

bool Lambertian::finishSample(const SurfaceHit& hit, const Vec3& wo, const Vec3& wi, float pdf,
                              BsdfSample& out) const {
  out.wi = wi;
  out.pdf = pdf;
  if (!keepsSample(hit.ng, wo, wi, pdf)) return false;
  out.weight = reflectanceAt(hit);
  out.delta = false;
  out.eta = 1.0f;
  return true;
}

}  // namespace ember
