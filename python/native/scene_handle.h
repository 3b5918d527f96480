// A scene as the Python module holds it: built once by the loaders `ember render` uses, then edited
// in place. Edits are written in the JSON format's own terms (a material's keys, a shape's keys, the
// camera's keys), read by the loader's own code (JsonEntryReader) with its checks and messages, and
// applied through Scene's edit calls, which rebuild only what depends on them.
#pragma once

#include "io/scene_loader.h"

#include <nlohmann/json.hpp>

#include <memory>
#include <string>
#include <variant>

namespace ember::python {

class SceneHandle {
 public:
  // A scene file (JSON or glTF), as `ember render` loads it.
  static SceneHandle fromFile(const std::string& path, const LoadOptions& options);
  // A JSON-format document; `name` stands for its file in errors, and its folder resolves paths.
  static SceneHandle fromDocument(nlohmann::json document, const std::string& name);

  Scene& scene() { return *scene_; }
  const Scene& scene() const { return *scene_; }
  const std::string& name() const { return name_; }
  bool isJson() const { return json_; }
  // JSON scenes: the document with every edit applied (loading it gives the edited scene).
  const nlohmann::json& document() const { return document_; }

  using Key = std::variant<int64_t, std::string>;  // an entry's index, or its "id"/"name"
  // Each merges `patch` into the entry's JSON (a null value removes a key) and applies it.
  void setCamera(const nlohmann::json& patch);
  void setMaterial(const std::string& name, const nlohmann::json& patch);
  void setShape(const Key& key, const nlohmann::json& patch);
  void setLight(const Key& key, const nlohmann::json& patch);
  // The constant environment radiance (render.background: a number or r, g, b; 0 = none); it
  // replaces an environment map.
  void setBackground(const nlohmann::json& value);

  // Set while a render runs without the GIL: edits and other renders are refused meanwhile.
  bool busy = false;

 private:
  size_t entryIndex(const Key& key, const char* array) const;
  void requireJson(const char* what) const;

  std::unique_ptr<Scene> scene_;
  std::string name_;
  bool json_ = false;
  nlohmann::json document_ = nlohmann::json::object();
  JsonSceneIndex index_;
};

}  // namespace ember::python
