// The intersect callback's last step (accel/user_geometry.cpp): a block of a shape's hits kept
// where they are nearer than the packet's current ones, and written into Embree's hit arrays.
// Lane by lane, each candidate hit took a data-dependent branch and its eight fields were stored
// one by one; here a block's lanes are compared and written as vectors, each lane exactly as the
// scalar rule decides it. callgrind: about as many instructions as before, a quarter to a third
// fewer mispredicted branches in the render loop (docs/performance.md, twelfth session).
#pragma once

#include "accel/shape_lanes.h"

#include <embree3/rtcore.h>

#include <cstdint>

namespace ember {

// For each lane i < n of hits.mask: the hit is kept when hits.t[i] <= tfar[i], except that a hit
// at exactly tfar[i] is kept only over a current hit of a larger geometry ID (so that ties do not
// depend on the order Embree visits the shapes in; a lane without a hit has tfar at its ray's
// open end). A kept hit sets tfar[i] = hits.t[i] and writes its normal, uv and the IDs into
// lane first + i of `packet`, Embree's hit arrays of a packet of `width` rays (first + n <=
// width). tfar holds the block's lanes [0, n) (the packet's own tfar, offset to the block's first
// lane, not the widened copy the shapes saw); n <= kMaxLanes, and mask bits at or past n are
// ignored.
void commitLaneHits(const LaneHits& hits, unsigned n, float* tfar, RTCHitN* packet, unsigned width,
                    unsigned first, uint32_t primID, uint32_t geomID, uint32_t instID);

}  // namespace ember
