// Owns the Embree device and scene: analytic shapes as user geometry, meshes as Embree triangles.
// Geometry IDs are handed out in the order geometries are added, so callers can index their own
// per-geometry tables (material, light) with the geomID of a hit.
#pragma once

#include "accel/shape.h"
#include "accel/triangle_mesh.h"
#include "accel/user_geometry.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

namespace ember {

// Scene::surfaceHit reads uv and ng.xy eight bytes at a time, so ClosestHitBatch::hit writes each
// of them as one 8-byte store: a read spanning two narrower writes still in flight stalls until
// they reach the cache (`perf annotate`: a third of surfaceHit's time, sixteenth session).
struct RawHit {
  float t;
  uint32_t geomID;
  uint32_t primID;
  Vec2 uv;  // shapes: their UV; meshes: barycentrics (b1, b2)
  Vec3 ng;  // unnormalised for meshes; for shapes, the shape's unit normal
};

// Embree's FLT_LARGE: the largest coordinate magnitude it accepts.
inline constexpr float kEmbreeLarge = 1.844e18f;

// Whether Embree may be given the ray: every origin and direction coordinate within Embree's
// FLT_LARGE (1.8e18) and a non-NaN interval, as its RayK::valid() requires (Debian builds Embree
// with assertions, which abort on anything else). Rays that are not traceable miss everything:
// they come from degenerate input (a camera at infinity, coordinates near FLT_MAX), and the
// paths they belong to give non-finite samples, which the film drops.
inline bool traceable(const Ray& ray) {
  // Every component compared on its own: std::max drops a NaN in all but its first argument, and
  // a NaN compares false, so it is untraceable wherever it is.
  const glm::bvec3 originOk = glm::lessThanEqual(absolute(ray.origin), Vec3(kEmbreeLarge));
  const glm::bvec3 dirOk = glm::lessThanEqual(absolute(ray.dir), Vec3(kEmbreeLarge));
  return glm::all(originOk) && glm::all(dirOk) && !std::isnan(ray.tMax);
}

class EmbreeAccel {
 public:
  EmbreeAccel();
  ~EmbreeAccel();
  EmbreeAccel(const EmbreeAccel&) = delete;
  EmbreeAccel& operator=(const EmbreeAccel&) = delete;

  // Rays whose mask shares no bit with a geometry's skip it (core/ray_spawn.h, kAllRayMask).
  // Geometries have all bits but the flat shapes and convex solids Scene gives one bit of their
  // own; rays have all bits but those of the shapes they cannot meet.
  // The pointers must outlive this object. `needsUv`: whether the shape's hits need texture
  // coordinates (accel/shape_lanes.h, RayLanes::needsUv).
  uint32_t addShape(const Shape* shape, bool needsUv = true, uint32_t mask = kAllRayMask);
  uint32_t addMesh(const TriangleMesh* mesh);
  // Instancing: a mesh built once into a BVH of its own (a prototype; the returned index names it),
  // placed any number of times by addInstance, which returns the instance's geomID. Hits on an
  // instance report that geomID (never the mesh's inside its prototype), so callers index their
  // tables the same way for instances and plain geometries.
  uint32_t addPrototype(const TriangleMesh* mesh);
  uint32_t addInstance(uint32_t prototype, const Mat4& toWorld);
  bool hasInstances() const { return instances_ > 0; }
  // Edits between commits: the shape a user geometry traces (which must keep its mask bit's
  // meaning: Shape::flat and Shape::convexSide as before), and an instance's placement. The next
  // commit() rebuilds only the BVHs of what changed (Embree tracks modified geometries).
  void replaceShape(uint32_t geomID, const Shape* shape);
  void setInstanceTransform(uint32_t geomID, const Mat4& toWorld);
  void commit();

  bool intersect(const Ray& ray, RawHit& hit, uint32_t mask = kAllRayMask) const;
  // True when something blocks the open segment (tMin, tMax) of the ray.
  bool occluded(const Ray& ray, float tMin = 0.0f, uint32_t mask = kAllRayMask) const;

  Bounds bounds() const;
  const char* isaName() const;
  // Rays per packet for batches (packet/ray_batch.h): 16 where Embree traverses 16-wide packets
  // natively (AVX-512), else 8 where it does 8 (AVX2, AVX). Embree splits a packet wider than its
  // own into packets of its width and calls the shapes' callbacks with those, after copying every
  // ray twice (measured in docs/performance.md). Where neither is native (SSE), 16.
  unsigned packetWidth() const { return packetWidth_; }
  // Overrides the choice (8 or 16): `--packet-width`, and the tests that check that both widths
  // give the same hits on any machine.
  void setPacketWidth(unsigned width);
  RTCScene rtcScene() const { return scene_; }  // for the raw-throughput benchmark

 private:
  RTCDevice device_ = nullptr;
  RTCScene scene_ = nullptr;
  unsigned packetWidth_ = 16;
  std::vector<std::unique_ptr<ShapeGeometry>> shapes_;  // the user geometries' data
  std::vector<RTCScene> prototypes_;
  size_t instances_ = 0;
};

// A hit on an instance names the instance's geomID: Embree reports the mesh's geomID inside its
// prototype and the instance's in instID[0].
inline uint32_t hitGeometry(uint32_t geomID, uint32_t instID) {
  return instID != RTC_INVALID_GEOMETRY_ID ? instID : geomID;
}

}  // namespace ember
