#include "materials/mixed.h"

#include "core/sampling.h"
#include "materials/specular.h"

namespace ember {

bool Mixed::hasDeltaLobes() const {
  return !isBlack(c_.kr) || !isBlack(c_.kt);
}

Color Mixed::eval(const SurfaceHit& hit, const Vec3& wo, const Vec3& wi) const {
  if (!sameSide(hit, wo, wi)) return Color(0.0f);
  const Vec3 n = facingNormal(hit, wo);
  const float cosI = glm::dot(wi, n);
  if (cosI <= 0.0f) return Color(0.0f);
  return (c_.kd->evalAt(hit) * kInvPi + c_.ks * lobe_.value(wi, reflect(wo, n))) * cosI;
}

float Mixed::pdf(const SurfaceHit& hit, const Vec3& wo, const Vec3& wi) const {
  if (!sameSide(hit, wo, wi)) return 0.0f;
  const Vec3 n = facingNormal(hit, wo);
  const float pd = maxComponent(c_.kd->evalAt(hit));
  const float ps = maxComponent(c_.ks);
  return pd * cosineHemispherePdf(glm::dot(wi, n)) + ps * lobe_.pdf(wi, reflect(wo, n));
}

bool Mixed::sample(const SurfaceHit& hit, const Vec3& wo, Vec2 u, float uLobe, BsdfSample& out) const {
  const float pd = maxComponent(c_.kd->evalAt(hit));
  const float ps = maxComponent(c_.ks);
  const float pr = maxComponent(c_.kr);
  const float pt = maxComponent(c_.kt);
  const Vec3 n = facingNormal(hit, wo);
  if (uLobe < pd + ps) {
    out.wi = uLobe < pd ? Frame(n).toWorld(sampleCosineHemisphere(u)) : lobe_.sample(reflect(wo, n), u);
    out.pdf = pdf(hit, wo, out.wi);
    if (out.pdf <= 0.0f) return false;
    out.weight = eval(hit, wo, out.wi) / out.pdf;
    out.delta = false;
    out.eta = 1.0f;
    return !isBlack(out.weight);
  }
  if (uLobe < pd + ps + pr) {
    out.wi = reflect(wo, n);
    out.weight = c_.kr / pr;
    out.pdf = pr;
    out.delta = true;
    out.eta = 1.0f;
    return sameSide(hit, wo, out.wi);
  }
  if (uLobe < pd + ps + pr + pt) {
    refractOrReflect(Interface::facing(hit, wo, c_.ior, 1.0f), wo, out);
    out.weight *= c_.kt / pt;
    out.pdf = pt;
    return true;
  }
  return false;  // absorbed
}

}  // namespace ember
