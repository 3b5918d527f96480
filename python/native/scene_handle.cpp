#include "python/native/scene_handle.h"

#include "io/input_error.h"
#include "io/json_reader.h"

#include <filesystem>

namespace ember::python {

namespace {

nlohmann::json merged(nlohmann::json base, const nlohmann::json& patch) {
  if (!base.is_object()) base = nlohmann::json::object();
  for (const auto& [key, value] : patch.items()) {
    if (value.is_null())
      base.erase(key);
    else
      base[key] = value;
  }
  return base;
}

// An entry whose "type" the patch changes keeps none of its old type's keys, only those `kept`
// says belong to every type.
template <class Kept>
nlohmann::json retyped(const nlohmann::json& base, const nlohmann::json& patch, Kept kept) {
  if (!patch.contains("type") || !base.is_object() || base.value("type", nlohmann::json()) == patch["type"])
    return base;
  nlohmann::json out = nlohmann::json::object();
  for (const auto& [key, value] : base.items())
    if (kept(key)) out[key] = value;
  return out;
}

// The keys of a shape entry that say how it is shaded, not where it is.
bool shadingKey(const std::string& key) {
  return key == "material" || key == "emission" || key == "two_sided" || key == "id" || key == "name" ||
         key == "note";
}

}  // namespace

SceneHandle SceneHandle::fromFile(const std::string& path, const LoadOptions& options) {
  SceneHandle h;
  h.name_ = path;
  if (isGltfPath(path) || !std::filesystem::is_regular_file(path)) {
    h.scene_ = std::make_unique<Scene>(loadScene(path, options));
  } else {
    // The JSON format: parsed once, kept for edits.
    if (options.camera >= 0) throw InputError(path + ": camera selects a camera of a glTF file");
    if (!options.variant.empty())
      throw InputError(path + ": variant selects a material variant of a glTF file");
    h.document_ = JsonNode::parseFile(path);
    h.json_ = true;
    h.scene_ = std::make_unique<Scene>(loadJsonScene(h.document_, path, &h.index_));
    h.scene_->sourceFiles.insert(h.scene_->sourceFiles.begin(), path);
  }
  h.scene_->build();
  return h;
}

SceneHandle SceneHandle::fromDocument(nlohmann::json document, const std::string& name) {
  SceneHandle h;
  h.name_ = name;
  h.document_ = std::move(document);
  h.json_ = true;
  h.scene_ = std::make_unique<Scene>(loadJsonScene(h.document_, name, &h.index_));
  h.scene_->build();
  return h;
}

void SceneHandle::requireJson(const char* what) const {
  if (!json_)
    throw InputError(name_ + ": the " + std::string(what) +
                     " of a glTF file cannot be edited here; place the file in a JSON scene's \"mesh\" "
                     "entry (docs/scene-format.md) to edit its placement");
}

size_t SceneHandle::entryIndex(const Key& key, const char* array) const {
  static const nlohmann::json none = nlohmann::json::array();
  const nlohmann::json& entries = document_.contains(array) ? document_.at(array) : none;
  if (const auto* index = std::get_if<int64_t>(&key)) {
    const int64_t n = int64_t(entries.size());
    if (*index < -n || *index >= n)
      throw InputError(name_ + ": " + array + "[" + std::to_string(*index) +
                       "]: out of range; the scene has " + std::to_string(n));
    return size_t(*index < 0 ? *index + n : *index);
  }
  const std::string& wanted = std::get<std::string>(key);
  std::vector<size_t> found;
  std::string names;
  for (size_t i = 0; i < entries.size(); ++i) {
    const nlohmann::json& e = entries[i];
    const std::string name = e.contains("id") && e["id"].is_string()       ? e["id"].get<std::string>()
                             : e.contains("name") && e["name"].is_string() ? e["name"].get<std::string>()
                             : e.contains("type") && e["type"].is_string() ? e["type"].get<std::string>()
                                                                           : "";
    if (name == wanted) found.push_back(i);
    names += (names.empty() ? "" : ", ") + name;
  }
  if (found.size() == 1) return found[0];
  if (found.empty())
    throw InputError(name_ + ": " + array + ": none is named '" + wanted +
                     "'; the names are: " + (names.empty() ? "(none)" : names));
  throw InputError(name_ + ": " + array + ": " + std::to_string(found.size()) + " entries are named '" +
                   wanted + "'; give an \"id\" to one, or its index");
}

void SceneHandle::setCamera(const nlohmann::json& patch) {
  const nlohmann::json camera = merged(
      json_ ? document_.value("camera", cameraJson(scene_->cameraParams)) : cameraJson(scene_->cameraParams),
      patch);
  scene_->cameraParams = JsonEntryReader(*scene_, name_).camera(camera);
  scene_->update();
  if (json_) document_["camera"] = camera;
}

void SceneHandle::setMaterial(const std::string& name, const nlohmann::json& patch) {
  const auto& names = scene_->materialNames;
  const auto it = std::find(names.begin(), names.end(), name);
  if (it == names.end()) {
    std::string valid;
    for (const std::string& n : names) valid += (valid.empty() ? "" : ", ") + n;
    throw InputError(name_ + ": materials: no material '" + name + "'; the materials are: " + valid);
  }
  // glTF scenes keep their edited materials here too, so a later edit can change one key.
  const bool known = document_.contains("materials") && document_["materials"].contains(name);
  const nlohmann::json base = known ? document_["materials"][name] : nlohmann::json::object();
  const nlohmann::json material =
      merged(retyped(base, patch, [](const std::string&) { return false; }), patch);
  if (!material.contains("type"))
    throw InputError(
        name_ + ": materials." + name +
        ": a glTF material is replaced by a whole material of the JSON format: give its \"type\" "
        "(docs/scene-format.md)");
  JsonEntryReader reader(*scene_, name_);
  std::unique_ptr<Material> replacement = reader.material(material, name);
  reader.adoptInto(*scene_);
  scene_->replaceMaterial(size_t(it - names.begin()), std::move(replacement));
  document_["materials"][name] = material;
}

void SceneHandle::setShape(const Key& key, const nlohmann::json& patch) {
  requireJson("shapes");
  const size_t k = entryIndex(key, "shapes");
  const std::string path = "shapes[" + std::to_string(k) + "]";
  const nlohmann::json& old = document_["shapes"][k];
  const nlohmann::json shape = merged(retyped(old, patch, shadingKey), patch);
  const JsonSceneIndex::Range& range = index_.shapes[k];
  JsonEntryReader reader(*scene_, name_);
  if (range.mesh) {
    // A mesh entry moves as a whole: every glTF primitive it placed, where each is an instance.
    for (const auto& [key, value] : patch.items())
      if (key != "transform")
        throw InputError(name_ + ": " + path + "." + key +
                         ": only a mesh entry's transform can change without loading the scene again");
    const nlohmann::json identity = nlohmann::json::object();
    const Mat4 after = reader.transform(shape.value("transform", identity), path + ".transform");
    for (size_t i = range.first; i < range.first + range.count; ++i)
      if (!scene_->meshes[i].toWorld || !scene_->meshes[i].inFile)
        throw InputError(name_ + ": " + path +
                         ".transform: this file's meshes were placed in world space when loaded (each is "
                         "used once), so moving them means loading the scene again; meshes used by several "
                         "nodes are instances and move without a reload");
    std::vector<std::pair<size_t, Mat4>> placements;
    for (size_t i = range.first; i < range.first + range.count; ++i) {
      placements.push_back({i, after * *scene_->meshes[i].inFile});
      if (!MeshInstance::placeable(placements.back().second))
        throw InputError(name_ + ": " + path + ".transform: not invertible, or not finite once composed");
    }
    scene_->setMeshTransforms(placements);
  } else {
    Scene::ShapeEntry entry = reader.shape(shape, path);
    reader.adoptInto(*scene_);
    bool moved = false;
    for (const auto& [key, value] : patch.items()) moved = moved || !shadingKey(key);
    Scene::ShapeEntry& current = scene_->shapes[range.first];
    current.name = entry.name;
    current.material = entry.material;
    current.emission = entry.emission;
    current.twoSidedEmission = entry.twoSidedEmission;
    if (moved)
      scene_->replaceShape(range.first, std::move(entry.shape));
    else
      scene_->update();
  }
  document_["shapes"][k] = shape;
}

void SceneHandle::setLight(const Key& key, const nlohmann::json& patch) {
  requireJson("lights");
  const size_t k = entryIndex(key, "lights");
  const nlohmann::json& old = document_["lights"][k];
  const nlohmann::json light =
      merged(retyped(old, patch, [](const std::string& key) { return key == "id" || key == "name"; }), patch);
  scene_->lights[index_.lights[k]] =
      JsonEntryReader(*scene_, name_).light(light, "lights[" + std::to_string(k) + "]");
  scene_->update();
  document_["lights"][k] = light;
}

void SceneHandle::setBackground(const nlohmann::json& value) {
  const Color background = JsonNode(value, "render.background", name_).color();
  scene_->background = background;
  scene_->environmentMap = nullptr;
  scene_->update();
  if (!json_) return;
  document_["render"]["background"] = value;
  document_.erase("environment");  // the format takes one or the other
}

}  // namespace ember::python
