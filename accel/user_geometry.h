// Embree user-geometry callbacks that route bounds, intersect and occluded queries to a Shape.
#pragma once

#include <embree3/rtcore.h>

namespace ember {

void shapeBoundsCallback(const RTCBoundsFunctionArguments* args);
void shapeIntersectCallback(const RTCIntersectFunctionNArguments* args);
void shapeOccludedCallback(const RTCOccludedFunctionNArguments* args);

}  // namespace ember
