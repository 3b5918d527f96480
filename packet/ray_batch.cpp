#include "packet/ray_batch.h"

#include "packet/packet_fields.h"
#include "packet/traceable_lanes.h"

#include <algorithm>
#include <bit>
#include <cstdlib>
#include <cstring>
#include <iterator>
#include <new>
#include <stdexcept>

namespace ember {

namespace {

constexpr size_t kMaxWidth = 16;
constexpr size_t kFloatsPerRay = sizeof(RTCRay16) / (16 * sizeof(float));
constexpr size_t kFloatsPerRayHit = sizeof(RTCRayHit16) / (16 * sizeof(float));
static_assert(sizeof(RTCRay8) == 8 * kFloatsPerRay * sizeof(float));
static_assert(sizeof(RTCRayHit8) == 8 * kFloatsPerRayHit * sizeof(float));

// The ray's fields into lane `lane`, with the interval (0, ray.tMax). Rays Embree may not be given
// (accel/embree_accel.h, traceable) are made inactive when the batch is traced
// (packet/traceable_lanes.h).
void writeRay(RTCRayN* p, unsigned n, unsigned lane, const Ray& ray) {
  RTCRayN_org_x(p, n, lane) = ray.origin.x;
  RTCRayN_org_y(p, n, lane) = ray.origin.y;
  RTCRayN_org_z(p, n, lane) = ray.origin.z;
  RTCRayN_tnear(p, n, lane) = 0.0f;
  RTCRayN_dir_x(p, n, lane) = ray.dir.x;
  RTCRayN_dir_y(p, n, lane) = ray.dir.y;
  RTCRayN_dir_z(p, n, lane) = ray.dir.z;
  RTCRayN_tfar(p, n, lane) = ray.tMax;
}

// A two-float field (a Vec2, or a Vec3's x and y) written as one 8-byte copy, which GCC emits as
// one 8-byte store (see ClosestHitBatch::hit).
void storePair(void* field, float a, float b) {
  const float pair[2] = {a, b};
  std::memcpy(field, pair, sizeof pair);
}
static_assert(sizeof(Vec2) == 2 * sizeof(float) && sizeof(Vec3) == 3 * sizeof(float));

// The fields no ray changes, written once per packet when the layout is set, and the mask, which
// each push then sets for its ray.
void initFixedFields(RTCRayN* p, unsigned n) {
  for (unsigned lane = 0; lane < n; ++lane) {
    RTCRayN_time(p, n, lane) = 0.0f;
    // Debian's Embree is built with ray masks: 0 would miss everything.
    RTCRayN_mask(p, n, lane) = kAllRayMask;
    RTCRayN_id(p, n, lane) = lane;
    RTCRayN_flags(p, n, lane) = 0;
  }
}

// Lanes [0, count) of a packet are valid. Packets after the last are never traced.
void validMask(int (&valid)[kMaxWidth], size_t count) {
  for (size_t i = 0; i < kMaxWidth; ++i) valid[i] = i < count ? -1 : 0;
}

// Where Embree splits a packet wider than its own it looks past the valid mask: so the unused lanes of the
// last packet always get the valid, empty interval (1, 0) at the origin: the InactiveRay
// (packet/traceable_lanes.h). (Left as they were, they held whatever the storage held: an uninitialised lane
// tripped Embree's assertion that every active ray is valid.)
void disableLanes(RTCRayN* p, unsigned n, size_t from) {
  for (size_t i = from; i < n; ++i) {
    RTCRayN_org_x(p, n, unsigned(i)) = InactiveRay::kOrigin;
    RTCRayN_org_y(p, n, unsigned(i)) = InactiveRay::kOrigin;
    RTCRayN_org_z(p, n, unsigned(i)) = InactiveRay::kOrigin;
    RTCRayN_dir_x(p, n, unsigned(i)) = InactiveRay::kDirX;
    RTCRayN_dir_y(p, n, unsigned(i)) = InactiveRay::kDirY;
    RTCRayN_dir_z(p, n, unsigned(i)) = InactiveRay::kDirZ;
    RTCRayN_tnear(p, n, unsigned(i)) = InactiveRay::kTnear;
    RTCRayN_tfar(p, n, unsigned(i)) = InactiveRay::kTfar;
  }
}

unsigned checkedWidth(unsigned width) {
  if (width != 8 && width != 16) throw std::invalid_argument("ray batches hold packets of 8 or 16 rays");
  return width;
}

}  // namespace

namespace detail {

void PacketStorage::Free::operator()(float* p) const {
  std::free(p);
}

PacketStorage::PacketStorage(size_t capacity, size_t floatsPerRay, unsigned width)
    : capacity_(capacity), floatsPerRay_(floatsPerRay) {
  // Whole packets of the widest layout: every narrower one fits in them.
  const size_t floats = (capacity + kMaxWidth - 1) / kMaxWidth * kMaxWidth * floatsPerRay;
  const size_t bytes = (floats * sizeof(float) + 63) / 64 * 64;
  data_.reset(static_cast<float*>(std::aligned_alloc(64, std::max<size_t>(bytes, 64))));
  if (!data_) throw std::bad_alloc();
  std::fill(data_.get(), data_.get() + bytes / sizeof(float), 0.0f);
  setWidth(width);
}

void PacketStorage::setWidth(unsigned width) {
  if (checkedWidth(width) == width_) return;
  width_ = width;
  shift_ = unsigned(std::countr_zero(width));
  stride_ = floatsPerRay_ * width;
  for (size_t k = 0; k < packets(capacity_); ++k)
    initFixedFields(reinterpret_cast<RTCRayN*>(packet(k)), width);
}

}  // namespace detail

ClosestHitBatch::ClosestHitBatch(size_t capacity, unsigned width)
    : storage_(capacity, kFloatsPerRayHit, width) {}

void ClosestHitBatch::push(const Ray& ray, uint32_t mask) {
  if (size_ == storage_.capacity()) throw std::logic_error("ClosestHitBatch overflow");
  const unsigned n = storage_.width(), lane = storage_.laneOf(size_);
  RTCRayHitN* p = packetOf(size_);
  writeRay(RTCRayHitN_RayN(p, n), n, lane, ray);
  RTCRayN_mask(RTCRayHitN_RayN(p, n), n, lane) = mask;
  RTCHitN* h = RTCRayHitN_HitN(p, n);
  RTCHitN_geomID(h, n, lane) = RTC_INVALID_GEOMETRY_ID;
  RTCHitN_primID(h, n, lane) = RTC_INVALID_GEOMETRY_ID;
  RTCHitN_instID(h, n, lane, 0) = RTC_INVALID_GEOMETRY_ID;
  ++size_;
}

namespace {

// A field's offset in floats from the start of its packet.
size_t offsetOf(const void* field, const float* packet) {
  return size_t(static_cast<const char*>(field) - reinterpret_cast<const char*>(packet)) / sizeof(float);
}

// The ray fields both batches fill from rows (RTCRayN at the start of `packet`, n lanes): the
// origin, tnear 0, the direction, tfar (a row, or +infinity where tfar is null) and the mask.
constexpr size_t kRayFieldSources = 9;
std::array<PacketFieldSource, kRayFieldSources> rayFieldSources(float* packet, unsigned n,
                                                                const std::array<const float*, 3>& origin,
                                                                const std::array<const float*, 3>& dir,
                                                                const float* tfar, const uint32_t* mask) {
  RTCRayN* r = reinterpret_cast<RTCRayN*>(packet);
  return {{{offsetOf(&RTCRayN_org_x(r, n, 0), packet), origin[0], 0.0f},
           {offsetOf(&RTCRayN_org_y(r, n, 0), packet), origin[1], 0.0f},
           {offsetOf(&RTCRayN_org_z(r, n, 0), packet), origin[2], 0.0f},
           {offsetOf(&RTCRayN_dir_x(r, n, 0), packet), dir[0], 0.0f},
           {offsetOf(&RTCRayN_dir_y(r, n, 0), packet), dir[1], 0.0f},
           {offsetOf(&RTCRayN_dir_z(r, n, 0), packet), dir[2], 0.0f},
           {offsetOf(&RTCRayN_tnear(r, n, 0), packet), nullptr, 0.0f},
           {offsetOf(&RTCRayN_tfar(r, n, 0), packet), tfar, kInfinity},
           {offsetOf(&RTCRayN_mask(r, n, 0), packet), reinterpret_cast<const float*>(mask), 0.0f}}};
}

}  // namespace

void ClosestHitBatch::assign(const std::array<const float*, 3>& origin,
                             const std::array<const float*, 3>& dir, const uint32_t* mask, size_t count) {
  if (count > storage_.capacity()) throw std::logic_error("ClosestHitBatch overflow");
  const unsigned n = storage_.width();
  float* base = storage_.packet(0);
  RTCHitN* h = RTCRayHitN_HitN(packetOf(0), n);
  const float invalid = std::bit_cast<float>(RTC_INVALID_GEOMETRY_ID);
  std::array<PacketFieldSource, kRayFieldSources + 3> fields;
  const auto ray = rayFieldSources(base, n, origin, dir, nullptr, mask);
  std::copy(ray.begin(), ray.end(), fields.begin());
  fields[kRayFieldSources] = {offsetOf(&RTCHitN_geomID(h, n, 0), base), nullptr, invalid};
  fields[kRayFieldSources + 1] = {offsetOf(&RTCHitN_primID(h, n, 0), base), nullptr, invalid};
  fields[kRayFieldSources + 2] = {offsetOf(&RTCHitN_instID(h, n, 0, 0), base), nullptr, invalid};
  fillPacketFields(base, kFloatsPerRayHit * n, n, count, fields.data(), fields.size());
  size_ = count;
}

void ClosestHitBatch::trace(const EmbreeAccel& accel) {
  if (size_ == 0) return;
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  const unsigned n = storage_.width();
  const size_t packets = storage_.packets(size_);
  auto* last = reinterpret_cast<RTCRayHitN*>(storage_.packet(packets - 1));
  disableLanes(RTCRayHitN_RayN(last, n), n, size_ - (packets - 1) * n);
  disableUntraceableRays(storage_.packet(0), packets, n * kFloatsPerRayHit, n);
  alignas(64) int valid[kMaxWidth];
  for (size_t k = 0; k < packets; ++k) {
    validMask(valid, std::min<size_t>(n, size_ - k * n));
    if (n == 16)
      rtcIntersect16(valid, accel.rtcScene(), &context, reinterpret_cast<RTCRayHit16*>(storage_.packet(k)));
    else
      rtcIntersect8(valid, accel.rtcScene(), &context, reinterpret_cast<RTCRayHit8*>(storage_.packet(k)));
  }
  // Hits name the instance, not the mesh inside its prototype (hitGeometry).
  if (accel.hasInstances())
    for (size_t i = 0; i < size_; ++i) {
      auto* p = reinterpret_cast<RTCRayHitN*>(storage_.packetOf(i));
      RTCHitN* h = RTCRayHitN_HitN(p, n);
      const unsigned lane = storage_.laneOf(i);
      RTCHitN_geomID(h, n, lane) = hitGeometry(RTCHitN_geomID(h, n, lane), RTCHitN_instID(h, n, lane, 0));
    }
}

bool ClosestHitBatch::hit(size_t i, RawHit& out) const {
  const unsigned n = storage_.width(), lane = storage_.laneOf(i);
  RTCRayHitN* p = packetOf(i);
  RTCHitN* h = RTCRayHitN_HitN(p, n);
  if (RTCHitN_geomID(h, n, lane) == RTC_INVALID_GEOMETRY_ID) return false;
  out.t = RTCRayN_tfar(RTCRayHitN_RayN(p, n), n, lane);
  out.geomID = RTCHitN_geomID(h, n, lane);
  out.primID = RTCHitN_primID(h, n, lane);
  // uv and ng.xy as 8-byte stores, the width Scene::surfaceHit reads them at (RawHit's comment).
  storePair(&out.uv, RTCHitN_u(h, n, lane), RTCHitN_v(h, n, lane));
  storePair(&out.ng, RTCHitN_Ng_x(h, n, lane), RTCHitN_Ng_y(h, n, lane));
  out.ng.z = RTCHitN_Ng_z(h, n, lane);
  return true;
}

HitFields ClosestHitBatch::hitFields() const {
  const unsigned n = storage_.width();
  RTCRayHitN* p = packetOf(0);
  RTCHitN* h = RTCRayHitN_HitN(p, n);
  const float* base = storage_.packet(0);
  const auto offset = [base](const float& field) { return uint32_t(offsetOf(&field, base)); };
  return HitFields{base,
                   uint32_t(std::countr_zero(n)),
                   n - 1,
                   uint32_t(kFloatsPerRayHit * n),
                   offset(RTCRayN_tfar(RTCRayHitN_RayN(p, n), n, 0)),
                   offset(RTCHitN_Ng_x(h, n, 0)),
                   offset(RTCHitN_Ng_y(h, n, 0)),
                   offset(RTCHitN_Ng_z(h, n, 0))};
}

ShadowBatch::ShadowBatch(size_t capacity, unsigned width) : storage_(capacity, kFloatsPerRay, width) {}

void ShadowBatch::push(const Ray& ray, uint32_t mask) {
  if (size_ == storage_.capacity()) throw std::logic_error("ShadowBatch overflow");
  auto* packet = reinterpret_cast<RTCRayN*>(storage_.packetOf(size_));
  const unsigned n = storage_.width(), lane = storage_.laneOf(size_);
  writeRay(packet, n, lane, ray);
  RTCRayN_mask(packet, n, lane) = mask;
  ++size_;
}

void ShadowBatch::assign(const std::array<const float*, 3>& origin, const std::array<const float*, 3>& dir,
                         const float* tMax, const uint32_t* mask, size_t count) {
  if (count > storage_.capacity()) throw std::logic_error("ShadowBatch overflow");
  const unsigned n = storage_.width();
  float* base = storage_.packet(0);
  const auto fields = rayFieldSources(base, n, origin, dir, tMax, mask);
  fillPacketFields(base, kFloatsPerRay * n, n, count, fields.data(), fields.size());
  size_ = count;
}

void ShadowBatch::trace(const EmbreeAccel& accel) {
  if (size_ == 0) return;
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  const unsigned n = storage_.width();
  const size_t packets = storage_.packets(size_);
  disableLanes(reinterpret_cast<RTCRayN*>(storage_.packet(packets - 1)), n, size_ - (packets - 1) * n);
  disableUntraceableRays(storage_.packet(0), packets, n * kFloatsPerRay, n);
  alignas(64) int valid[kMaxWidth];
  for (size_t k = 0; k < packets; ++k) {
    validMask(valid, std::min<size_t>(n, size_ - k * n));
    if (n == 16)
      rtcOccluded16(valid, accel.rtcScene(), &context, reinterpret_cast<RTCRay16*>(storage_.packet(k)));
    else
      rtcOccluded8(valid, accel.rtcScene(), &context, reinterpret_cast<RTCRay8*>(storage_.packet(k)));
  }
}

}  // namespace ember
