// Embree user-geometry callbacks that route bounds, intersect and occluded queries to a Shape.
#pragma once

#include <embree3/rtcore.h>

namespace ember {

class Shape;

// A user geometry's data: the shape, and whether its closest hits need texture coordinates.
struct ShapeGeometry {
  const Shape* shape;
  bool needsUv;
};

void shapeBoundsCallback(const RTCBoundsFunctionArguments* args);
void shapeIntersectCallback(const RTCIntersectFunctionNArguments* args);
void shapeOccludedCallback(const RTCOccludedFunctionNArguments* args);

}  // namespace ember
