// Many rays against one shape at once, for Embree's packet callbacks (accel/user_geometry.cpp):
// Embree hands a user geometry the rays of a 16-wide packet that reached its leaf, with a mask of
// the live ones. A lane filter runs a float version of the shape's test on all of them together
// (Highway vectors, 16 floats per AVX-512 register; the widest ISA the CPU has is picked at run
// time by HWY_DYNAMIC_DISPATCH) and carries a conservative bound on its rounding error, so it
// rejects only rays that certainly miss. The few that may hit are then intersected by the shape's
// scalar, double-precision routine. The flat shapes' kernel also says which rays certainly meet
// the shape inside its edges, farther from them than the rounding error; for those the hit is
// settled without the exact routine (Shape::intersectLanes): its t and barycentrics come from
// the shape's double-precision plane, as accurate as Moller-Trumbore's. Single rays take the same
// route as packets, so both find the same hits bit for bit, and the double-precision routines'
// robustness (no acne, no leaks at grazing angles) serves the rays near edges, where it matters
// (tests/test_shape_lanes.cpp).
//
// Error bounds follow the standard model fl(a op b) = (a op b)(1 + d), |d| <= eps = 2^-24, and
// gamma(n) = n eps / (1 - n eps) for sums and dot products of n terms (Higham 2002, ch. 3;
// PBRT4 section 6.8.1).
#pragma once

#include "core/math.h"

#include <cstdint>

namespace ember {

struct DoublePlane;
struct PlaneCoordinates;

// Up to kMaxLanes rays in Embree's RTCRayN layout: lane i of each array.
struct RayLanes {
  static constexpr unsigned kMaxLanes = 16;
  const float* org[3];
  const float* dir[3];
  const float* tnear;
  const float* tfar;
  const int* valid;  // -1 = live
  unsigned n;
  // Whether the hits' texture coordinates are wanted: not by shadow rays, nor by shapes whose
  // material reads no texture. Without, intersectLanes may leave a hit's uv at (0, 0).
  bool needsUv = true;

  Ray ray(unsigned i) const {
    return Ray{Vec3(org[0][i], org[1][i], org[2][i]), Vec3(dir[0][i], dir[1][i], dir[2][i]), tfar[i]};
  }
};

// What an intersection routine reports: enough to rebuild the full surface record later.
struct LocalHit {
  float t = kInfinity;
  Vec3 ng{0.0f};  // unit geometric normal, outward / front side
  Vec2 uv{0.0f};
};

// The hits of a block of packet lanes (Shape::intersectLanes): bit i of `mask` set when lane i
// hit, with its hit in lane i of the arrays. Structure of arrays, as Embree's RTCHitN is: the
// callback commits a block's hits with vector loads and stores (accel/packet_commit.h), and the
// sphere's kernel writes its t and normals as vectors; other shapes set lanes one by one
// (set, fillFlat). Lanes outside `mask` hold earlier values, never read as hits.
struct LaneHits {
  static constexpr unsigned kLanes = RayLanes::kMaxLanes;
  uint32_t mask = 0;
  alignas(64) float t[kLanes] = {};
  alignas(64) float ng[3][kLanes] = {};
  alignas(64) float uv[2][kLanes] = {};

