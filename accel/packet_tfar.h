// The intersect callback's two passes over a 16-ray packet's tfar (accel/user_geometry.cpp), as
// vectors. Embree writes a packet's tfar with vector stores, and the lane filters read it with
// vector loads; the callback's lane-by-lane loads and stores between them made each vector load
// wait on narrow stores it could not forward from (`perf annotate`: most of the callback's 10% of
// a render). Each function does, lane for lane, what the scalar loop it replaces did.
#pragma once

namespace ember {

constexpr unsigned kPacketTfarLanes = 16;

// saved[i] = tfar[i] for every lane; then each live lane's (valid[i] != 0) tfar moves one float
// up, except +infinity, which stays.
void widenLiveTfar16(float* tfar, const int* valid, float* saved);

// tfar[i] = result[i] for each live lane; the others keep theirs.
void storeLiveTfar16(float* tfar, const int* valid, const float* result);

}  // namespace ember
