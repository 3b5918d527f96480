#include "python/native/python_json.h"

#include "io/input_error.h"

#include <nanobind/stl/string.h>

namespace nb = nanobind;

namespace ember::python {

nlohmann::json toJson(nb::handle value, const std::string& where) {
  if (value.is_none()) return nullptr;
  if (nb::isinstance<nb::bool_>(value)) return nb::cast<bool>(value);
  if (nb::isinstance<nb::int_>(value)) {
    try {
      // As nlohmann's parser stores it: non-negative integers unsigned (JsonNode reads them so).
      if (nb::cast<bool>(value.attr("__ge__")(nb::int_(0)))) return nb::cast<uint64_t>(value);
      return nb::cast<int64_t>(value);
    } catch (const nb::cast_error&) {
      throw InputError(where + ": integer out of range");
    }
  }
  if (nb::isinstance<nb::float_>(value)) return nb::cast<double>(value);  // NaN stays: the loader names it
  if (nb::isinstance<nb::str>(value)) return nb::cast<std::string>(value);
  if (nb::isinstance<nb::dict>(value)) {
    nlohmann::json out = nlohmann::json::object();
    for (auto [k, v] : nb::borrow<nb::dict>(value)) {
      if (!nb::isinstance<nb::str>(k)) throw InputError(where + ": keys must be strings");
      const std::string key = nb::cast<std::string>(k);
      out[key] = toJson(v, where.empty() ? key : where + "." + key);
    }
    return out;
  }
  if (nb::isinstance<nb::list>(value) || nb::isinstance<nb::tuple>(value)) {
    nlohmann::json out = nlohmann::json::array();
    size_t i = 0;
    for (nb::handle item : value) out.push_back(toJson(item, where + "[" + std::to_string(i++) + "]"));
    return out;
  }
  if (nb::hasattr(value, "__fspath__")) return nb::cast<std::string>(nb::str(value.attr("__fspath__")()));
  if (nb::hasattr(value, "tolist")) return toJson(value.attr("tolist")(), where);
  throw InputError((where.empty() ? std::string("(top level)") : where) + ": a " +
                   nb::cast<std::string>(nb::str(value.type().attr("__name__"))) +
                   " cannot stand in a JSON scene (numbers, strings, lists and dicts can)");
}

nb::object fromJson(const nlohmann::json& value) {
  switch (value.type()) {
    case nlohmann::json::value_t::null:
      return nb::none();
    case nlohmann::json::value_t::boolean:
      return nb::bool_(value.get<bool>());
    case nlohmann::json::value_t::number_integer:
      return nb::int_(value.get<int64_t>());
    case nlohmann::json::value_t::number_unsigned:
      return nb::int_(value.get<uint64_t>());
    case nlohmann::json::value_t::number_float:
      return nb::float_(value.get<double>());
    case nlohmann::json::value_t::string:
      return nb::str(value.get<std::string>().c_str());
    case nlohmann::json::value_t::array: {
      nb::list out;
      for (const auto& item : value) out.append(fromJson(item));
      return out;
    }
    case nlohmann::json::value_t::object: {
      nb::dict out;
      for (const auto& [k, v] : value.items()) out[k.c_str()] = fromJson(v);
      return out;
    }
    default:
      return nb::none();
  }
}

}  // namespace ember::python
