#include "accel/triangle.h"

#include <cstring>

#include "accel/spherical_rectangle.h"
#include "accel/spherical_triangle.h"
#include "core/sampling.h"

namespace ember {

bool intersectTriangle(const Ray& ray, const Vec3& v0, const Vec3& v1, const Vec3& v2, float tMin, float tMax,
                       float& t, float& b1, float& b2) {
  const glm::dvec3 e1 = glm::dvec3(v1) - glm::dvec3(v0);
  const glm::dvec3 e2 = glm::dvec3(v2) - glm::dvec3(v0);
  const glm::dvec3 d(ray.dir);
  const glm::dvec3 pvec = glm::cross(d, e2);
  const double det = glm::dot(e1, pvec);
  if (det == 0.0) return false;
  const double invDet = 1.0 / det;
  const glm::dvec3 tvec = glm::dvec3(ray.origin) - glm::dvec3(v0);
  const double u = glm::dot(tvec, pvec) * invDet;
  if (u < 0.0 || u > 1.0) return false;
  const glm::dvec3 qvec = glm::cross(tvec, e1);
  const double v = glm::dot(d, qvec) * invDet;
  if (v < 0.0 || u + v > 1.0) return false;
  const double tt = glm::dot(e2, qvec) * invDet;
  if (tt <= tMin || tt >= tMax) return false;
  t = float(tt);
  b1 = float(u);
  b2 = float(v);
  return true;
}

// The texture coordinates at barycentrics (b1, b2) of the second and third vertex.
static Vec2 uvAt(const Vec2& uv0, const Vec2& uv1, const Vec2& uv2, float b1, float b2) {
  return (1.0f - b1 - b2) * uv0 + b1 * uv1 + b2 * uv2;
}

static void setUv(LaneHits& hits, unsigned i, Vec2 uv) {
  hits.uv[0][i] = uv.x;
  hits.uv[1][i] = uv.y;
}

static Vec3 frontNormal(const Vec3& v0, const Vec3& v1, const Vec3& v2) {
  return glm::normalize(glm::cross(v1 - v0, v2 - v0));
}
static float triangleArea(const Vec3& v0, const Vec3& v1, const Vec3& v2) {
  return 0.5f * glm::length(glm::cross(v1 - v0, v2 - v0));
}

Triangle::Triangle(const std::array<Vec3, 3>& v, const std::array<Vec2, 3>& uv)
    : v_(v),
      uv_(uv),
      normal_(frontNormal(v[0], v[1], v[2])),
      plane_(DoublePlane::through(v[0], v[1], v[2])),
      filter_(TriangleFilter::of(v[0], v[1], v[2], plane_)),
      coords_(PlaneCoordinates::of(v[0], v[1], v[2])),
      area_(triangleArea(v[0], v[1], v[2])) {}

Bounds Triangle::bounds() const {
  Bounds b;
  for (const Vec3& p : v_) b.extend(p);
  return b;
}

bool Triangle::intersect(const Ray& ray, float tMin, float tMax, LocalHit& hit) const {
  float t, b1, b2;
  if (!plane_.crossedWithin(ray, tMin, tMax) ||
      !intersectTriangle(ray, v_[0], v_[1], v_[2], tMin, tMax, t, b1, b2))
    return false;
  hit.t = t;
  hit.ng = normal_;
  hit.uv = uvAt(uv_[0], uv_[1], uv_[2], b1, b2);
  return true;
}

uint32_t Triangle::candidateLanes(const RayLanes& rays) const {
  TriangleLanes lanes;
  triangleLanes(rays, filter_, lanes);
  return lanes.candidates;
}

void Triangle::intersectLanes(const RayLanes& rays, LaneHits& out) const {
  TriangleLanes lanes;
  triangleLanes(rays, filter_, lanes);
  // Certainly inside: the hit is where the ray crosses the plane, and its barycentrics are the
  // crossing point's plane coordinates, both in double as Moller-Trumbore has them.
  PlaneCrossings crossings;
  out.mask = planeCrossings(rays, plane_, coords_, lanes.inside, rays.needsUv, crossings);
  out.fillFlat(normal_);
  for (uint32_t bits = out.mask; bits != 0; bits &= bits - 1) {
    const unsigned i = unsigned(__builtin_ctz(bits));
    out.t[i] = crossings.t[i];
    if (rays.needsUv) setUv(out, i, uvAt(uv_[0], uv_[1], uv_[2], crossings.b[0][i], crossings.b[1][i]));
  }
  intersectEach(lanes.candidates & ~lanes.inside, rays, out);
}

bool Triangle::sampleSolidAngle(const Vec3& ref, Vec2 u, ShapeSample& s, float& pdf) const {
  if (const auto st = sphericalTriangleForSampling(ref, v_[0], v_[1], v_[2], area_)) {
    const Vec2 b = barycentricsAlong(v_[0], v_[1], v_[2], ref, st->sample(u));
    s.p = (1.0f - b.x - b.y) * v_[0] + b.x * v_[1] + b.y * v_[2];
    s.n = normal_;
    pdf = float(1.0 / st->solidAngle());
    return true;
  }
  return Shape::sampleSolidAngle(ref, u, s, pdf);
}

float Triangle::pdfSolidAngle(const Vec3& ref, const Vec3& p, const Vec3& n) const {
  if (const auto st = sphericalTriangleForSampling(ref, v_[0], v_[1], v_[2], area_))
    return float(1.0 / st->solidAngle());
  return Shape::pdfSolidAngle(ref, p, n);
}

ShapeSample Triangle::sampleArea(Vec2 u) const {
  const Vec2 b = sampleUniformTriangle(u);
  return {b.x * v_[0] + b.y * v_[1] + (1.0f - b.x - b.y) * v_[2], normal_};
}

// Parallelogram with a right angle at v0: v2 = v1 + v3 - v0 and (v1 - v0) . (v3 - v0) = 0.
static bool isRectangleQuad(const std::array<Vec3, 4>& v) {
  const Vec3 e1 = v[1] - v[0], e2 = v[3] - v[0];
  const float scale = glm::length(e1) * glm::length(e2);
  return std::abs(glm::dot(e1, e2)) <= 1e-5f * scale &&
         glm::length(v[2] - (v[1] + e2)) <= 1e-5f * std::sqrt(scale);
}

// Solid-angle sampling pays where the light subtends a wide angle: there the 1 / d^2 and cosine
// factors vary across it and area sampling wastes samples. From farther than twice the light's
// size area sampling is nearly as good and far cheaper (no inverse trigonometry), so it is used
// there; the choice depends on the reference point alone. (The sampling kernel and pdfSolidAngle
// evaluate the solid-angle threshold with different float code, so within rounding of it they may
// disagree on the regime; both densities are then nearly equal, and the MIS weights sum to 1
// within that rounding.)
static bool useSphericalRectangle(const Vec3& ref, const Vec3& center, float area) {
  const Vec3 d = ref - center;
  return glm::dot(d, d) < 4.0f * area;
}

Quad::Quad(const std::array<Vec3, 4>& v, const std::array<Vec2, 4>& uv)
    : rectangle_(isRectangleQuad(v)),
      v_(v),
      uv_(uv),
      normal_(frontNormal(v[0], v[1], v[2])),
      planes_{DoublePlane::through(v[0], v[1], v[2]), DoublePlane::through(v[0], v[2], v[3])},
      area0_(triangleArea(v[0], v[1], v[2])),
      area1_(triangleArea(v[0], v[2], v[3])) {
  // A degenerate half (a quad given as a triangle, v3 = v0) has no plane of its own.
  if (!(area1_ > 0.0f)) planes_[1] = planes_[0];
  if (!(area0_ > 0.0f)) planes_[0] = planes_[1];
  // Bit for bit (+0 and -0 differ), so that skipping the side test never changes a projection.
  samePlanes_ = std::memcmp(&planes_[0], &planes_[1], sizeof(DoublePlane)) == 0;
  // An exact parallelogram (v2 = v1 + v3 - v0, which double evaluates without rounding) whose
  // halves lie in planes agreeing far below the filter's float tolerance is filtered in one test.
  const glm::dvec3 opposite = glm::dvec3(v[1]) + glm::dvec3(v[3]) - glm::dvec3(v[0]);
  singleFilter_ = opposite == glm::dvec3(v[2]) && area0_ > 0.0f && area1_ > 0.0f &&
                  glm::length(planes_[0].n - planes_[1].n) < 1e-12 &&
                  std::abs(planes_[0].d - planes_[1].d) < 1e-12 * (1.0 + std::abs(planes_[0].d));
  const Vec3 corners[4] = {v[0], v[1], v[2], v[3]};
  sampling_ = QuadSampling::of(corners, rectangle_, normal_, area0_, area1_);
  if (singleFilter_) {
    filters_[0] = filters_[1] = TriangleFilter::of(v[0], v[1], v[3], planes_[0], true);
    axisAligned_ = AxisRectangle::of(v[0], v[1], v[2], v[3], axisRectangle_);
    coords_[0] = coords_[1] = PlaneCoordinates::of(v[0], v[1], v[3]);
  } else {
    filters_[0] = TriangleFilter::of(v[0], v[1], v[2], planes_[0]);
    filters_[1] = TriangleFilter::of(v[0], v[2], v[3], planes_[1]);
    coords_[0] = PlaneCoordinates::of(v[0], v[1], v[2]);
    coords_[1] = PlaneCoordinates::of(v[0], v[2], v[3]);
  }
}

Bounds Quad::bounds() const {
  Bounds b;
  for (const Vec3& p : v_) b.extend(p);
  return b;
}

bool Quad::intersectHalf(int half, const Ray& ray, float tMin, float tMax, LocalHit& hit) const {
  const Vec3& a = v_[half == 0 ? 1 : 2];
  const Vec3& b = v_[half == 0 ? 2 : 3];
  float t, b1, b2;
  if (!planes_[half].crossedWithin(ray, tMin, tMax) ||
      !intersectTriangle(ray, v_[0], a, b, tMin, tMax, t, b1, b2))
    return false;
  hit.t = t;
  hit.ng = normal_;
  hit.uv = uvAt(uv_[0], uv_[half == 0 ? 1 : 2], uv_[half == 0 ? 2 : 3], b1, b2);
  return true;
}

// A quad that is not an exact parallelogram may be folded along v0-v2 (its vertices need only
// be coplanar to 1e-4 of its size), so a ray near grazing can cross both halves: the closer wins.
bool Quad::intersect(const Ray& ray, float tMin, float tMax, LocalHit& hit) const {
  if (axisAligned_) {
    RectangleCrossing crossing;
    if (!axisRectangle_.cross(ray, tMin, tMax, crossing)) return false;
    hit = LocalHit{crossing.t, normal_, rectangleUv(crossing.a, crossing.b)};
    return true;
  }
  if (!intersectHalf(0, ray, tMin, tMax, hit)) return intersectHalf(1, ray, tMin, tMax, hit);
  LocalHit second;
  if (!singleFilter_ && intersectHalf(1, ray, tMin, hit.t, second)) hit = second;
  return true;
}

bool Quad::settledHit(int half, const Ray& ray, float tMin, float tMax, bool needsUv, LocalHit& hit) const {
  double t;
  if (!planes_[half].crossedWithin(ray, tMin, tMax, coords_[half].v0, t)) return false;
  hit.t = float(t);
  hit.ng = normal_;
  hit.uv = Vec2(0.0f);
  if (!needsUv) return true;
  const Vec2 b = coords_[half].at(glm::dvec3(ray.origin) + t * glm::dvec3(ray.dir));
  hit.uv = singleFilter_ ? parallelogramUv(b)
                         : uvAt(uv_[0], uv_[half == 0 ? 1 : 2], uv_[half == 0 ? 2 : 3], b.x, b.y);
  return true;
}

// The UV of an axis-aligned rectangle's crossing at coordinates (a, b), for intersect();
// intersectLanes() has the rectangle kernel compute the same (axisRectangleLanes in
// accel/quadric_lanes.cpp), held to this bit for bit by tests/test_shape_lanes.cpp.
Vec2 Quad::rectangleUv(float a, float b) const {
  return parallelogramUv(axisRectangle_.edgeCoordinates(a, b));
}

Vec2 Quad::parallelogramUv(Vec2 b) const {
  // (s, r) = b are the parallelogram's coordinates along v1 - v0 and v3 - v0. The half
  // (v0, v1, v2) is s >= r, with barycentrics (s - r, r); the other has (s, r - s).
  const int half = b.x >= b.y ? 0 : 1;
  b = half == 0 ? Vec2(b.x - b.y, b.y) : Vec2(b.x, b.y - b.x);
  return uvAt(uv_[0], uv_[half == 0 ? 1 : 2], uv_[half == 0 ? 2 : 3], b.x, b.y);
}

// A half without area (a quad given as a triangle) is never hit; its filter, with NaN dual
// vectors, would keep every lane.
void Quad::halfLanes(int half, const RayLanes& rays, TriangleLanes& out) const {
  if (!((half == 0 ? area0_ : area1_) > 0.0f)) {
    out.candidates = out.inside = 0;
    return;
  }
  triangleLanes(rays, filters_[half], out);
}

uint32_t Quad::candidateLanes(const RayLanes& rays) const {
  if (axisAligned_) {
    return axisRectangleCrossings(rays, axisRectangle_, Shape::candidateLanes(rays));
  }
  TriangleLanes lanes;
  halfLanes(0, rays, lanes);
  if (singleFilter_) return lanes.candidates;
  const uint32_t first = lanes.candidates;
  halfLanes(1, rays, lanes);
  return first | lanes.candidates;
}

// Each half is settled by its kernel where the kernel is certain, and tested exactly where not;
// as in intersect(), the closer half wins when both are hit.
void Quad::intersectLanes(const RayLanes& rays, LaneHits& out) const {
  if (axisAligned_) {
    // Every live lane through the rectangle's test at once: a ray that reaches an axis-aligned
    // rectangle's bounding box has crossed its plane within its bounds, so it nearly always hits.
    // Their texture coordinates too, in the kernel (rectangleUv for every lane at once).
    out.mask = rays.needsUv ? axisRectangleHits(rays, axisRectangle_, out.t, uv_.data(), out.uv[0], out.uv[1])
                            : axisRectangleHits(rays, axisRectangle_, out.t);
    if (out.mask != 0) out.fillFlat(normal_, !rays.needsUv);
    return;
  }
  out.mask = 0;
  TriangleLanes first;
  halfLanes(0, rays, first);
  if (singleFilter_) {
    // The settled lanes at once (settledHit's crossing and coordinates in one kernel), the
    // others by the exact test.
    PlaneCrossings crossings;
    out.mask = planeCrossings(rays, planes_[0], coords_[0], first.inside, rays.needsUv, crossings);
    out.fillFlat(normal_);
    for (uint32_t bits = out.mask; bits != 0; bits &= bits - 1) {
      const unsigned i = unsigned(__builtin_ctz(bits));
      out.t[i] = crossings.t[i];
      if (rays.needsUv) setUv(out, i, parallelogramUv(Vec2(crossings.b[0][i], crossings.b[1][i])));
    }
    intersectEach(first.candidates & ~first.inside, rays, out);
    return;
  }
  TriangleLanes second;
  halfLanes(1, rays, second);
  for (uint32_t bits = first.candidates | second.candidates; bits != 0; bits &= bits - 1) {
    const unsigned i = unsigned(__builtin_ctz(bits));
    const uint32_t bit = 1u << i;
    const Ray ray = rays.ray(i);
    const float tMin = rays.tnear[i];
    LocalHit h;
    auto half = [&](int k, const TriangleLanes& lanes, float tMax, LocalHit& hit) {
      if (!(lanes.candidates & bit)) return false;
      if (lanes.inside & bit) return settledHit(k, ray, tMin, tMax, rays.needsUv, hit);
      return intersectHalf(k, ray, tMin, tMax, hit);
    };
    LocalHit other;
    if (half(0, first, ray.tMax, h)) {
      if (half(1, second, h.t, other)) h = other;
    } else if (!half(1, second, ray.tMax, h)) {
      continue;
    }
    out.set(i, h);
    out.mask |= bit;
  }
}

SurfacePoint Quad::projectToSurface(const Vec3& p, const LocalHit&) const {
  if (axisAligned_) {
    // DoublePlane::project's arithmetic where the plane's normal is an axis (its other
    // components are zeros, and its length one, exactly): only that coordinate moves. The
    // point equals the general projection's up to the sign of a zero coordinate (which the
    // general form can turn from -0 to +0).
    // Coordinate by coordinate: GCC kept a double vector indexed by k on the stack, and its wide
    // reload after the narrow store of coordinate k stalled on store-to-load forwarding (`perf
    // annotate`, an AVX-512 Xeon). The other coordinates round-trip through double unchanged.
    const double c = double(axisRectangle_.c);
    const auto onPlane = [c](float x) { return float(double(x) - (double(x) - c)); };
    switch (axisRectangle_.axis) {
      case 0:
        return roundedPoint(onPlane(p.x), p.y, p.z);
      case 1:
        return roundedPoint(p.x, onPlane(p.y), p.z);
      default:
        return roundedPoint(p.x, p.y, onPlane(p.z));
    }
  }
  if (samePlanes_) return planes_[0].project(p);
  // The diagonal v0-v2 separates the halves: v1 lies on one side of it, v3 on the other.
  const bool firstHalf = glm::dot(glm::cross(v_[2] - v_[0], p - v_[0]), normal_) <= 0.0f;
  return planes_[firstHalf ? 0 : 1].project(p);
}

// One live lane of the lane kernel, so that a single ray and a packet get the same sample.
bool Quad::sampleSolidAngle(const Vec3& ref, Vec2 u, ShapeSample& s, float& pdf) const {
  SolidAngleLanes lanes;
  lanes.n = 1;
  lanes.set(0, ref, u);
  lanes.padFrom(1);
  sampleQuadLanes(sampling_, lanes);
  s = {lanes.point(0), lanes.normalAt(0)};
  pdf = lanes.pdf[0];
  return pdf > 0.0f;
}

float Quad::pdfSolidAngle(const Vec3& ref, const Vec3& p, const Vec3& n) const {
  if (rectangle_ && useSphericalRectangle(ref, 0.5f * (v_[0] + v_[2]), area())) {
    const SphericalRectangle sr(v_[0], v_[1] - v_[0], v_[3] - v_[0], ref);
    if (sr.solidAngle() > QuadSampling::kMinSphericalRectangle) return 1.0f / sr.solidAngle();
  }
  return Shape::pdfSolidAngle(ref, p, n);
}

ShapeSample Quad::sampleArea(Vec2 u) const {
  // Pick a triangle by area, then reuse the remainder of u.x.
  const float total = area0_ + area1_;
  const float pick = u.x * total;
  const bool first = pick < area0_;
  const float ux = first ? pick / area0_ : (pick - area0_) / area1_;
  const Vec2 b = sampleUniformTriangle(Vec2(std::min(ux, 0.99999994f), u.y));
  const Vec3& a = v_[0];
  const Vec3& p1 = first ? v_[1] : v_[2];
  const Vec3& p2 = first ? v_[2] : v_[3];
  return {b.x * a + b.y * p1 + (1.0f - b.x - b.y) * p2, normal_};
}

}  // namespace ember

namespace ember {

namespace {

// sqrt(UV area / area) of a triangle: its texture coordinates per unit of length.
float uvDensityOf(Vec2 a, Vec2 b, Vec2 c, float area) {
  const Vec2 du = b - a, dv = c - a;
  const float uvArea = 0.5f * std::abs(du.x * dv.y - du.y * dv.x);
  return area > 0.0f && std::isfinite(uvArea) ? std::sqrt(uvArea / area) : 0.0f;
}

}  // namespace

float Triangle::uvDensity() const {
  return uvDensityOf(uv_[0], uv_[1], uv_[2], area_);
}

float Quad::uvDensity() const {
  // The two halves' UV areas over their areas together.
  const float d0 = uvDensityOf(uv_[0], uv_[1], uv_[2], area0_),
              d1 = uvDensityOf(uv_[0], uv_[2], uv_[3], area1_);
  const float area = area0_ + area1_;
  return area > 0.0f ? std::sqrt((d0 * d0 * area0_ + d1 * d1 * area1_) / area) : 0.0f;
}

}  // namespace ember
