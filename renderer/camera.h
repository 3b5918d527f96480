// The camera exactly as ../shared/refs/CONVENTIONS.md defines the pinhole: f = normalize(target -
// origin), r = normalize(cross(f, up)), u = cross(r, f); raster (x, y) in [0,W]x[0,H] with y down;
// direction = normalize(f + (2x/W - 1) t (W/H) r + (1 - 2y/H) t u), t = tan(vertical fov / 2).
// The orthographic projection (glTF 2.0 section 3.10.3) uses the same frame: every ray points
// along f and starts at origin + (2x/W - 1) ymag (W/H) r + (1 - 2y/H) ymag u.
#pragma once

#include "core/math.h"
#include "renderer/camera_lanes.h"

namespace ember {

enum class Projection { Perspective, Orthographic };

struct CameraParams {
  Vec3 origin{0.0f, 0.0f, 1.0f};
  Vec3 target{0.0f};
  Vec3 up{0.0f, 1.0f, 0.0f};
  float fovYDeg = 40.0f;  // perspective only
  Projection projection = Projection::Perspective;
  float orthoHalfHeight = 1.0f;  // orthographic only: glTF ymag, half the view's height in metres
};

class Camera {
 public:
  Camera() : Camera(CameraParams{}, 1, 1) {}
  Camera(const CameraParams& params, int width, int height);

  // Ray through raster position (x, y); (0, 0) is the top-left corner of the image.
  Ray generateRay(float x, float y) const {
    const float sx = (2.0f * x * invWidth_ - 1.0f) * scale_ * aspect_;
    const float sy = (1.0f - 2.0f * y * invHeight_) * scale_;
    if (orthographic_) return Ray{origin_ + sx * right_ + sy * up_, forward_};
    return Ray{origin_, glm::normalize(forward_ + sx * right_ + sy * up_)};
  }
  const CameraParams& params() const { return params_; }
  int width() const { return width_; }
  int height() const { return height_; }
  bool perspective() const { return !orthographic_; }
  // What generateRay reads of a perspective camera (renderer/camera_lanes.h).
  PerspectiveFrame perspectiveFrame() const {
    return {forward_, right_, up_, scale_, aspect_, invWidth_, invHeight_};
  }
  const Vec3& origin() const { return origin_; }
  // Area of the perspective image plane at unit distance: (2 t W/H) x (2 t).
  float imagePlaneArea() const { return 4.0f * scale_ * scale_ * aspect_; }

  // Where a perspective camera sees the point p: its raster position in [0, W) x [0, H) and the
  // cosine between the direction to it and the view axis; false when p is behind the camera or
  // outside the image. The inverse of generateRay.
  bool project(const Vec3& p, Vec2& raster, float& cosTheta) const {
    const Vec3 v = p - origin_;
    const float z = glm::dot(v, forward_);
    if (!(z > 0.0f)) return false;
    const float sx = glm::dot(v, right_) / (z * scale_ * aspect_);
    const float sy = glm::dot(v, up_) / (z * scale_);
    raster = Vec2((sx + 1.0f) * 0.5f * float(width_), (1.0f - sy) * 0.5f * float(height_));
    if (!(raster.x >= 0.0f && raster.x < float(width_) && raster.y >= 0.0f && raster.y < float(height_)))
      return false;
    cosTheta = z / glm::length(v);
    return true;
  }

  // The width of one pixel's footprint on a surface at p with unit normal n, as the camera sees
  // it: the pixel's spread at p's distance, widened by 1 / sqrt|cos| of the viewing angle (the
  // geometric mean of the footprint ellipse's axes). pbrt-v4's camera approximation of ray
  // differentials at every vertex (Camera::Approximate_dp_dxy, section 10.1.1), in isotropic form;
  // it depends on the image's size and never on the sample count, so that renders split over runs
  // merge exactly.
  float footprintAt(const Vec3& p, const Vec3& n) const {
    const Vec3 d = orthographic_ ? forward_ : p - origin_;
    const float distance = orthographic_ ? 1.0f : glm::length(d);
    const float cosine = std::abs(glm::dot(d, n)) / (orthographic_ ? 1.0f : distance);
    const float width = 2.0f * scale_ * invHeight_ * distance;
    return width / std::sqrt(std::max(cosine, 1e-3f));
  }

 private:
  CameraParams params_;
  Vec3 origin_, forward_, right_, up_;
  float scale_, aspect_, invWidth_, invHeight_;  // scale_: tan(fov / 2), or ymag
  bool orthographic_;
  int width_, height_;
};

}  // namespace ember
