// Uniform sampling of the solid angle a rectangle subtends: Urena, Fajardo and King 2013, "An
// Area-Preserving Parametrization for Spherical Rectangles" (EGSR), section 4. Every direction in
// the rectangle's solid angle is equally likely (pdf = 1 / solid angle), which removes the 1 / d^2
// and cosine variation that area sampling leaves in next-event estimation close to a light.
#pragma once

#include "core/math.h"

namespace ember {

class SphericalRectangle {
 public:
  // corner s, orthogonal edges ex and ey, seen from o.
  SphericalRectangle(const Vec3& s, const Vec3& ex, const Vec3& ey, const Vec3& o);

  float solidAngle() const { return solidAngle_; }
  // The point of the rectangle in the direction given by u, uniform in solid angle.
  Vec3 sample(Vec2 u) const;

 private:
  Vec3 o_, x_, y_, z_;
  float z0_, x0_, y0_, x1_, y1_;
  float b0_, b1_, k_;
  float solidAngle_ = 0.0f;
};

}  // namespace ember
