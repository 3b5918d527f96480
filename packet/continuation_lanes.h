// The continuation of a whole bounce's vertices at once (packet/wave_integrator.h):
// PathIntegrator::followBsdfSample for every vertex in Highway vectors (16 floats per AVX-512
// register): the throughput times the BSDF sample's weight, the side the next ray leaves to and its
// origin pushed off the surface, the eta product, Russian roulette, and the surviving paths written
// compacted into the next bounce's rows by vector compress-and-store, row by row. Each lane takes
// the scalar code's float operations in their order, and the file is compiled without fused
// multiply-adds, so a path's next state equals the scalar step's bit for bit
// (tests/test_wavefront.cpp).
#pragma once

#include "packet/next_event_lanes.h"

#include <cstddef>
#include <cstdint>

namespace ember {

// The paths in flight, by slot: the ray each casts and what its next vertex needs
// (PathIntegrator's path state), padded as NextEventArrays. A compacted store writes a whole
// vector, the lanes past the paths it adds holding whatever the compression left there; the next
// store or nothing reads them. It never reaches past vertex n's block, so n <= kCapacity keeps
// every store inside the rows.
struct PathArrays {
  static constexpr size_t kStride = NextEventArrays::kStride;
  alignas(64) float origin[3][kStride] = {};
  alignas(64) float dir[3][kStride] = {};
  alignas(64) float throughput[3][kStride] = {};
  alignas(64) float previousPoint[3][kStride] = {};  // the vertex the ray left
  alignas(64) float previousPdf[kStride] = {};       // the BSDF sample's density there
  alignas(64) float etaProduct[kStride] = {};
  alignas(64) int32_t owner[kStride] = {};                // the camera sample (the wave's lane)
  alignas(64) int32_t depth[kStride] = {};                // segments so far, this one included
  alignas(64) int32_t previousDelta[kStride] = {};        // -1: a Dirac lobe (or the camera) cast it
  alignas(64) int32_t firstBounceNonDelta[kStride] = {};  // -1: the first bounce sampled a non-Dirac lobe
  alignas(64) uint32_t mask[kStride] = {};                // the ray's Embree mask
};

// The bounce's vertices' BSDF samples and path state, beside the NextEventArrays that hold their
// points, normals, error bounds, directions back, reflectances and throughputs; index v is the
// vertex. Lanes past the count are computed too (their results reach only the rows' lanes past
// the paths written): they must hold finite values, as the arrays start.
struct ContinuationArrays {
  static constexpr size_t kStride = NextEventArrays::kStride;
  // The BSDF sample's direction and density. A vertex in the kernels' Lambertian form has them
  // from the cosine kernel; a general vertex (-1 in `general`: any other material) has its weight,
  // eta, Dirac flag and whether it sampled at all (-1 in `generalSampled`) from its material, where
  // a Lambertian one's are its reflectance (NextEventArrays::albedo), 1, 0 and Lambertian::sample's
  // test (a density, and wi on wo's side).
  alignas(64) float wi[3][kStride] = {};
  alignas(64) float pdf[kStride] = {};
  alignas(64) int32_t general[kStride] = {};
  alignas(64) float weight[3][kStride] = {};
  alignas(64) float eta[kStride] = {};
  alignas(64) int32_t generalSampled[kStride] = {};
  alignas(64) int32_t sampledDelta[kStride] = {};  // -1: the sample is a Dirac lobe's
  // The path at the vertex: its eta product, camera sample, depth and first-bounce flag, and the
  // surface's Embree masks for rays leaving to its front and back (SurfaceHit::maskFor).
  alignas(64) float etaProduct[kStride] = {};
  alignas(64) int32_t owner[kStride] = {};
  alignas(64) int32_t depth[kStride] = {};
  alignas(64) int32_t firstBounceNonDelta[kStride] = {};
  alignas(64) uint32_t maskFront[kStride] = {};
  alignas(64) uint32_t maskBack[kStride] = {};
  // Russian roulette's number, read where depth >= rrDepth.
  alignas(64) float roulette[kStride] = {};
};

// Follows the BSDF samples of vertices [0, n), n <= NextEventArrays::kCapacity, and writes the
// paths that go on into slots [0, returned count) of `next`, in vertex order. rrDepth: the depth
// from which roulette plays.
size_t continuationLanes(const NextEventArrays& vertices, const ContinuationArrays& c, size_t n, int rrDepth,
                         PathArrays& next);

}  // namespace ember
