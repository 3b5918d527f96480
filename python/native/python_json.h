// Python values to and from nlohmann::json: the module's dicts are scenes and entries of the JSON
// format, read by the same loader as files (docs/scene-format.md).
#pragma once

#include <nanobind/nanobind.h>
#include <nlohmann/json.hpp>

#include <string>

namespace ember::python {

// dict, list, tuple, str, bool, int, float, None, numpy arrays and scalars (through tolist()) and
// path-like objects; anything else raises ember.SceneError naming `where` (a JSON path).
nlohmann::json toJson(nanobind::handle value, const std::string& where);
nanobind::object fromJson(const nlohmann::json& value);

}  // namespace ember::python
