#include "accel/box.h"

namespace ember {

Box::Box(const Vec3& center, const Vec3& size, const glm::mat3& rotation)
    : center_(center), half_(0.5f * size), rotation_(rotation) {
  slab_.center = glm::dvec3(center_);
  for (int k = 0; k < 3; ++k) slab_.axes[k] = glm::dvec3(rotation_[k]);
  slab_.half = glm::dvec3(half_);
}

Bounds Box::bounds() const {
  Bounds b;
  for (int i = 0; i < 8; ++i) {
    const Vec3 corner((i & 1) ? half_.x : -half_.x, (i & 2) ? half_.y : -half_.y,
                      (i & 4) ? half_.z : -half_.z);
    b.extend(center_ + rotation_ * corner);
  }
  return b;
}

// UV of a point on face `axis` (0, 1, 2 = x, y, z) from the other two local coordinates.
static Vec2 faceUv(const glm::dvec3& local, const Vec3& half, int axis) {
  const int a = (axis + 1) % 3, b = (axis + 2) % 3;
  return Vec2(float(0.5 + 0.5 * local[a] / half[a]), float(0.5 + 0.5 * local[b] / half[b]));
}

LocalHit Box::faceHit(const BoxCrossing& crossing) const {
  Vec3 nLocal(0.0f);
  nLocal[crossing.axis] = crossing.local[crossing.axis] > 0.0 ? 1.0f : -1.0f;
  LocalHit hit;
  hit.t = float(crossing.t);
  hit.ng = rotation_ * nLocal;
  hit.uv = faceUv(crossing.local, half_, crossing.axis);
  return hit;
}

bool Box::intersect(const Ray& ray, float tMin, float tMax, LocalHit& hit) const {
  BoxCrossing crossing;
  if (!slab_.cross(ray, tMin, tMax, crossing)) return false;
  hit = faceHit(crossing);
  return true;
}

void Box::intersectLanes(const RayLanes& rays, LaneHits& out) const {
  BoxLanes crossings;
  out.mask = boxCrossings(rays, slab_, candidateLanes(rays), crossings);
  for (uint32_t bits = out.mask; bits != 0; bits &= bits - 1) {
    const unsigned i = unsigned(__builtin_ctz(bits));
    const glm::dvec3 local(crossings.local[0][i], crossings.local[1][i], crossings.local[2][i]);
    out.set(i, faceHit({crossings.t[i], local, int(crossings.axis[i])}));
  }
}

SurfacePoint Box::projectToSurface(const Vec3& p, const LocalHit& hit) const {
  const glm::dmat3 rotation(rotation_);
  const glm::dvec3 nLocal = glm::transpose(rotation) * glm::dvec3(hit.ng);
  glm::dvec3 local = glm::transpose(rotation) * (glm::dvec3(p) - glm::dvec3(center_));
  int axis = 0;
  for (int i = 1; i < 3; ++i)
    if (std::abs(nLocal[i]) > std::abs(nLocal[axis])) axis = i;
  local[axis] = std::copysign(double(half_[axis]), nLocal[axis]);
  // Off the face's edges, where the neighbouring faces begin.
  const float margin = edgeMargin(roundedPoint(glm::dvec3(p), 2.0f * maxComponent(half_)));
  for (int i = 0; i < 3; ++i)
    if (i != axis && half_[i] > 2.0f * margin)
      local[i] = std::clamp(local[i], -double(half_[i] - margin), double(half_[i] - margin));
  // The float rotation is orthonormal to ~1e-7, so the face is known to that fraction of the box.
  return roundedPoint(glm::dvec3(center_) + rotation * local, 2.0f * maxComponent(half_));
}

float Box::area() const {
  return 8.0f * (half_.x * half_.y + half_.y * half_.z + half_.z * half_.x);
}

ShapeSample Box::sampleArea(Vec2 u) const {
  // Choose one of the six faces by area, then a uniform point on it.
  const float faceArea[3] = {4.0f * half_.y * half_.z, 4.0f * half_.z * half_.x, 4.0f * half_.x * half_.y};
  float pick = u.x * 2.0f * (faceArea[0] + faceArea[1] + faceArea[2]);
  int face = 0;
  while (face < 5 && pick >= faceArea[face / 2]) {
    pick -= faceArea[face / 2];
    ++face;
  }
  const int axis = face / 2;
  const float sign = (face % 2) ? 1.0f : -1.0f;
  const float ua = std::min(pick / faceArea[axis], 1.0f);
  const int a = (axis + 1) % 3, b = (axis + 2) % 3;
  Vec3 local(0.0f), nLocal(0.0f);
  local[axis] = sign * half_[axis];
  local[a] = (2.0f * ua - 1.0f) * half_[a];
  local[b] = (2.0f * u.y - 1.0f) * half_[b];
  nLocal[axis] = sign;
  return {center_ + rotation_ * local, rotation_ * nLocal};
}

}  // namespace ember
