// The Sobol sampler's requests for many samplers at once (a bounce of a wave,
// packet/wave_integrator.cpp): each sampler's next 1D or 2D request, exactly the value its
// get1D / get2D would return. The Owen-scrambling hashes (renderer/sampler.h) are integer
// arithmetic, so the Highway kernel (32-bit lanes, the widest ISA the CPU has) equals the scalar
// code bit for bit by construction (tests/test_sampling_lanes.cpp); requests past the Sobol
// dimensions, and the independent sampler's, come from each sampler's own PCG32 stream.
#pragma once

#include "renderer/sampler.h"

#include <cstddef>
#include <cstdint>

namespace ember {

// Up to kBlock Sobol requests, structure of arrays: the inputs of Sampler::get1D / get2D and
// their 32-bit results before the conversion to float.
struct SobolBlock {
  // Four AVX-512 vectors (eight AVX2): the hash is four dependent 32-bit multiplies per scramble,
  // and one vector per flush left the core waiting on that chain and on the vector loads of the
  // just-written scalar stores (perf: 6% of cornell-area on an AVX-512 host). Blocks of 64 are
  // 3.6% faster there than 16 (docs/performance.md, sixteenth session); 128 gains nothing more.
  static constexpr size_t kBlock = 64;
  alignas(64) uint32_t seed[kBlock];  // the dimension's seed, mix64(pixelSeed << 32 | dimension)
  alignas(64) uint32_t index[kBlock];
  alignas(64) uint32_t first[kBlock];
  alignas(64) uint32_t second[kBlock];
};

// out[i] = samplers[i]->get1D() for i < n.
void draw1DLanes(Sampler* const* samplers, size_t n, float* out);
// out[i] = samplers[i]->get2D() for i < n.
void draw2DLanes(Sampler* const* samplers, size_t n, Vec2* out);
// Which of a step's two requests its caller reads. One that is not read is passed over
// (Sampler::skip1D / skip2D) instead of computed, and its output set to 0.5: the sampler's state
// afterwards, and so every later number, is what the full draw leaves (tests/test_sampling_lanes.cpp).
// A light choice among one light reads no number, and in a scene whose lights are all point, spot
// or directional lights no light sample reads its two; a Lambertian reflection reads no lobe
// number, a mirror neither of its two (Material::usesDirectionSample).
struct RequestUse {
  bool first = true, second = true;
};
// Two requests of each sampler in one pass (a light choice's, a BSDF sample's): first[i] =
// samplers[i]->get1D(), then second[i] = samplers[i]->get2D(); and the other way round. `use`:
// the same for every sampler, or one per sampler (nullptr: every request is read).
void draw1DThen2DLanes(Sampler* const* samplers, size_t n, float* first, Vec2* second, RequestUse use = {});
void draw2DThen1DLanes(Sampler* const* samplers, size_t n, Vec2* first, float* second,
                       const RequestUse* use = nullptr);

}  // namespace ember
