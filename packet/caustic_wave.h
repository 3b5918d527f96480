// The caustic tracer's light paths (renderer/caustic_tracer.h) run as a wavefront, as the path
// tracer's camera paths are (packet/wave_integrator.h): a task's light paths advance
// together, one bounce at a time, and each bounce casts all their rays, then all their camera
// connections, as batches of 16-wide Embree packets. Every path takes exactly the steps
// CausticTracer::traceAlone takes (start, onHit) with its own sampler, and splats are summed in
// fixed point, so the splat images equal the scalar driver's bit for bit (tests/test_caustics.cpp).
#pragma once

#include "packet/ray_batch.h"
#include "renderer/integrator.h"

namespace ember {

void traceCausticsInWaves(const Scene& scene, int maxDepth, int rrDepth, uint64_t seed, SamplerType sampler,
                          uint64_t firstIndex, int count, CausticSplats& splats, PathStats& stats);

}  // namespace ember
