// Everything shading needs about a ray's hit point, in world space.
#pragma once

#include "renderer/math.h"

#include <cstdint>

namespace ember {

class Material;
class Light;

struct SurfaceHit {
  Vec3 p;
  Vec3 ng;  // unit geometric normal: outward for closed shapes, the front side otherwise
  Vec3 ns;  // unit shading normal, in the same hemisphere as ng
  Vec2 uv;
  float t = 0.0f;
  const Material* material = nullptr;
  const Light* light = nullptr;  // the area light this surface belongs to, if it emits
  Color emission{0.0f};          // radiance emitted on the side of ng

  // Radiance the surface emits towards direction w (one-sided: only on the side of ng).
  Color emitted(const Vec3& w) const { return glm::dot(w, ng) > 0.0f ? emission : Color(0.0f); }
};

// Origin for a ray leaving a hit point in direction dir: pushed off the surface along the geometric
// normal, to the side dir leaves on (Woo et al. 1996). The push is a small multiple of the float
// rounding error of the hit point, which grows with the magnitude of its coordinates and with the
// ray distance t it was found at (p = o + t d; PBRT4 section 6.8 derives exact bounds): large
// enough to escape self-intersection, small enough not to cross a neighbouring face near an acute
// edge (a cone's rim).
inline Vec3 offsetRayOrigin(const Vec3& p, const Vec3& ng, const Vec3& dir, float t = 0.0f) {
  const float eps = 2e-6f * (maxComponent(glm::abs(p)) + std::abs(t)) + 1e-7f;
  return p + (glm::dot(dir, ng) >= 0.0f ? eps : -eps) * ng;
}

}  // namespace ember
