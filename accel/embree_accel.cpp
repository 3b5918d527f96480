#include "accel/embree_accel.h"

#include "accel/user_geometry.h"
#include "core/rng.h"

#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>

namespace ember {

static void embreeErrorHandler(void* /*user*/, RTCError code, const char* message) {
  std::fprintf(stderr, "ember: Embree error %d: %s\n", int(code), message ? message : "");
}

EmbreeAccel::EmbreeAccel() {
  device_ = rtcNewDevice(nullptr);
  if (!device_) throw std::runtime_error("could not create an Embree device");
  rtcSetDeviceErrorFunction(device_, embreeErrorHandler, nullptr);
  if (rtcGetDeviceProperty(device_, RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED) == 0 &&
      rtcGetDeviceProperty(device_, RTC_DEVICE_PROPERTY_NATIVE_RAY8_SUPPORTED) != 0)
    packetWidth_ = 8;
  scene_ = rtcNewScene(device_);
  // Medium (Embree's default, a binned SAH build): on the million-triangle scaling scene it
  // builds in 0.45 s instead of high quality's 1.8 s (spatial splits), and renders as fast
  // (docs/performance.md, optimisation log).
  rtcSetSceneBuildQuality(scene_, RTC_BUILD_QUALITY_MEDIUM);
}

EmbreeAccel::~EmbreeAccel() {
  if (scene_) rtcReleaseScene(scene_);
  for (RTCScene prototype : prototypes_) rtcReleaseScene(prototype);
  if (device_) rtcReleaseDevice(device_);
}

uint32_t EmbreeAccel::addShape(const Shape* shape, bool needsUv, uint32_t mask) {
  RTCGeometry geom = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_USER);
  rtcSetGeometryUserPrimitiveCount(geom, 1);
  shapes_.push_back(std::make_unique<ShapeGeometry>(ShapeGeometry{shape, needsUv}));
  rtcSetGeometryUserData(geom, shapes_.back().get());
  rtcSetGeometryBoundsFunction(geom, shapeBoundsCallback, nullptr);
  rtcSetGeometryIntersectFunction(geom, shapeIntersectCallback);
  rtcSetGeometryOccludedFunction(geom, shapeOccludedCallback);
  rtcSetGeometryMask(geom, mask);
  rtcCommitGeometry(geom);
  const uint32_t id = rtcAttachGeometry(scene_, geom);
  rtcReleaseGeometry(geom);
  return id;
}

// Alpha cut-outs and stochastic transparency (glTF alpha modes): Embree calls this for every
// candidate hit of a mesh with an opacity, and a hit rejected here is skipped as if the surface were
// not there, for closest-hit and shadow rays alike. The random number is a hash of the ray and the
// triangle, so renders stay deterministic and independent of the thread count.
static void meshOpacityFilter(const RTCFilterFunctionNArguments* args) {
  const auto* mesh = static_cast<const TriangleMesh*>(args->geometryUserPtr);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    const uint32_t prim = RTCHitN_primID(args->hit, args->N, i);
    const Vec2 b(RTCHitN_u(args->hit, args->N, i), RTCHitN_v(args->hit, args->N, i));
    uint32_t bits[7];
    const float ray[6] = {RTCRayN_org_x(args->ray, args->N, i), RTCRayN_org_y(args->ray, args->N, i),
                          RTCRayN_org_z(args->ray, args->N, i), RTCRayN_dir_x(args->ray, args->N, i),
                          RTCRayN_dir_y(args->ray, args->N, i), RTCRayN_dir_z(args->ray, args->N, i)};
    std::memcpy(bits, ray, sizeof(ray));
    bits[6] = prim;
    uint64_t h = 0x9e3779b97f4a7c15ull;
    for (uint32_t b : bits) h = mix64(h ^ b);
    const float u = float(h >> 40) * 0x1p-24f;
    if (mesh->opacity->passesThrough(*mesh, prim, b, u)) args->valid[i] = 0;
  }
}

static uint32_t attachMesh(RTCDevice device, RTCScene scene, const TriangleMesh* mesh) {
  RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  rtcSetGeometryMask(geom, kAllRayMask);  // every ray tests meshes (Embree 3's default, stated)
  // Embree-owned buffers: Embree pads them as its SIMD loads need (16 bytes past the end).
  auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(
      geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), mesh->positions.size()));
  std::memcpy(vertices, mesh->positions.data(), mesh->positions.size() * sizeof(Vec3));
  auto* indices = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(
      geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(uint32_t), mesh->indices.size()));
  std::memcpy(indices, mesh->indices.data(), mesh->indices.size() * sizeof(glm::uvec3));
  if (mesh->opacity) {
    rtcSetGeometryUserData(geom, const_cast<TriangleMesh*>(mesh));
    rtcSetGeometryIntersectFilterFunction(geom, meshOpacityFilter);
    rtcSetGeometryOccludedFilterFunction(geom, meshOpacityFilter);
  }
  rtcCommitGeometry(geom);
  const uint32_t id = rtcAttachGeometry(scene, geom);
  rtcReleaseGeometry(geom);
  return id;
}

