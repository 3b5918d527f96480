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

  // The shading normal with the normal map applied (glTF 2.0 section 3.9.3).
  Vec3 perturb(const Vec3& n, const glm::vec4& tangent, Vec2 uv) const {
    return perturbNormal(*normalMap, normalScale, n, tangent, uv);
  }

  // The normal `n` perturbed by tangent-space normal map `map` at uv (coordinates of the map's
  // set): the texel's XYZ = 2 RGB - 1, X and Y scaled by `scale`, in the frame (T, B, N) with
  // B = cross(N, T) w (glTF 2.0 section 3.9.3). Falls back to `n` where the tangent is unusable.
  // The clearcoat layer's own normal map (KHR_materials_clearcoat) is read the same way.
  static Vec3 perturbNormal(const Texture& map, float scale, const Vec3& n, const glm::vec4& tangent,
                            Vec2 uv) {
    const Color c = map.eval(uv);
    const Vec3 local((2.0f * c.x - 1.0f) * scale, (2.0f * c.y - 1.0f) * scale, 2.0f * c.z - 1.0f);
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
// 2010), which is an unbiased estimate of alpha blending for a path tracer. Alpha is the texture's
// (in its own texture coordinate set) times, with `vertexAlpha`, COLOR_0's alpha.
class AlphaOpacity final : public MeshOpacity {
 public:
  AlphaOpacity(std::shared_ptr<const Texture> alpha, AlphaMode mode, float cutoff, bool vertexAlpha = false)
      : alpha_(std::move(alpha)), mode_(mode), cutoff_(cutoff), vertexAlpha_(vertexAlpha) {}
  bool passesThrough(const TriangleMesh& mesh, uint32_t prim, Vec2 b, float u) const override {
    const float a = alphaAt(mesh, prim, b);
    return mode_ == AlphaMode::Mask ? a < cutoff_ : u >= a;
  }
  float coverage(const TriangleMesh& mesh, uint32_t prim, Vec2 b) const override {
    const float a = alphaAt(mesh, prim, b);
    return mode_ == AlphaMode::Mask ? (a < cutoff_ ? 0.0f : 1.0f) : std::clamp(a, 0.0f, 1.0f);
  }

 private:
  float alphaAt(const TriangleMesh& mesh, uint32_t prim, Vec2 b) const {
    const float a = alpha_->eval(mesh.texCoordAt(alpha_->texCoordSet(), prim, b)).x;
    return vertexAlpha_ ? a * mesh.colorAt(prim, b).w : a;
  }

  std::shared_ptr<const Texture> alpha_;  // coverage in .x: baseColorFactor.a x texture alpha
  AlphaMode mode_;
  float cutoff_;
  bool vertexAlpha_;
};

}  // namespace ember
