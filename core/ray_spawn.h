// How rays leave surfaces. Every point a ray starts from or aims at was computed in float, so it
// lies off its surface by up to a small rounding error; a ray that ignored this would hit the
// surface it leaves (acne) or the emitter it aims at (light lost next to curved lights). The
// bounds follow PBRT4 section 6.8: a point computed from float data of magnitude m is within a
// few ulps of m of the exact point, so pushing it off its surface by roundingErrorBound(m) along
// the normal puts it strictly on the side the ray travels to.
#pragma once

#include "core/math.h"

#include <cstdint>

namespace ember {

// Bound on the float rounding error of a point computed from data whose magnitude is at most `m`:
// about 17 ulps of m, plus an absolute floor for points at the origin. The lane kernels take the
// same bound from core/ray_spawn-inl.h.
inline constexpr float kRoundingErrorPerMagnitude = 2e-6f;
inline constexpr float kRoundingErrorFloor = 1e-7f;
inline float roundingErrorBound(float m) {
  return kRoundingErrorPerMagnitude * m + kRoundingErrorFloor;
}

// `p` pushed along the normal `n` by `error` to the side `dir` points to (Woo et al. 1996): large
// enough to escape self-intersection, small enough not to cross a neighbouring face near an acute
// edge (a cone's rim). A zero normal (a point light) leaves p where it is.
// Every Embree mask bit: the mask of a ray that skips no geometry. Rays leaving a surface or aimed
// at a light may leave out the bit of a shape they cannot meet (SurfaceHit::maskFor,
// Light::shadowMask), and Embree then skips that shape.
inline constexpr uint32_t kAllRayMask = 0xFFFFFFFFu;

// The side: whether `dir` leaves to the side n points to. Every caller that also needs the side
// (SurfaceHit's ray masks) takes it from here, so that the two can never round differently.
inline bool frontSide(const Vec3& n, const Vec3& dir) {
  return glm::dot(dir, n) >= 0.0f;
}
inline Vec3 offsetAlongNormal(const Vec3& p, const Vec3& n, float error, bool front) {
  return p + (front ? error : -error) * n;
}
inline Vec3 offsetAlongNormal(const Vec3& p, const Vec3& n, float error, const Vec3& dir) {
  return offsetAlongNormal(p, n, error, frontSide(n, dir));
}

// A ray along the segment between two points on surfaces, each given with its unit normal (zero
// for a point light) and its rounding-error bound, for a shadow ray that must report blockers
// between the two but neither surface itself. Both ends are pushed off their surfaces towards each
// other, the direction is taken between the pushed points, and the ray stops short of the far
// end by the far point's error plus the rounding of the ray itself (its direction and length are
// rounded to float, which moves its end by a few ulps of the length). No shape needs a case of its
// own: the segment ends in the open half-space in front of the target's tangent plane, which a
// convex emitter never enters, and a flat one only at the far end's offset.
// Returns a ray with tMax = 0 when the two points coincide. `fromFront`: the side of nFrom to push
// the origin to, frontSide(nFrom, to - from), given by a caller that needs it too.
inline Ray spawnRayTo(const Vec3& from, const Vec3& nFrom, float errorFrom, const Vec3& to, const Vec3& nTo,
                      float errorTo, bool fromFront) {
  const Vec3 d = to - from;
  const Vec3 origin = offsetAlongNormal(from, nFrom, errorFrom, fromFront);
  const Vec3 target = offsetAlongNormal(to, nTo, errorTo, -d);
  const Vec3 segment = target - origin;
  const float length = glm::length(segment);
  if (!(length > 0.0f)) return Ray{origin, Vec3(0.0f, 0.0f, 1.0f), 0.0f};
  const float stopShort = errorTo + roundingErrorBound(length);
  return Ray{origin, segment / length, std::max(0.0f, length - stopShort)};
}
inline Ray spawnRayTo(const Vec3& from, const Vec3& nFrom, float errorFrom, const Vec3& to, const Vec3& nTo,
                      float errorTo) {
  return spawnRayTo(from, nFrom, errorFrom, to, nTo, errorTo, frontSide(nFrom, to - from));
}

}  // namespace ember
