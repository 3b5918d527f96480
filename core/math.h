// Small vector helpers shared by every layer. Colours are linear RGB triples (Mitsuba's `rgb`
// mode): every product is per channel, so a glm::vec3 serves both as a direction and a colour.
#pragma once

#include <glm/glm.hpp>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <numbers>

namespace ember {

using Vec2 = glm::vec2;
using Vec3 = glm::vec3;
using Color = glm::vec3;
using Mat4 = glm::mat4;

inline constexpr float kPi = std::numbers::pi_v<float>;
inline constexpr float kInvPi = 1.0f / kPi;
inline constexpr float kInfinity = std::numeric_limits<float>::infinity();

inline float maxComponent(const Vec3& v) {
  return std::max(v.x, std::max(v.y, v.z));
}
// Componentwise |v|. glm::abs is `x >= 0 ? x : -x`, which GCC compiles to a branch per component,
// and on ray directions those branches are unpredictable; fabs is one AND.
inline Vec3 absolute(const Vec3& v) {
  return {std::fabs(v.x), std::fabs(v.y), std::fabs(v.z)};
}
// On the bit patterns: those of non-negative floats order as their values, and an integer max is a
// conditional move, where GCC's profile-guided build turns std::max of floats into branches that
// mispredict on hit points (1.5% of a render for one more call per shadow ray, seventeenth
// session). Equal to maxComponent(absolute(v)) but for NaN components, which it propagates.
inline float maxAbsComponent(const Vec3& v) {
  const uint32_t x = std::bit_cast<uint32_t>(std::fabs(v.x)), y = std::bit_cast<uint32_t>(std::fabs(v.y)),
                 z = std::bit_cast<uint32_t>(std::fabs(v.z));
  return std::bit_cast<float>(std::max(x, std::max(y, z)));
}
inline bool isBlack(const Color& c) {
  return c.x == 0.0f && c.y == 0.0f && c.z == 0.0f;
}
inline bool isFinite(const Color& c) {
  return std::isfinite(c.x) && std::isfinite(c.y) && std::isfinite(c.z);
}
// Rec. 709 luminance of linear RGB.
inline float luminance(const Color& c) {
  return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z;
}

struct Ray {
  Vec3 origin;
  Vec3 dir;  // unit length
  float tMax = kInfinity;
};

// Orthonormal basis around a unit normal (Duff et al. 2017, "Building an Orthonormal Basis,
// Revisited", JCGT 6(1)); branchless and free of the singularity of the classic construction.
struct Frame {
  Vec3 s, t, n;

  Frame() = default;
  explicit Frame(const Vec3& normal) : n(normal) {
    const float sign = std::copysign(1.0f, n.z);
    const float a = -1.0f / (sign + n.z);
    const float b = n.x * n.y * a;
    s = Vec3(1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x);
    t = Vec3(b, sign + n.y * n.y * a, -n.y);
  }
  Vec3 toLocal(const Vec3& v) const { return {glm::dot(v, s), glm::dot(v, t), glm::dot(v, n)}; }
  Vec3 toWorld(const Vec3& v) const { return s * v.x + t * v.y + n * v.z; }
};

}  // namespace ember
