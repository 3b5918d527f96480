// The intersect callback's two passes over a packet's tfar (accel/user_geometry.cpp), as vectors.
// Embree writes a packet's tfar with vector stores, and the lane filters read it with vector
// loads; the callback's lane-by-lane loads and stores between them made each vector load wait on
// narrow stores it could not forward from (`perf annotate`: most of the callback's 10% of a
// render). Each function does, lane for lane, what the scalar loop it replaces did: whole vectors
// first, then the lanes past the last whole vector one by one (a single ray, or an 8-ray packet
// on a CPU whose vectors hold 16 floats).
#pragma once

#include <bit>
#include <cstdint>
#include <limits>

namespace ember {

// The most lanes a packet has (Embree calls the callbacks with 16, 8, 4 or 1 rays).
constexpr unsigned kPacketTfarLanes = 16;

// The next float above a ray's tfar (positive, or +infinity, which stays): what the callback
// shows the shapes. The tests and the kernels' tails use it; the kernels do the same.
inline float nextFloatUp(float x) {
  return x < std::numeric_limits<float>::infinity() ? std::bit_cast<float>(std::bit_cast<uint32_t>(x) + 1u)
                                                    : x;
}

// For lanes [0, n), n <= kPacketTfarLanes: saved[i] = tfar[i]; then each live lane's
// (valid[i] != 0) tfar moves one float up, except +infinity, which stays.
void widenLiveTfar(float* tfar, const int* valid, float* saved, unsigned n);

// For lanes [0, n): tfar[i] = result[i] for each live lane; the others keep theirs.
void storeLiveTfar(float* tfar, const int* valid, const float* result, unsigned n);

}  // namespace ember
