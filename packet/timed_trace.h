// A batch traced with its wall time added to the thread's PathStats::traceNanoseconds, so that
// `ember bench` can report how much of a render is traversal (Embree and the shapes' callbacks)
// on the renderer's own rays, beside benchmarks/embree_raw_throughput's synthetic ray mix. Two
// clock reads per batch of up to a wave's rays: nothing next to the rays themselves where the
// clock is read in user space (the vDSO), as on every Linux host measured (render time 0.998).
#pragma once

#include "packet/ray_batch.h"
#include "renderer/integrator.h"
#include "renderer/path_phases.h"

#include <chrono>

namespace ember {

template <class Batch>
void traceTimed(Batch& batch, const EmbreeAccel& accel, PathStats& stats) {
  const std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
  batch.trace(accel);
  stats.traceNanoseconds += nanosecondsBetween(start, std::chrono::steady_clock::now());
}

}  // namespace ember
