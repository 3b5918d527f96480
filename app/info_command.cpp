#include "app/commands.h"

#include "io/image_plugin.h"
#include "io/scene_loader.h"

#include <map>
#include <memory>

namespace ember::cli {

Runner addInfoCommand(CLI::App& app) {
  auto path = std::make_shared<std::string>();
  auto variant = std::make_shared<std::string>();
  CLI::App* cmd =
      app.add_subcommand("info", "Print what a scene file loads: shapes, meshes, lights, materials, bounds");
  cmd->add_option("scene", *path, "Scene file: Ember JSON, .gltf or .glb")->required();
  cmd->add_option("--variant", *variant,
                  "glTF files: load the materials of this KHR_materials_variants variant");
  return [path, variant] {
    LoadOptions options;
    options.variant = *variant;
    Scene scene = loadScene(*path, options);
    const size_t punctualLights = scene.lights.size();  // point, spot, directional: before build() adds more
    scene.build();
    std::map<std::string, int> byType;
    int emitters = 0, twoSidedEmitters = 0;
    for (const auto& s : scene.shapes) {
      ++byType[std::string(s.shape->typeName())];
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
    const Bounds b = scene.bounds();
    std::printf("scene:      %s\n", path->c_str());
    std::printf("image:      %d x %d, %d spp, max depth %d, Russian roulette from %d, seed %llu\n", rs.width,
                rs.height, rs.spp, rs.maxDepth, rs.rrDepth, static_cast<unsigned long long>(rs.seed));
    std::printf("camera:     origin (%g, %g, %g) target (%g, %g, %g) ", c.origin.x, c.origin.y, c.origin.z,
                c.target.x, c.target.y, c.target.z);
    if (c.projection == Projection::Orthographic)
      std::printf("orthographic, half height %g\n", c.orthoHalfHeight);
    else
      std::printf("fov_y %g deg\n", c.fovYDeg);
    std::printf("shapes:     %zu", scene.shapes.size());
    for (const auto& [type, n] : byType) std::printf("  %s %d", type.c_str(), n);
    std::printf("\nmeshes:     %zu (%zu triangles", scene.meshes.size(), scene.triangleCount());
    if (scene.uniqueTriangleCount() != scene.triangleCount())
      std::printf("; %zu unique, the rest instances of them", scene.uniqueTriangleCount());
    std::printf(")\n");
    std::printf(
        "lights:     %zu punctual, %d area (%d two-sided), %zu emissive triangles (%zu two-sided), %s "
        "environment\n",
        punctualLights, emitters, twoSidedEmitters, emissiveTriangles, twoSidedTriangles,
        scene.environment() ? "1" : "no");
    std::printf("strategy:   %s\n", std::string(strategyName(rs.strategy)).c_str());
    const CausticTracer& caustics = scene.causticTracer();
    if (!rs.traceCaustics || !caustics.enabled())
      std::printf("caustics:   path-traced (%s)\n",
                  rs.traceCaustics ? caustics.whyDisabled() : "render.caustic_tracing is off");
    else
      std::printf("caustics:   light-traced, %zu specular object(s)\n", caustics.casters().size());
    std::printf("materials:  %zu", scene.materials.size());
    for (size_t i = 0; i < scene.materials.size(); ++i)
      std::printf("%s %s (%s)", i ? "," : "", scene.materialNames[i].c_str(),
                  std::string(scene.materials[i]->typeName()).c_str());
    if (!scene.materialVariants.empty()) {
      std::printf("\nvariants:   %zu", scene.materialVariants.size());
      for (size_t i = 0; i < scene.materialVariants.size(); ++i)
        std::printf("%s '%s'", i ? "," : "", scene.materialVariants[i].c_str());
      std::printf(" (--variant NAME)");
    }
    std::printf("\nbounds:     (%g, %g, %g) - (%g, %g, %g)\n", b.lower.x, b.lower.y, b.lower.z, b.upper.x,
                b.upper.y, b.upper.z);
    // Which reader image files go through (io/image_plugin.h); EXR and PFM are always read built in.
    if (const ImagePlugin* plugin = imagePlugin())
      std::printf("images:     %s\n", plugin->describe().c_str());
    else
      std::printf("images:     built-in readers (stb_image); no OpenImageIO plugin: %s\n",
                  imagePluginError().c_str());
    return 0;
  };
}

}  // namespace ember::cli
