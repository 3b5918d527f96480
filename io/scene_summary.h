// What a built scene holds, as `ember info` prints it and the Python module's Scene.info() returns
// it: one set of counts for both.
#pragma once

#include "renderer/scene.h"

#include <nlohmann/json.hpp>

namespace ember {

// Keys: image {width, height, spp, max_depth, rr_depth, seed}, camera (as the JSON format
// writes it: cameraJson), shapes {type: count}, meshes, triangles, unique_triangles,
// lights {punctual, area, area_two_sided, emissive_triangles, emissive_triangles_two_sided,
// environment}, strategy, caustics {traced, casters | why_not}, materials [{name, type}],
// variants [names], bounds [[lower], [upper]].
nlohmann::json sceneSummary(const Scene& scene);

}  // namespace ember
