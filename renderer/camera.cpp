#include "renderer/camera.h"

namespace ember {

Camera::Camera(const CameraParams& params, int width, int height)
    : params_(params),
      origin_(params.origin),
      forward_(glm::normalize(params.target - params.origin)),
      right_(glm::normalize(glm::cross(forward_, params.up))),
      up_(glm::cross(right_, forward_)),
      scale_(params.projection == Projection::Orthographic ? params.orthoHalfHeight
                                                           : std::tan(glm::radians(params.fovYDeg) * 0.5f)),
      aspect_(float(width) / float(height)),
      invWidth_(1.0f / float(width)),
      invHeight_(1.0f / float(height)),
      orthographic_(params.projection == Projection::Orthographic),
      width_(width),
      height_(height) {}

}  // namespace ember
