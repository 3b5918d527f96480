// Pinhole camera exactly as ../shared/refs/CONVENTIONS.md defines it: f = normalize(target -
// origin), r = normalize(cross(f, up)), u = cross(r, f); raster (x, y) in [0,W]x[0,H] with y down;
// direction = normalize(f + (2x/W - 1) t (W/H) r + (1 - 2y/H) t u), t = tan(vertical fov / 2).
#pragma once

#include "renderer/math.h"

namespace ember {

struct CameraParams {
  Vec3 origin{0.0f, 0.0f, 1.0f};
  Vec3 target{0.0f};
  Vec3 up{0.0f, 1.0f, 0.0f};
  float fovYDeg = 40.0f;
};

class PinholeCamera {
 public:
  PinholeCamera() : PinholeCamera(CameraParams{}, 1, 1) {}
  PinholeCamera(const CameraParams& params, int width, int height);

  // Ray through raster position (x, y); (0, 0) is the top-left corner of the image.
  Ray generateRay(float x, float y) const {
    const float sx = (2.0f * x * invWidth_ - 1.0f) * tanHalf_ * aspect_;
    const float sy = (1.0f - 2.0f * y * invHeight_) * tanHalf_;
    return Ray{origin_, glm::normalize(forward_ + sx * right_ + sy * up_)};
  }
  const CameraParams& params() const { return params_; }

 private:
  CameraParams params_;
  Vec3 origin_, forward_, right_, up_;
  float tanHalf_, aspect_, invWidth_, invHeight_;
};

}  // namespace ember
