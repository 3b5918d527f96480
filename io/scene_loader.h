// Loads a scene file into a Scene (not yet built): Ember's JSON format (docs/scene-format.md), or a
// glTF 2.0 file (.gltf / .glb) directly, which gets a camera and a default environment.
// Bad input throws InputError naming the file and the JSON path.
#pragma once

#include "renderer/scene.h"

#include <nlohmann/json.hpp>

#include <string>

namespace ember {

struct LoadOptions {
  int camera = -1;  // glTF files: index into the file's cameras (-1: the first one placed by a node)
  bool environmentGiven = false;   // the caller sets an environment (--env): no default sky for glTF
  std::string variant;             // glTF files: a KHR_materials_variants variant (--variant)
  bool trilinearTextures = false;  // glTF files: filter their images trilinearly (--texture-filter)
};

// Where each entry of a JSON scene's "shapes" and "lights" arrays went in the Scene.
struct JsonSceneIndex {
  struct Range {
    bool mesh = false;  // into Scene::meshes (a "mesh" entry: all its glTF primitives), else Scene::shapes
    size_t first = 0, count = 0;
  };
  std::vector<Range> shapes;
  std::vector<size_t> lights;  // into Scene::lights
};

Scene loadScene(const std::string& path, const LoadOptions& options = {});
Scene loadJsonScene(const std::string& path, JsonSceneIndex* index = nullptr);
// A JSON scene held in memory (the Python module's dicts): `name` stands for the file in error
// messages, and its folder (none: the working directory) resolves the relative paths inside.
Scene loadJsonScene(const nlohmann::json& document, const std::string& name, JsonSceneIndex* index = nullptr);

// A camera as the JSON format writes it ("camera": origin, target, up, fov_y_deg, or type
// "orthographic" and half_height): what JsonEntryReader::camera reads back.
nlohmann::json cameraJson(const CameraParams& camera);

class JsonSceneLoader;

// Single entries of a JSON scene read again, with the loader's checks and error messages (naming
// `file` and the entry's JSON path), to edit a loaded scene: materials named in a shape entry
// must be the scene's. Texture files are read again; nothing else is. Reading changes nothing in
// the scene: what an entry needs besides itself (an emitter's black material, its texture files)
// waits here until adoptInto(), which the caller makes once every entry of an edit was read.
class JsonEntryReader {
 public:
  JsonEntryReader(const Scene& scene, const std::string& file);
  void adoptInto(Scene& scene);
  ~JsonEntryReader();
  CameraParams camera(const nlohmann::json& value) const;
  std::unique_ptr<Material> material(const nlohmann::json& value, const std::string& name) const;
  Scene::ShapeEntry shape(const nlohmann::json& value, const std::string& path) const;  // not meshes
  std::unique_ptr<Light> light(const nlohmann::json& value, const std::string& path) const;
  Mat4 transform(const nlohmann::json& value, const std::string& path) const;  // a mesh entry's "transform"

 private:
  std::string file_;
  std::unique_ptr<Scene> scratch_;
  std::unique_ptr<JsonSceneLoader> loader_;
};

bool isGltfPath(const std::string& path);

// An equirectangular environment map (EXR/HDR linear; 8-bit files decoded from sRGB), times scale.
std::shared_ptr<const ImageTexture> loadEnvironmentMap(const std::string& path,
                                                       const Color& scale = Color(1.0f),
                                                       TextureFilter filter = TextureFilter::Bilinear);

}  // namespace ember
