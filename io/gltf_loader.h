// glTF 2.0 (.gltf with embedded or external buffers, .glb) through tinygltf: every triangle
// primitive of every node of the default scene (the first scene if none is marked), with node
// transforms (matrix or TRS), indexed or not, per-vertex normals (flat shading without them),
// TEXCOORD_0 and TANGENT; materials as io/gltf_materials.h converts them; KHR_lights_punctual;
// perspective and orthographic cameras. Every accessor is bounds-checked before it is read.
// docs/gltf.md lists what is supported.
#pragma once

#include "renderer/scene.h"

#include <map>
#include <optional>
#include <string>

namespace ember {

struct GltfImportOptions {
  Mat4 transform{1.0f};                                    // applied on top of the file's node transforms
  const Material* materialOverride = nullptr;              // replaces every glTF material when set
  std::map<std::string, const Material*> materialsByName;  // replaces glTF materials by name
  int camera = -1;  // index into the file's `cameras`; -1: the first camera met in the node tree
  // KHR_materials_variants: the variant whose materials primitives take where they map one;
  // empty: every primitive's default material.
  std::string variant;
  // The images' filter: trilinear (MIP-mapped over each hit's footprint through OpenImageIO's
  // TextureSystem, io/filtered_texture.h; the plugin must be loaded) instead of the samplers'
  // bilinear. Samplers asking for nearest keep it.
  bool trilinearTextures = false;
};

struct GltfImport {
  std::optional<CameraParams> camera;  // the chosen camera as placed by its node, if any
  float cameraAspect = 0.0f;           // its aspect ratio, 0 if unspecified
  size_t cameraCount = 0;              // entries in the file's `cameras`
  size_t triangles = 0;
  size_t points = 0, segments = 0;  // POINTS and LINES primitives, rendered as spheres and cylinders
  size_t primitives = 0;
  size_t lights = 0;                       // KHR_lights_punctual lights placed by nodes
  std::vector<std::string> materialNames;  // every glTF material's name, in file order
  std::vector<std::string> variants;       // KHR_materials_variants names, in file order
};

// Appends the file's meshes, materials and lights to `scene`.
GltfImport importGltf(const std::string& path, Scene& scene, const GltfImportOptions& options = {});

}  // namespace ember