uint32_t EmbreeAccel::addMesh(const TriangleMesh* mesh) {
  return attachMesh(device_, scene_, mesh);
}

uint32_t EmbreeAccel::addPrototype(const TriangleMesh* mesh) {
  RTCScene prototype = rtcNewScene(device_);
  rtcSetSceneBuildQuality(prototype, RTC_BUILD_QUALITY_MEDIUM);
  attachMesh(device_, prototype, mesh);
  rtcCommitScene(prototype);
  prototypes_.push_back(prototype);
  return uint32_t(prototypes_.size() - 1);
}

uint32_t EmbreeAccel::addInstance(uint32_t prototype, const Mat4& toWorld) {
  RTCGeometry geom = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_INSTANCE);
  rtcSetGeometryInstancedScene(geom, prototypes_.at(prototype));
  rtcSetGeometryTimeStepCount(geom, 1);
  rtcSetGeometryTransform(geom, 0, RTC_FORMAT_FLOAT4X4_COLUMN_MAJOR, &toWorld[0][0]);
  rtcSetGeometryMask(geom, kAllRayMask);
  rtcCommitGeometry(geom);
  const uint32_t id = rtcAttachGeometry(scene_, geom);
  rtcReleaseGeometry(geom);
  ++instances_;
  return id;
}

void EmbreeAccel::replaceShape(uint32_t geomID, const Shape* shape) {
  RTCGeometry geom = rtcGetGeometry(scene_, geomID);
  static_cast<ShapeGeometry*>(rtcGetGeometryUserData(geom))->shape = shape;
  rtcCommitGeometry(geom);
}

void EmbreeAccel::setInstanceTransform(uint32_t geomID, const Mat4& toWorld) {
  RTCGeometry geom = rtcGetGeometry(scene_, geomID);
  rtcSetGeometryTransform(geom, 0, RTC_FORMAT_FLOAT4X4_COLUMN_MAJOR, &toWorld[0][0]);
  rtcCommitGeometry(geom);
}

void EmbreeAccel::commit() {
  rtcCommitScene(scene_);
  const RTCError err = rtcGetDeviceError(device_);
  if (err != RTC_ERROR_NONE)
    throw std::runtime_error("Embree failed to build the scene (error " + std::to_string(int(err)) + ")");
}

static RTCRay toRtc(const Ray& ray, float tMin, uint32_t mask = kAllRayMask) {
  RTCRay r;
  r.org_x = ray.origin.x;
  r.org_y = ray.origin.y;
  r.org_z = ray.origin.z;
  r.tnear = tMin;
  r.dir_x = ray.dir.x;
  r.dir_y = ray.dir.y;
  r.dir_z = ray.dir.z;
  r.time = 0.0f;
  r.tfar = ray.tMax;
  r.mask = mask;  // Debian's Embree is built with ray masks: 0 would miss everything
  r.id = 0;
  r.flags = 0;
  return r;
}

bool EmbreeAccel::intersect(const Ray& ray, RawHit& hit, uint32_t mask) const {
  if (!traceable(ray)) return false;
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit rh;
  rh.ray = toRtc(ray, 0.0f, mask);
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(scene_, &context, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
  hit.t = rh.ray.tfar;
  hit.geomID = hitGeometry(rh.hit.geomID, rh.hit.instID[0]);
  hit.primID = rh.hit.primID;
  hit.ng = Vec3(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z);
  hit.uv = Vec2(rh.hit.u, rh.hit.v);
  return true;
}

bool EmbreeAccel::occluded(const Ray& ray, float tMin, uint32_t mask) const {
  if (!traceable(ray)) return false;
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRay r = toRtc(ray, tMin, mask);
  rtcOccluded1(scene_, &context, &r);
  return r.tfar < 0.0f;
}

Bounds EmbreeAccel::bounds() const {
  RTCBounds b;
  rtcGetSceneBounds(scene_, &b);
  Bounds out;
  out.extend(Vec3(b.lower_x, b.lower_y, b.lower_z));
  out.extend(Vec3(b.upper_x, b.upper_y, b.upper_z));
  return out;
}

void EmbreeAccel::setPacketWidth(unsigned width) {
  if (width != 8 && width != 16) throw std::invalid_argument("packets hold 8 or 16 rays");
  packetWidth_ = width;
}

const char* EmbreeAccel::isaName() const {
  // Embree does not expose the kernel it picked through its API; report what the CPU offers.
  if (__builtin_cpu_supports("avx512f")) return "avx512";
  if (__builtin_cpu_supports("avx2")) return "avx2";
  if (__builtin_cpu_supports("avx")) return "avx";
  if (__builtin_cpu_supports("sse4.2")) return "sse4.2";
  return "sse2";
}

}  // namespace ember
