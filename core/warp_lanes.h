// Sampling warps over lanes: the same warp for up to kMaxLanes inputs at once, in Highway vectors
// (the widest ISA the CPU has, picked at run time). A material's scalar sample() calls the kernel
// with one live lane, so one vertex and a wave of them get the same directions bit for bit; a
// lane's result never depends on the other lanes (tests/test_sampling_lanes.cpp).
#pragma once

#include "core/math.h"

namespace ember {

// Cosine-weighted directions about per-lane unit normals: Malley's method over the Shirley-Chiu
// concentric map (PBRT4 eq. A.5.1, core/sampling.h), turned into the frame of Duff et al. 2017
// (core/math.h, Frame). pdf = cos(theta) / pi, 0 where the lane has no direction.
struct CosineLanes {
  // Four AVX-512 vectors: a material's run of vertices fills them with scalar stores, and a
  // kernel's first vector loads would wait for the latest of those stores to retire (a load
  // cannot take its data from several narrower stores); in blocks of 64 the first block's stores
  // have retired by the time the kernel reads it, and one dispatch serves four vectors.
  static constexpr unsigned kMaxLanes = 64;
  // The kernel computes whole groups of this many lanes (the widest vector's float lanes).
  static constexpr unsigned kGroup = 16;
  alignas(64) float normal[3][kMaxLanes];
  alignas(64) float u[2][kMaxLanes];
  alignas(64) float wi[3][kMaxLanes];
  alignas(64) float pdf[kMaxLanes];

  void set(unsigned i, const Vec3& n, Vec2 uu) {
    normal[0][i] = n.x, normal[1][i] = n.y, normal[2][i] = n.z;
    u[0][i] = uu.x, u[1][i] = uu.y;
  }
  // The lanes from `from` to the end of its group get harmless inputs; returns that end, the
  // number of lanes sampleCosineLanes is to compute.
  unsigned padFrom(unsigned from) {
    const unsigned end = (from + kGroup - 1) / kGroup * kGroup;
    for (unsigned i = from; i < end; ++i) set(i, Vec3(0.0f, 0.0f, 1.0f), Vec2(0.5f));
    return end;
  }
  Vec3 direction(unsigned i) const { return {wi[0][i], wi[1][i], wi[2][i]}; }
};

// Computes wi and pdf of lanes [0, count), count a multiple of CosineLanes::kGroup up to kMaxLanes.
void sampleCosineLanes(CosineLanes& lanes, unsigned count = CosineLanes::kMaxLanes);

}  // namespace ember
