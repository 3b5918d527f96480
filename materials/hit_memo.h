// A per-thread memo of a value that is a pure function of (its owner, the hit's UV and, on a mesh,
// the point of the triangle it lies on, whose further attributes a material may read): what a
// material or texture looks up at a vertex, which the integrator asks for more than once per
// vertex (the light sample's evalPdf, then sample; Phong and the mixed material a third time for
// their lobe choice). Texture lookups repeated so were 16% of a textured glTF render's
// instructions (docs/performance-history.md, nineteenth session).
//
// Why it never changes a value: a slot is reused only when its key, the owner's id and the UV's
// bits and its triangle point's, equals the request's, and equal keys are equal arguments of the
// same pure function. Owner
// ids come from one process-wide counter and are never reused, so an object built where a freed
// one lay (a second scene, a test's loop) has another key, as its address would not. Owners must
// therefore not be copied or moved: a moved-from object would keep its id with other contents.
//
// Slots are direct-mapped by the hit's address: the wave's vertices have their hits side by side
// (packet/wave_integrator.cpp), so each keeps its slot between the bounce's passes; any other
// hit finds a different key and computes. Per thread: no locks, nothing allocated per sample.
#pragma once

#include "core/surface_hit.h"

#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>

namespace ember {

// A new owner id: unique in the process, never 0 (0 marks an empty slot).
uint64_t newHitMemoOwner();

// One memo per Value and Tag (the owning class), so that owners of different kinds never share
// slots.
template <typename Value, typename Tag>
class HitMemo {
 public:
  // WaveIntegrator::kWaveSize, which this layer cannot include; a mismatch only costs lookups.
  static constexpr size_t kSlots = 1024;

  // compute(), or what it returned for the same owner and UV at this hit before. The reference
  // stays valid until the thread's next call of the same memo.
  template <typename Compute>
  static const Value& at(const SurfaceHit& hit, uint64_t owner, Compute&& compute) {
    thread_local std::array<Slot, kSlots> slots{};
    Slot& slot = slots[(reinterpret_cast<uintptr_t>(&hit) / sizeof(SurfaceHit)) % kSlots];
    const uint64_t uvBits = std::bit_cast<uint64_t>(hit.uv);
    const uint64_t baryBits = std::bit_cast<uint64_t>(hit.bary);
    if (slot.owner != owner || slot.uvBits != uvBits || slot.attributes != hit.attributes ||
        slot.prim != hit.prim || slot.baryBits != baryBits) {
      slot.value = compute();
      slot.owner = owner;
      slot.uvBits = uvBits;
      slot.attributes = hit.attributes;
      slot.prim = hit.prim;
      slot.baryBits = baryBits;
    }
    return slot.value;
  }

 private:
  struct Slot {
    uint64_t owner = 0;  // 0: empty
    uint64_t uvBits = 0;
    const VertexAttributes* attributes = nullptr;
    uint64_t baryBits = 0;
    uint32_t prim = 0;
    Value value{};
  };
};

}  // namespace ember
