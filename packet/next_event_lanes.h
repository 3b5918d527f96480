// Next-event estimation for a whole bounce of Lambertian vertices at once (packet/wave_integrator.h):
// PathIntegrator::shadowFor with Lambertian::evalPdf, spawnRayTo, SurfaceHit::maskToward and the
// power heuristic, for every vertex in Highway vectors (16 floats per AVX-512 register; the widest
// ISA the CPU has is picked at run time). Each lane takes the scalar code's float operations in
// their order, and the file is compiled without fused multiply-adds, so a lane's shadow ray and
// contribution equal the scalar ones bit for bit (tests/test_wavefront.cpp).
#pragma once

#include <cstddef>
#include <cstdint>

namespace ember {

// Structure of arrays over the bounce's vertices; index v is the vertex. Lanes past the count the
// kernel is given are computed too, up to the next multiple of kBlock: they must hold finite
// values (the arrays start zeroed), and their per-vertex results are not read.
struct NextEventArrays {
  static constexpr size_t kCapacity = 1024;
  static constexpr size_t kBlock = 16;
  // Each row is padded by a cache line: rows of exactly 4 KiB would put a vertex's fields at
  // addresses equal in their low 12 bits, and the core, which matches loads against earlier stores
  // by those bits first, then holds a load back behind every store to another row ("4K aliasing":
  // writing the light samples into these rows took 17% of a render).
  static constexpr size_t kStride = kCapacity + 16;
  // The vertex: its point, unit geometric normal (its shading normal too: analytic shapes), the
  // point's rounding-error bound, the direction back along the ray, the constant reflectance and
  // the path's throughput.
  alignas(64) float p[3][kStride] = {};
  alignas(64) float ng[3][kStride] = {};
  alignas(64) float pError[kStride] = {};
  alignas(64) float wo[3][kStride] = {};
  alignas(64) float albedo[3][kStride] = {};
  alignas(64) float throughput[3][kStride] = {};
  // Its light sample (LightSample at a finite distance) and the light's selection probability.
  alignas(64) float lightP[3][kStride] = {};
  alignas(64) float lightN[3][kStride] = {};
  alignas(64) float lightPError[kStride] = {};
  alignas(64) float lightWi[3][kStride] = {};
  alignas(64) float lightLi[3][kStride] = {};
  alignas(64) float lightPdf[kStride] = {};  // solid angle; <= 0 where the vertex has no sample
  alignas(64) float pmf[kStride] = {};
  alignas(64) int32_t delta[kStride] = {};  // -1: a delta light (weight 1), 0 otherwise
  // -1: the light is a point light at lightP with intensity lightLi, whose sample the kernel takes
  // itself (renderer/light.cpp, samplePosition); lightWi, lightPdf and delta are then not read.
  alignas(64) int32_t pointLight[kStride] = {};
  // -1: the light is infinitely far (directional, environment): the shadow ray leaves in lightWi
  // with no end (PathIntegrator::shadowFor's infinite case), and lightP and lightN are not read.
  alignas(64) int32_t infinite[kStride] = {};
  // The Embree mask of the light's shadow rays (Light::shadowMask).
  alignas(64) uint32_t lightMask[kStride] = {};
  // Results. Per vertex: the unoccluded contribution. Per shadow ray, compacted in vertex order
  // (the vertices whose sample contributes): the ray, its Embree mask (the surface's mask for the
  // side it leaves to where its target is clearly off the tangent plane, SurfaceHit::maskToward,
  // and the light's) and its vertex.
  alignas(64) float contribution[3][kStride] = {};
  alignas(64) float shadowOrigin[3][kStride] = {};
  alignas(64) float shadowDir[3][kStride] = {};
  alignas(64) float shadowTMax[kStride] = {};
  alignas(64) uint32_t shadowMask[kStride] = {};
  alignas(64) int32_t shadowVertex[kStride] = {};
};

// Computes the results of vertices [0, n) and returns the number of shadow rays. maskFront and
// maskBack: each vertex's surface masks for rays leaving to its front and back
// (SurfaceHit::maskFor), 64-byte aligned rows readable up to the next multiple of kBlock past n.
// The compacted rows' lanes past the count hold leftovers of the compression; the batches copy
// them into the last packet's unused lanes, which ShadowBatch::trace then makes inactive.
// misWeights: the power heuristic against the BSDF's density (strategy mis); off, every light
// sample has weight 1 (strategy light).
size_t nextEventLanes(NextEventArrays& a, const uint32_t* maskFront, const uint32_t* maskBack, size_t n,
                      bool misWeights);

}  // namespace ember