  void set(unsigned i, const LocalHit& h) {
    t[i] = h.t;
    ng[0][i] = h.ng.x, ng[1][i] = h.ng.y, ng[2][i] = h.ng.z;
    uv[0][i] = h.uv.x, uv[1][i] = h.uv.y;
  }
  LocalHit at(unsigned i) const {
    return LocalHit{t[i], Vec3(ng[0][i], ng[1][i], ng[2][i]), Vec2(uv[0][i], uv[1][i])};
  }
  // Every lane's normal n, and texture coordinates (0, 0): a flat shape's hits, before their t
  // (and, where wanted, uv) are written.
  // With whole-vector stores (a Highway kernel): the callback's commit reads these arrays back
  // as vectors at once, and a load spanning several narrower stores would wait for them to retire.
  // `zeroUv` false: uv is left as it is (a kernel wrote it).
  void fillFlat(const Vec3& n, bool zeroUv = true);
};

// A triangle (v0, v1, v2) as its float filter sees it: the plane dot(n, x) = d, and the dual
// vectors g1, g2 with b1 = dot(p - v0, g1), b2 = dot(p - v0, g2) for a point p of the plane
// (the barycentrics of v1 and v2; Moller-Trumbore's u and v). With `parallelogram` it stands for
// the parallelogram v0 + b1 (v1 - v0) + b2 (v2 - v0), 0 <= b1, b2 <= 1: a quad whose two halves
// it covers exactly, tested once instead of twice.
struct TriangleFilter {
  bool parallelogram = false;
  Vec3 v0{0.0f}, n{0.0f, 0.0f, 1.0f}, g1{0.0f}, g2{0.0f};
  float d = 0.0f;
  float v0Max = 0.0f;  // max |v0_i|
  float g1Sum = 0.0f;  // sum |g1_i|
  float g2Sum = 0.0f;
  float dError = 0.0f;  // bound on |float(d) - d|

  // `plane` is the one the scalar test uses (the plane through the float vertices).
  static TriangleFilter of(const Vec3& v0, const Vec3& v1, const Vec3& v2, const DoublePlane& plane,
                           bool parallelogram = false);
};

// What the triangle kernel found for a block of rays.
struct TriangleLanes {
  // Bit i set: live lane i may hit the triangle (DoublePlane::crossedWithin and intersectTriangle
  // might both succeed); clear: it certainly misses.
  uint32_t candidates = 0;
  // Bit i set: candidate lane i meets the triangle's plane certainly inside the triangle (or
  // parallelogram). The verdict depends on the ray alone, not on its interval (tnear, tfar), so
  // the hit a lane gets does not depend on the order Embree visits the shapes in.
  uint32_t inside = 0;
};

// The lane kernels read RayLanes' arrays in blocks of this many floats (the widest SIMD vector of
// the CPU's Highway target, at most kMaxLanes); the double-precision kernels in blocks of half
// as many doubles. So a RayLanes whose n is a multiple of it may point into arrays of exactly n
// floats; any other n needs arrays of kMaxLanes.
unsigned rayLanesStep();

// Bit i set: lane i is live (valid[i] == -1).
uint32_t liveLanes(const RayLanes& rays);

void triangleLanes(const RayLanes& rays, const TriangleFilter& tri, TriangleLanes& out);

// Bit i set: live lane i may hit the sphere (its discriminant may be >= 0).
uint32_t sphereCandidates(const RayLanes& rays, const Vec3& center, float radius);

// Sphere::intersect of the lanes in `candidates`, all at once in double precision and equal to it
// bit for bit: bit i of the result set when lane i hits, with its t and unit normal in lane i of
// `out` (its uv is left as it was).
uint32_t sphereHits(const RayLanes& rays, const Vec3& center, float radius, uint32_t candidates,
                    LaneHits& out);

// The settled hits of a flat shape (the lanes its kernel found certainly inside), all at once in
// double precision and equal bit for bit to DoublePlane::crossedWithin(ray, tnear, tfar,
// coords.v0, t) and, with `needsCoords`, to coords.at(o + t dir): bit i of the result set when
// lane i of `lanes` crosses the plane within its interval, with float(t) and the coordinates in
// lane i of `out`.
struct PlaneCrossings {
  alignas(64) float t[RayLanes::kMaxLanes];
  alignas(64) float b[2][RayLanes::kMaxLanes];
};
uint32_t planeCrossings(const RayLanes& rays, const DoublePlane& plane, const PlaneCoordinates& coords,
                        uint32_t lanes, bool needsCoords, PlaneCrossings& out);

}  // namespace ember
