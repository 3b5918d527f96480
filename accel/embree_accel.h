// Owns the Embree device and scene: analytic shapes as user geometry, meshes as Embree triangles.
// Geometry IDs are handed out in the order geometries are added, so callers can index their own
// per-geometry tables (material, light) with the geomID of a hit.
#pragma once

#include "accel/shape.h"
#include "accel/triangle_mesh.h"

#include <embree3/rtcore.h>

#include <cstdint>

namespace ember {

struct RawHit {
  float t;
  uint32_t geomID;
  uint32_t primID;
  Vec3 ng;  // unnormalised for meshes; for shapes, the shape's unit normal
  Vec2 uv;  // shapes: their UV; meshes: barycentrics (b1, b2)
};

class EmbreeAccel {
 public:
  EmbreeAccel();
  ~EmbreeAccel();
  EmbreeAccel(const EmbreeAccel&) = delete;
  EmbreeAccel& operator=(const EmbreeAccel&) = delete;

  // The pointers must outlive this object.
  uint32_t addShape(const Shape* shape);
  uint32_t addMesh(const TriangleMesh* mesh);
  void commit();

  bool intersect(const Ray& ray, RawHit& hit) const;
  // True when something blocks the open segment (tMin, tMax) of the ray.
  bool occluded(const Ray& ray, float tMin = 0.0f) const;

  Bounds bounds() const;
  const char* isaName() const;
  RTCScene rtcScene() const { return scene_; }  // for the raw-throughput benchmark

 private:
  RTCDevice device_ = nullptr;
  RTCScene scene_ = nullptr;
};

}  // namespace ember
