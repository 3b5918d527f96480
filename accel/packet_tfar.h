// The tfar the intersect callback shows the shapes (accel/user_geometry.cpp): each live ray's
// tfar one float step up, as a vector pass into the callback's own array. The shapes read it in
// place of the packet's tfar, and the callback commits their hits into the packet's, which is
// never widened and so needs no pass restoring it. (Widened in Embree's arrays and restored after
// the shapes, the two passes cost a dispatch and a copy per callback; done lane by lane, their
// narrow stores made the filters' vector loads wait, `perf annotate`: most of the callback's 10%
// of a render.) The lanes past the last whole vector (a single ray, or an 8-ray packet on a CPU
// whose vectors hold 16 floats) are done one by one.
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

// For lanes [0, n), n <= kPacketTfarLanes: widened[i] is the next float above tfar[i] for each
// live lane (valid[i] == -1, as for the shapes' lane kernels; +infinity stays), and tfar[i] for
// the others.
void widenedTfar(const float* tfar, const int* valid, float* widened, unsigned n);

}  // namespace ember
