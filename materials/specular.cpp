#include "materials/specular.h"

#include "materials/fresnel.h"

namespace ember {

bool Mirror::sample(const SurfaceHit& hit, const Vec3& wo, Vec2, float, BsdfSample& out) const {
  out.wi = reflect(wo, facingNormal(hit, wo));
  out.weight = reflectance_;
  out.pdf = 1.0f;
  out.delta = true;
  out.eta = 1.0f;
  return sameSide(hit, wo, out.wi);
}

void refractOrReflect(const Interface& iface, const Vec3& wo, BsdfSample& out) {
  out.delta = true;
  if (refract(wo, iface.n, iface.eta, out.wi)) {
    out.eta = iface.eta;
    out.weight = Color(1.0f / (iface.eta * iface.eta));
  } else {
    out.wi = reflect(wo, iface.n);
    out.eta = 1.0f;
    out.weight = Color(1.0f);
  }
}

bool Refraction::sample(const SurfaceHit& hit, const Vec3& wo, Vec2, float, BsdfSample& out) const {
  refractOrReflect(Interface::facing(hit, wo, iorInside_, iorOutside_), wo, out);
  out.weight *= transmittance_;
  out.pdf = 1.0f;
  return true;
}

bool Dielectric::sample(const SurfaceHit& hit, const Vec3& wo, Vec2, float uLobe, BsdfSample& out) const {
  const Interface iface = Interface::facing(hit, wo, iorInside_, iorOutside_);
  const float F = fresnelDielectric(glm::dot(wo, iface.n), iface.eta);
  out.delta = true;
  if (uLobe < F) {
    // Reflection with probability F: weight F / F = 1.
    out.wi = reflect(wo, iface.n);
    out.weight = Color(1.0f);
    out.pdf = F;
    out.eta = 1.0f;
    return true;
  }
  refractOrReflect(iface, wo, out);  // F < 1 here, so Snell has a solution
  out.pdf = 1.0f - F;
  return true;
}

}  // namespace ember
