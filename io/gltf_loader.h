// glTF 2.0 (.gltf with embedded or external buffers, .glb) through tinygltf: every triangle
// primitive of every node of the default scene (the first scene if none is marked), with node
// transforms (matrix or TRS), indexed or not, per-vertex normals (flat shading without them) and
// TEXCOORD_0. baseColorFactor x baseColorTexture drive a Lambertian material for now;
// emissiveFactor makes a primitive emit. Every accessor is bounds-checked before it is read.
#pragma once

#include "renderer/scene.h"

#include <optional>
#include <string>

namespace ember {

struct GltfImport {
  std::optional<CameraParams> camera;  // the first camera met in the node tree, if any
  float cameraAspect = 0.0f;           // its aspectRatio, 0 if unspecified
  size_t triangles = 0;
  size_t primitives = 0;
  size_t lights = 0;  // KHR_lights_punctual lights placed by nodes
};

// Appends the file's meshes (transformed by `transform`) and materials to `scene`. With
// `materialOverride`, every primitive uses that material instead of the file's.
GltfImport importGltf(const std::string& path, Scene& scene, const Mat4& transform = Mat4(1.0f),
                      const Material* materialOverride = nullptr);

}  // namespace ember
