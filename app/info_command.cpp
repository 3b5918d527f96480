#include "app/commands.h"

#include "io/image_plugin.h"
#include "io/scene_loader.h"
#include "io/scene_summary.h"

#include <cstdio>

#include <map>
#include <memory>

namespace ember::cli {

namespace {

std::string fmt(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", v);
  return text;
}

}  // namespace

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
    scene.build();
    const nlohmann::json info = sceneSummary(scene);
    const auto& image = info["image"];
    const auto& camera = info["camera"];
    const auto vec = [](const nlohmann::json& v) {
      return "(" + fmt(v[0].get<double>()) + ", " + fmt(v[1].get<double>()) + ", " + fmt(v[2].get<double>()) +
             ")";
    };
    std::printf("scene:      %s\n", path->c_str());
    std::printf("image:      %d x %d, %d spp, max depth %d, Russian roulette from %d, seed %llu\n",
                image["width"].get<int>(), image["height"].get<int>(), image["spp"].get<int>(),
                image["max_depth"].get<int>(), image["rr_depth"].get<int>(),
                static_cast<unsigned long long>(image["seed"].get<uint64_t>()));
    std::printf("camera:     origin %s target %s ", vec(camera["origin"]).c_str(),
                vec(camera["target"]).c_str());
    if (camera.value("type", "pinhole") == "orthographic")
      std::printf("orthographic, half height %g\n", camera["half_height"].get<double>());
    else
      std::printf("fov_y %g deg\n", camera["fov_y_deg"].get<double>());
    std::printf("shapes:     %zu", scene.shapes.size());
    for (const auto& [type, n] : info["shapes"].items()) std::printf("  %s %d", type.c_str(), n.get<int>());
    std::printf("\nmeshes:     %zu (%zu triangles", scene.meshes.size(), info["triangles"].get<size_t>());
    if (info["unique_triangles"] != info["triangles"])
      std::printf("; %zu unique, the rest instances of them", info["unique_triangles"].get<size_t>());
    std::printf(")\n");
    const auto& lights = info["lights"];
    std::printf(
        "lights:     %zu punctual, %d area (%d two-sided), %zu emissive triangles (%zu two-sided), %s "
        "environment\n",
        lights["punctual"].get<size_t>(), lights["area"].get<int>(), lights["area_two_sided"].get<int>(),
        lights["emissive_triangles"].get<size_t>(), lights["emissive_triangles_two_sided"].get<size_t>(),
        lights["environment"].get<bool>() ? "1" : "no");
    std::printf("strategy:   %s\n", info["strategy"].get<std::string>().c_str());
    const auto& caustics = info["caustics"];
    if (!caustics["traced"].get<bool>())
      std::printf("caustics:   path-traced (%s)\n", caustics["why_not"].get<std::string>().c_str());
    else
      std::printf("caustics:   light-traced, %zu specular object(s)\n", caustics["casters"].get<size_t>());
    std::printf("materials:  %zu", info["materials"].size());
    for (size_t i = 0; i < info["materials"].size(); ++i)
      std::printf("%s %s (%s)", i ? "," : "", info["materials"][i]["name"].get<std::string>().c_str(),
                  info["materials"][i]["type"].get<std::string>().c_str());
    if (!scene.materialVariants.empty()) {
      std::printf("\nvariants:   %zu", scene.materialVariants.size());
      for (size_t i = 0; i < scene.materialVariants.size(); ++i)
        std::printf("%s '%s'", i ? "," : "", scene.materialVariants[i].c_str());
      std::printf(" (--variant NAME)");
    }
    std::printf("\nbounds:     %s - %s\n", vec(info["bounds"][0]).c_str(), vec(info["bounds"][1]).c_str());
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
