// Texture maps that change a mesh's surface rather than its BSDF (glTF 2.0 section 3.9): the
// tangent-space normal map, the emissive texture, and the alpha coverage used by MASK and BLEND.
#pragma once

#include "accel/triangle_mesh.h"
#include "materials/texture.h"

#include <memory>

namespace ember {

struct SurfaceMaps {
  std::shared_ptr<const Texture> normalMap;  // linear, RGB in [0, 1] encoding XYZ in [-1, 1]
  float normalScale = 1.0f;                  // normalTextureInfo.scale: scales X and Y
  std::shared_ptr<const Texture> emission;   // multiplies the mesh's emissive colour; null = 1

  // The shading normal with the normal map applied (glTF 2.0 section 3.9.3): the texel's XYZ in the
  // frame (T, B, N) with B = cross(N, T) w. Falls back to `n` where the tangent is unusable.
  Vec3 perturb(const Vec3& n, const glm::vec4& tangent, Vec2 uv) const {
    const Color c = normalMap->eval(uv);
    const Vec3 local((2.0f * c.x - 1.0f) * normalScale, (2.0f * c.y - 1.0f) * normalScale, 2.0f * c.z - 1.0f);
    Vec3 t = Vec3(tangent) - n * glm::dot(n, Vec3(tangent));
    const float tl = glm::length(t);
    if (!(tl > 1e-6f)) return n;
    t /= tl;
    const Vec3 b = glm::cross(n, t) * (tangent.w < 0.0f ? -1.0f : 1.0f);
    const Vec3 mapped = local.x * t + local.y * b + local.z * n;
    const float ml = glm::length(mapped);
    return ml > 1e-6f && std::isfinite(ml) ? mapped / ml : n;
  }
};

enum class AlphaMode { Opaque, Mask, Blend };

// glTF alpha coverage (section 3.9.4) as a MeshOpacity: MASK cuts out where alpha < alphaCutoff;
// BLEND lets a ray through with probability 1 - alpha (stochastic transparency, Enderton et al.
// 2010), which is an unbiased estimate of alpha blending for a path tracer.
class AlphaOpacity final : public MeshOpacity {
 public:
  AlphaOpacity(std::shared_ptr<const Texture> alpha, AlphaMode mode, float cutoff)
      : alpha_(std::move(alpha)), mode_(mode), cutoff_(cutoff) {}
  bool passesThrough(Vec2 uv, float u) const override {
    const float a = alpha_->eval(uv).x;
    return mode_ == AlphaMode::Mask ? a < cutoff_ : u >= a;
  }
  float coverage(Vec2 uv) const override {
    const float a = alpha_->eval(uv).x;
    return mode_ == AlphaMode::Mask ? (a < cutoff_ ? 0.0f : 1.0f) : std::clamp(a, 0.0f, 1.0f);
  }

 private:
  std::shared_ptr<const Texture> alpha_;  // coverage in .x: baseColorFactor.a x texture alpha
  AlphaMode mode_;
  float cutoff_;
};

}  // namespace ember
