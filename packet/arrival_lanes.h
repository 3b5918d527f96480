// The arrival of a run of paths at one Lambertian shape with a constant reflectance
// (packet/wave_integrator.h): the part of PathIntegrator::arrive and Scene::surfaceHit that such a
// vertex needs, for a whole run in Highway vectors. Each lane gathers its path's ray and state
// from the paths' rows by slot and its hit from the batch's packets, and the run's vertices are
// stored consecutively, as whole vectors, into the vertex rows.
//
// Why a kernel: the scalar arrival copies some twenty fields per vertex from slot order into
// vertex order, one load and one store each, and was the largest step of a bounce (27% of
// cornell-area). The kernel's loads are gathers, but its stores are whole rows.
//
// Each lane takes the scalar code's float operations in their order, and the file is compiled
// without fused multiply-adds, so the vertices equal the scalar arrival's bit for bit
// (tests/test_wavefront.cpp).
#pragma once

#include "core/math.h"
#include "packet/continuation_lanes.h"
#include "packet/ray_batch.h"

#include <cstddef>
#include <cstdint>

namespace ember {

// A run of paths that hit one shape, and the shape's constants.
struct LambertianRun {
  const uint16_t* slots;  // the paths' slots, in the order their vertices take; readable in
                          // whole vectors, up to NextEventArrays::kBlock entries past count
  size_t count;
  size_t firstVertex;  // the run's vertices are [firstVertex, firstVertex + count)
  Color albedo;
  uint32_t maskFront, maskBack;
};

// Writes the run's vertices: point p = o + t d with its error bound, the normal, wo, the
// reflectance and throughput, no light sample yet, and the path's state; lanes past the run are
// written too, with values the next run or nothing overwrites (the rows are padded). A vertex
// whose point the float step leaves too far off the surface (t greater than the point's
// magnitude) needs Shape::projectToSurface: the returned count of them are listed in
// `project` (vertex indices), which must hold count + NextEventArrays::kBlock entries.
size_t arriveLambertianLanes(const HitFields& hits, const PathArrays& paths, const LambertianRun& run,
                             NextEventArrays& nee, ContinuationArrays& cont, int32_t* project);

}  // namespace ember
