// The directions of a block of area-light samples (AreaLight::sampleLanes, a bounce's light
// queries in a wave): from each lane's reference point to its sampled point, in Highway vectors
// (16 floats per AVX-512 register), with AreaLight::fromShapeSample's float operations in their
// order (both files are compiled without fused multiply-adds), so each lane equals the scalar
// light sample bit for bit.
#pragma once

#include "accel/sampling_lanes.h"

#include <cstdint>

namespace ember {

struct LightDirectionLanes {
  alignas(64) float wi[3][SolidAngleLanes::kMaxLanes];  // (p - ref) / dist
  alignas(64) float dist[SolidAngleLanes::kMaxLanes];   // |p - ref|
  uint32_t facing = 0;  // bit i: the sampled point's normal faces lane i's reference point
};

// For every lane of `lanes` (all kMaxLanes: pad the unused ones, as the sampling kernels need).
void lightDirectionLanes(const SolidAngleLanes& lanes, LightDirectionLanes& out);

}  // namespace ember
