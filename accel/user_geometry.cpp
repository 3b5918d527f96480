#include "accel/user_geometry.h"

#include "accel/shape.h"

namespace ember {

void shapeBoundsCallback(const RTCBoundsFunctionArguments* args) {
  const auto* shape = static_cast<const Shape*>(args->geometryUserPtr);
  const Bounds b = shape->bounds();
  // Pad by a relative epsilon so float rounding of the exact bounds never culls a true hit.
  const Vec3 pad = 1e-5f * (glm::abs(b.lower) + glm::abs(b.upper)) + Vec3(1e-7f);
  RTCBounds* out = args->bounds_o;
  out->lower_x = b.lower.x - pad.x;
  out->lower_y = b.lower.y - pad.y;
  out->lower_z = b.lower.z - pad.z;
  out->upper_x = b.upper.x + pad.x;
  out->upper_y = b.upper.y + pad.y;
  out->upper_z = b.upper.z + pad.z;
}

static Ray rayOf(RTCRayN* rays, unsigned n, unsigned i) {
  Ray r;
  r.origin = Vec3(RTCRayN_org_x(rays, n, i), RTCRayN_org_y(rays, n, i), RTCRayN_org_z(rays, n, i));
  r.dir = Vec3(RTCRayN_dir_x(rays, n, i), RTCRayN_dir_y(rays, n, i), RTCRayN_dir_z(rays, n, i));
  r.tMax = RTCRayN_tfar(rays, n, i);
  return r;
}

void shapeIntersectCallback(const RTCIntersectFunctionNArguments* args) {
  const auto* shape = static_cast<const Shape*>(args->geometryUserPtr);
  RTCRayN* rays = RTCRayHitN_RayN(args->rayhit, args->N);
  RTCHitN* hits = RTCRayHitN_HitN(args->rayhit, args->N);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    const Ray ray = rayOf(rays, args->N, i);
    LocalHit h;
    if (!shape->intersect(ray, RTCRayN_tnear(rays, args->N, i), ray.tMax, h)) continue;
    RTCRayN_tfar(rays, args->N, i) = h.t;
    RTCHitN_Ng_x(hits, args->N, i) = h.ng.x;
    RTCHitN_Ng_y(hits, args->N, i) = h.ng.y;
    RTCHitN_Ng_z(hits, args->N, i) = h.ng.z;
    RTCHitN_u(hits, args->N, i) = h.uv.x;
    RTCHitN_v(hits, args->N, i) = h.uv.y;
    RTCHitN_primID(hits, args->N, i) = args->primID;
    RTCHitN_geomID(hits, args->N, i) = args->geomID;
    RTCHitN_instID(hits, args->N, i, 0) = args->context->instID[0];
  }
}

void shapeOccludedCallback(const RTCOccludedFunctionNArguments* args) {
  const auto* shape = static_cast<const Shape*>(args->geometryUserPtr);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    const Ray ray = rayOf(args->ray, args->N, i);
    LocalHit h;
    // Embree 3 reports an occluded ray by setting tfar to -infinity.
    if (shape->intersect(ray, RTCRayN_tnear(args->ray, args->N, i), ray.tMax, h))
      RTCRayN_tfar(args->ray, args->N, i) = -kInfinity;
  }
}

}  // namespace ember
