// Camera::generateRay's directions for many camera samples at once (the lane kernel's camera rays,
// packet/wave_integrator.cpp), in Highway vectors: the raster position, the point on the image
// plane and glm::normalize's 1 / sqrt, with the scalar code's float operations in their order
// (this file is compiled without fused multiply-adds; square root and division round exactly), so
// each lane equals the scalar ray bit for bit (tests/test_wavefront.cpp).
#pragma once

#include "core/math.h"

#include <cstddef>

namespace ember {

// A perspective camera's frame as generateRay reads it.
struct PerspectiveFrame {
  Vec3 forward, right, up;
  float scale, aspect, invWidth, invHeight;
};

// dir[k][i] = component k of the direction through raster position (x[i] + jitter[i].x,
// y[i] + jitter[i].y), for i < n.
void perspectiveDirections(const PerspectiveFrame& frame, const int* x, const int* y, const Vec2* jitter,
                           size_t n, float* const (&dir)[3]);

}  // namespace ember
