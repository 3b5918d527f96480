#include "io/scene_summary.h"

#include "io/scene_loader.h"

namespace ember {

nlohmann::json sceneSummary(const Scene& scene) {
  using nlohmann::json;
  const auto vec = [](const Vec3& v) { return json::array({v.x, v.y, v.z}); };
  json shapes = json::object();
  int emitters = 0, twoSidedEmitters = 0;
  for (const auto& s : scene.shapes) {
    const std::string type(s.shape->typeName());
    shapes[type] = shapes.value(type, 0) + 1;
    emitters += !isBlack(s.emission);
    twoSidedEmitters += !isBlack(s.emission) && s.twoSidedEmission;
  }
  size_t emissiveTriangles = 0, twoSidedTriangles = 0;
  for (const auto& m : scene.meshes) {
    if (isBlack(m.emission)) continue;
    emissiveTriangles += m.mesh->indices.size();
    if (m.twoSidedEmission) twoSidedTriangles += m.mesh->indices.size();
  }
  const RenderSettings& rs = scene.settings;
  const CameraParams& c = scene.cameraParams;
  const CausticTracer& tracer = scene.causticTracer();
  json caustics = {{"traced", rs.traceCaustics && tracer.enabled()}};
  if (!rs.traceCaustics)
    caustics["why_not"] = "render.caustic_tracing is off";
  else if (!tracer.enabled())
    caustics["why_not"] = tracer.whyDisabled();
  else
    caustics["casters"] = tracer.casters().size();
  json materials = json::array();
  for (size_t i = 0; i < scene.materials.size(); ++i)
    materials.push_back(
        {{"name", scene.materialNames[i]}, {"type", std::string(scene.materials[i]->typeName())}});
  const Bounds b = scene.bounds();
  return {
      {"image",
       {{"width", rs.width},
        {"height", rs.height},
        {"spp", rs.spp},
        {"max_depth", rs.maxDepth},
        {"rr_depth", rs.rrDepth},
        {"seed", rs.seed}}},
      {"camera", cameraJson(c)},
      {"shapes", shapes},
      {"meshes", scene.meshes.size()},
      {"triangles", scene.triangleCount()},
      {"unique_triangles", scene.uniqueTriangleCount()},
      {"lights",
       {{"punctual", scene.loadedLightCount()},
        {"area", emitters},
        {"area_two_sided", twoSidedEmitters},
        {"emissive_triangles", emissiveTriangles},
        {"emissive_triangles_two_sided", twoSidedTriangles},
        {"environment", scene.environment() != nullptr}}},
      {"strategy", std::string(strategyName(rs.strategy))},
      {"caustics", caustics},
      {"materials", materials},
      {"variants", scene.materialVariants},
      {"bounds", json::array({vec(b.lower), vec(b.upper)})},
  };
}

}  // namespace ember
