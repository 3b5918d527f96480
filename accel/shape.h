// The interface every analytic shape implements. Shapes are exact (no tessellation): Embree calls
// them through user-geometry callbacks (accel/user_geometry.cpp), and lights sample them
// (AreaLight in renderer/light.cpp). A closed shape's normal points outwards; an open shape's normal is its
// "front" side, the side an emitting shape emits on.
#pragma once

#include "renderer/math.h"

#include <string_view>

namespace ember {

struct Bounds {
  Vec3 lower{kInfinity};
  Vec3 upper{-kInfinity};

  void extend(const Vec3& p) {
    lower = glm::min(lower, p);
    upper = glm::max(upper, p);
  }
  void extend(const Bounds& b) {
    lower = glm::min(lower, b.lower);
    upper = glm::max(upper, b.upper);
  }
  bool empty() const { return lower.x > upper.x; }
};

// What an intersection routine reports: enough to rebuild the full surface record later.
struct LocalHit {
  float t = kInfinity;
  Vec3 ng{0.0f};  // unit geometric normal, outward / front side
  Vec2 uv{0.0f};
};

// A point on a shape's surface, chosen by a light-sampling routine.
struct ShapeSample {
  Vec3 p;
  Vec3 n;  // unit geometric normal at p (outward / front side)
};

class Shape {
 public:
  virtual ~Shape() = default;

  virtual std::string_view typeName() const = 0;
  virtual Bounds bounds() const = 0;

  // Closest hit with t in (tMin, tMax); false when there is none.
  virtual bool intersect(const Ray& ray, float tMin, float tMax, LocalHit& hit) const = 0;

  // Shading normal at a hit point; equal to the geometric normal for every shape Ember has.
  virtual Vec3 shadingNormal(const Vec3& /*p*/, const LocalHit& hit) const { return hit.ng; }

  virtual float area() const = 0;

  // A point distributed uniformly by area over the whole surface (density 1 / area()).
  virtual ShapeSample sampleArea(Vec2 u) const = 0;

  // A point seen from `ref`, with its density per unit solid angle at `ref`. The default converts
  // area sampling (PBRT4 eq. 4.9: p_w = p_A d^2 / |cos theta_light|); shapes with a better
  // strategy (the sphere's cone of directions) override both functions together.
  virtual bool sampleSolidAngle(const Vec3& ref, Vec2 u, ShapeSample& s, float& pdf) const;
  virtual float pdfSolidAngle(const Vec3& ref, const Vec3& p, const Vec3& n) const;
};

// Converts a density per unit area at p (normal n) into one per unit solid angle seen from ref.
float areaToSolidAnglePdf(float pdfArea, const Vec3& ref, const Vec3& p, const Vec3& n);

}  // namespace ember
