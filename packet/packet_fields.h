// Ray packets' fields written from rows (structure of arrays) as whole vector moves. A batch's
// rays are kept in rows by the wave driver and copied into Embree's packets just before each
// trace (ClosestHitBatch::assign): field by field, a packet's 8 or 16 lanes are one row's next 8
// or 16 entries. Written with Highway rather than memcpy, which GCC expanded as `rep movsl` in
// the profile-guided link (3% of a render, `perf annotate` on cornell-area, Zen 4).
#pragma once

#include <cstddef>

namespace ember {

// One field of every packet: lane 0's field lies `field` floats from its packet's start, and lane
// i of packet k takes row[k * width + i], or `value` where row is null. Integer fields pass their
// bits as floats: the copy moves bits and computes nothing.
struct PacketFieldSource {
  size_t field;
  const float* row;
  float value;
};

// Writes the fields of packets [0, ceil(count / width)), `stride` floats apart from `packets` on,
// in packets of `width` rays (8 or 16). The rows are read in whole packets: up to the next
// multiple of width past count.
void fillPacketFields(float* packets, size_t stride, unsigned width, size_t count,
                      const PacketFieldSource* fields, size_t fieldCount);

}  // namespace ember
