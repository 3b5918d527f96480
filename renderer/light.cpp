#include "renderer/light.h"

#include "renderer/sampling.h"

namespace ember {

bool PointLight::sample(const Vec3& ref, Vec2, LightSample& out) const {
  const Vec3 d = position_ - ref;
  const float dist2 = glm::dot(d, d);
  if (dist2 == 0.0f) return false;
  out.dist = std::sqrt(dist2);
  out.wi = d / out.dist;
  out.p = position_;
  out.Li = intensity_ / dist2;
  out.pdf = 1.0f;
  out.delta = true;
  return true;
}

bool AreaLight::sample(const Vec3& ref, Vec2 u, LightSample& out) const {
  ShapeSample s;
  float pdf;
  if (!shape_->sampleSolidAngle(ref, u, s, pdf)) return false;
  const Vec3 d = s.p - ref;
  out.dist = glm::length(d);
  if (out.dist == 0.0f) return false;
  out.wi = d / out.dist;
  out.p = s.p;
  out.pdf = pdf;
  out.delta = false;
  // One-sided: the light emits only towards the side its normal faces.
  out.Li = glm::dot(-out.wi, s.n) > 0.0f ? radiance_ : Color(0.0f);
  return true;
}

bool TriangleLight::sample(const Vec3& ref, Vec2 u, LightSample& out) const {
  const Vec2 b = sampleUniformTriangle(u);
  const TriangleMesh::Surface surface = mesh_->surfaceAt(prim_, b.y, 1.0f - b.x - b.y);
  const glm::uvec3& idx = mesh_->indices[prim_];
  const Vec3 p = b.x * mesh_->positions[idx.x] + b.y * mesh_->positions[idx.y] +
                 (1.0f - b.x - b.y) * mesh_->positions[idx.z];
  const Vec3 d = p - ref;
  out.dist = glm::length(d);
  if (out.dist == 0.0f) return false;
  out.wi = d / out.dist;
  out.p = p;
  out.pdf = pdf(ref, p, surface.ng);
  out.delta = false;
  out.Li = glm::dot(-out.wi, surface.ng) > 0.0f ? radiance_ : Color(0.0f);
  return out.pdf > 0.0f && std::isfinite(out.pdf);
}

bool EnvironmentLight::sample(const Vec3&, Vec2 u, LightSample& out) const {
  out.wi = sampleUniformSphere(u);
  out.dist = kInfinity;
  out.pdf = kUniformSpherePdf;
  out.Li = radiance_;
  out.delta = false;
  return true;
}

float EnvironmentLight::pdf(const Vec3&, const Vec3&, const Vec3&) const {
  return kUniformSpherePdf;
}

}  // namespace ember
