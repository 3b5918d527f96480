#include "materials/lambertian.h"

#include "core/sampling.h"

namespace ember {

Color Lambertian::eval(const SurfaceHit& hit, const Vec3& wo, const Vec3& wi) const {
  if (!sameSide(hit, wo, wi)) return Color(0.0f);
  const float cosI = glm::dot(wi, facingNormal(hit, wo));
  if (cosI <= 0.0f) return Color(0.0f);
  return reflectance_->eval(hit.uv) * (cosI * kInvPi);
}

float Lambertian::pdf(const SurfaceHit& hit, const Vec3& wo, const Vec3& wi) const {
  if (!sameSide(hit, wo, wi)) return 0.0f;
  return cosineHemispherePdf(glm::dot(wi, facingNormal(hit, wo)));
}

bool Lambertian::sample(const SurfaceHit& hit, const Vec3& wo, Vec2 u, float, BsdfSample& out) const {
  const Frame frame(facingNormal(hit, wo));
  const Vec3 local = sampleCosineHemisphere(u);
  out.wi = frame.toWorld(local);
  out.pdf = cosineHemispherePdf(local.z);
  // With a shading normal the sampled direction can dip below the geometric surface: absorb it.
  if (out.pdf <= 0.0f || !sameSide(hit, wo, out.wi)) return false;
  out.weight = reflectance_->eval(hit.uv);
  out.delta = false;
  out.eta = 1.0f;
  return true;
}

}  // namespace ember
