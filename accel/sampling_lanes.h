// Light sampling of many reference points at once (next-event estimation for a whole bounce of a
// wave, packet/wave_integrator.h). A shape's solid-angle sampling runs over up to kMaxLanes
// lanes in Highway vectors (16 floats per AVX-512 register; the widest ISA the CPU has is picked at
// run time). The scalar Shape::sampleSolidAngle of a shape with a lane kernel calls the same kernel
// with one live lane, and a lane's result never depends on the other lanes: one ray or a packet,
// the sample is the same bit for bit (tests/test_sampling_lanes.cpp).
#pragma once

#include "core/math.h"

#include <cstdint>

namespace ember {

// Queries (ref, u) and results (p, n, pdf), structure of arrays; lanes [0, n) are live.
struct SolidAngleLanes {
  static constexpr unsigned kMaxLanes = 16;
  unsigned n = 0;
  alignas(64) float ref[3][kMaxLanes];
  alignas(64) float u[2][kMaxLanes];
  alignas(64) float p[3][kMaxLanes];
  alignas(64) float normal[3][kMaxLanes];
  alignas(64) float pdf[kMaxLanes];  // solid-angle density; 0 where the lane has no sample

  void set(unsigned i, const Vec3& r, Vec2 uu) {
    ref[0][i] = r.x, ref[1][i] = r.y, ref[2][i] = r.z;
    u[0][i] = uu.x, u[1][i] = uu.y;
  }
  // Lanes from `from` up repeat lane 0 (or a point at the origin if there is none): the kernels
  // compute all kMaxLanes, and copies of a live lane never send a block down a branch (the
  // spherical rectangle's) that no live lane needs.
  void padFrom(unsigned from) {
    const Vec3 r = from > 0 ? Vec3(ref[0][0], ref[1][0], ref[2][0]) : Vec3(0.0f);
    const Vec2 uu = from > 0 ? Vec2(u[0][0], u[1][0]) : Vec2(0.5f);
    for (unsigned i = from; i < kMaxLanes; ++i) set(i, r, uu);
  }
  Vec3 point(unsigned i) const { return {p[0][i], p[1][i], p[2][i]}; }
  Vec3 normalAt(unsigned i) const { return {normal[0][i], normal[1][i], normal[2][i]}; }
};

// A quad as its sampling kernel sees it (accel/triangle.h, Quad::sampleSolidAngle):
//  - from within twice its size, a rectangle is sampled uniformly in the solid angle it subtends
//    (Urena, Fajardo and King 2013, accel/spherical_rectangle.h), unless that solid angle is below
//    kMinSphericalRectangle, where the inversion loses float precision;
//  - otherwise uniformly by area (a half picked by area, then PBRT4 eq. A.5.4), converted to solid
//    angle by p_w = p_A d^2 / |cos theta_light| (PBRT4 eq. 4.9).
struct QuadSampling {
  static constexpr float kMinSphericalRectangle = 1e-4f;
  bool rectangle = false;
  Vec3 v[4];
  Vec3 normal{0.0f, 0.0f, 1.0f};
  float area0 = 0.0f, area1 = 0.0f;
  Vec3 center{0.0f};
  // The rectangle's frame: unit edges x (v1 - v0) and y (v3 - v0), z = x cross y, edge lengths.
  Vec3 x{1.0f, 0.0f, 0.0f}, y{0.0f, 1.0f, 0.0f}, z{0.0f, 0.0f, 1.0f};
  float xLength = 0.0f, yLength = 0.0f;

  static QuadSampling of(const Vec3 (&v)[4], bool rectangle, const Vec3& normal, float area0, float area1);
};

// Fills p, normal and pdf of all kMaxLanes lanes of `lanes` (pad the unused ones).
void sampleQuadLanes(const QuadSampling& quad, SolidAngleLanes& lanes);

}  // namespace ember
