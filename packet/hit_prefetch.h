// Software prefetch for the bounce loops that settle a batch's hits in grouped order
// (packet/wave_integrator.cpp, packet/caustic_wave.cpp). On a large triangle mesh,
// Scene::surfaceHit's loads of a triangle's indices and then of its vertices miss the caches:
// `perf annotate` put 65% of its time on those two loads on the million-triangle scaling scene.
#pragma once

#include "packet/geometry_groups.h"
#include "packet/ray_batch.h"
#include "renderer/scene.h"

#include <cstddef>

namespace ember {

// Call before the hit at position o of `groups`' order is settled. Starts loading the triangle
// indices (and triangle light) of the hit kPrefetchDistance positions later and the vertices of
// the hit half as far ahead, whose indices were asked for that many hits earlier, so that the
// misses overlap the work on the hits between. Meant for scenes whose meshes do not fit in the
// caches (Scene::prefetchesMeshHits): for an analytic shape's hit it only reads the batch.
inline void prefetchGroupedHits(const Scene& scene, const ClosestHitBatch& batch,
                                const GeometryGroups& groups, size_t o, size_t active) {
  constexpr size_t kPrefetchDistance = 16;
  const auto prefetch = [&](size_t ahead, auto step) {
    if (o + ahead >= active) return;
    const size_t a = groups.order()[o + ahead];
    const uint32_t geomID = batch.geometryOf(a);
    if (geomID != RTC_INVALID_GEOMETRY_ID) step(geomID, batch.primitiveOf(a));
  };
  prefetch(kPrefetchDistance, [&](uint32_t g, uint32_t p) { scene.prefetchTriangle(g, p); });
  prefetch(kPrefetchDistance / 2, [&](uint32_t g, uint32_t p) { scene.prefetchVertices(g, p); });
}

}  // namespace ember
