// Loads a scene file into a Scene (not yet built): Ember's JSON format (docs/scene-format.md), or a
// glTF 2.0 file (.gltf / .glb) directly, which gets a camera and a default environment.
// Bad input throws InputError naming the file and the JSON path.
#pragma once

#include "renderer/scene.h"

#include <string>

namespace ember {

struct LoadOptions {
  int camera = -1;  // glTF files: index into the file's cameras (-1: the first one placed by a node)
  bool environmentGiven = false;   // the caller sets an environment (--env): no default sky for glTF
  std::string variant;             // glTF files: a KHR_materials_variants variant (--variant)
  bool trilinearTextures = false;  // glTF files: filter their images trilinearly (--texture-filter)
};

Scene loadScene(const std::string& path, const LoadOptions& options = {});
Scene loadJsonScene(const std::string& path);

bool isGltfPath(const std::string& path);

// An equirectangular environment map (EXR/HDR linear; 8-bit files decoded from sRGB), times scale.
std::shared_ptr<const ImageTexture> loadEnvironmentMap(const std::string& path,
                                                       const Color& scale = Color(1.0f),
                                                       TextureFilter filter = TextureFilter::Bilinear);

}  // namespace ember
