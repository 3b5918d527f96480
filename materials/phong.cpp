#include "materials/phong.h"

#include "core/sampling.h"

namespace ember {

float Phong::diffuseProbability(const Color& kd) const {
  const float d = maxComponent(kd), s = maxComponent(ks_);
  return d + s > 0.0f ? d / (d + s) : 1.0f;
}

Color Phong::eval(const SurfaceHit& hit, const Vec3& wo, const Vec3& wi) const {
  if (!sameSide(hit, wo, wi)) return Color(0.0f);
  const Vec3 n = facingNormal(hit, wo);
  const float cosI = glm::dot(wi, n);
  if (cosI <= 0.0f) return Color(0.0f);
  const Vec3 r = reflect(wo, n);
  return (kd_->evalAt(hit) * kInvPi + ks_ * lobe_.value(wi, r)) * cosI;
}

float Phong::pdf(const SurfaceHit& hit, const Vec3& wo, const Vec3& wi) const {
  if (!sameSide(hit, wo, wi)) return 0.0f;
  const Vec3 n = facingNormal(hit, wo);
  const float pd = diffuseProbability(kd_->evalAt(hit));
  return pd * cosineHemispherePdf(glm::dot(wi, n)) + (1.0f - pd) * lobe_.pdf(wi, reflect(wo, n));
}

bool Phong::sample(const SurfaceHit& hit, const Vec3& wo, Vec2 u, float uLobe, BsdfSample& out) const {
  const Vec3 n = facingNormal(hit, wo);
  const float pd = diffuseProbability(kd_->evalAt(hit));
  out.wi = uLobe < pd ? Frame(n).toWorld(sampleCosineHemisphere(u)) : lobe_.sample(reflect(wo, n), u);
  out.pdf = pdf(hit, wo, out.wi);
  if (out.pdf <= 0.0f) return false;
  out.weight = eval(hit, wo, out.wi) / out.pdf;
  out.delta = false;
  out.eta = 1.0f;
  return !isBlack(out.weight);
}

}  // namespace ember
