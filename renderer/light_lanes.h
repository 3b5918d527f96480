// The directions of a block of area-light samples (AreaLight::sampleLanes, a bounce's light
// queries in a wave): from each lane's reference point to its sampled point, in Highway vectors
// (16 floats per AVX-512 register), with AreaLight::fromShapeSample's float operations in their
// order (both files are compiled without fused multiply-adds), so each lane equals the scalar
// light sample bit for bit.
#pragma once

#include "accel/sampling_lanes.h"
#include "core/math.h"

#include <cstdint>

namespace ember {

struct LightDirectionLanes {
  alignas(64) float wi[3][SolidAngleLanes::kMaxLanes];  // (p - ref) / dist
  alignas(64) float dist[SolidAngleLanes::kMaxLanes];   // |p - ref|
  uint32_t facing = 0;  // bit i: the sampled point's normal faces lane i's reference point
};

// For every lane of `lanes` (all kMaxLanes: pad the unused ones, as the sampling kernels need).
void lightDirectionLanes(const SolidAngleLanes& lanes, LightDirectionLanes& out);

// Light samples kept as rows (structure of arrays) at the caller's own indices, LightSample's
// fields one row each: the packet integrator's next-event rows (packet/next_event_lanes.h).
struct LightSampleRows {
  float* p[3];
  float* n[3];
  float* wi[3];
  float* Li[3];
  float* pError;
  float* pdf;
  int32_t* delta;     // 0: an area light's sample is never a delta
  int32_t* infinite;  // -1 where the distance is not finite
  // -1: the light is a point light at p with intensity Li, whose sample the next-event kernel
  // takes itself (PointLight::sampleRun); wi, pdf and delta are then not read.
  int32_t* pointLight;
};

// How far behind the plane (beyond the margin) a reference point must lie, per unit of its
// largest coordinate, to count as clearly behind: clearlyBehind in renderer/light.h and the
// lanes of loadSolidAngleRows.
inline constexpr float kClearlyBehindPerMagnitude = 1e-5f;

// The plane of a one-sided flat emitter, behind which a reference point sees only its back
// (clearlyBehind in renderer/light.h).
struct BackPlane {
  Vec3 point, normal;
  float margin;
};

// Fills all kMaxLanes lanes from rows [first, first + kMaxLanes): the reference points from
// refRows, the numbers from us. Returns bit i set where lane i's point is not clearly behind
// `back` (every bit when back is null); the other lanes get a copy of the lowest live lane, as
// SolidAngleLanes::padFrom pads. No bit set: the lanes are left as loaded.
uint32_t loadSolidAngleRows(const float* const refRows[3], const Vec2* us, size_t first,
                            const BackPlane* back, SolidAngleLanes& lanes);

// AreaLight::fillSample of each `live` lane whose sample exists (pdf > 0 and a non-zero distance),
// stored into `rows` at first + lane, with the directions of lightDirectionLanes; the rows of the
// other lanes keep their values (targets without masked stores read and write them back).
void storeLightSampleRows(const SolidAngleLanes& lanes, uint32_t live, const Color& radiance, bool twoSided,
                          float pError, const LightSampleRows& rows, size_t first);

}  // namespace ember
