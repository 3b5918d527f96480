// The check that Embree may be given a ray (accel/embree_accel.h, traceable), run over a batch's
// packets as vectors just before they are traced, rather than ray by ray as each is written: a
// branch and some thirty scalar instructions per ray (3% of a render) become a few vector
// instructions per packet.
#pragma once

#include <cstddef>

namespace ember {

// The inactive ray, at the origin along +z with the empty interval (1, 0): Embree traces it as
// missing everything and blocked by nothing. The one definition both its writers use: this
// file's kernel, and the ray batches' unused lanes (packet/ray_batch.cpp).
struct InactiveRay {
  static constexpr float kOrigin = 0.0f;  // each coordinate
  static constexpr float kDirX = 0.0f, kDirY = 0.0f, kDirZ = 1.0f;
  static constexpr float kTnear = 1.0f, kTfar = 0.0f;
};

// For each of `packets` packets of `width` rays in Embree's RTCRayN layout (field f of lane i at
// packet[f * width + i]), `stride` floats apart from `first` on: every lane whose ray is not
// traceable becomes the InactiveRay, which misses everything and is blocked by nothing, as
// EmbreeAccel treats such single rays. The other lanes keep their rays bit for bit.
void disableUntraceableRays(float* first, size_t packets, size_t stride, unsigned width);

}  // namespace ember
