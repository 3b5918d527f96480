#include "io/json_reader.h"

#include <fstream>
#include <sstream>

namespace ember {

nlohmann::json JsonNode::parseFile(const std::string& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file + ": cannot open file");
  try {
    return nlohmann::json::parse(in, nullptr, true, /*ignore_comments=*/true);
  } catch (const nlohmann::json::parse_error& e) {
    // nlohmann's message already carries "at line L, column C".
    throw InputError(file + ": invalid JSON: " + e.what());
  } catch (const nlohmann::json::exception& e) {
    // A number too large for a double ("888e888", found by fuzz/fuzz_scene_json) is out_of_range.
    throw InputError(file + ": invalid JSON: " + e.what());
  }
}

void JsonNode::fail(std::string_view message) const {
  throw InputError(file_ + ": " + (path_.empty() ? std::string("(top level)") : path_) + ": " +
                   std::string(message));
}

static std::string describe(const nlohmann::json& v) {
  switch (v.type()) {
    case nlohmann::json::value_t::null:
      return "null";
    case nlohmann::json::value_t::object:
      return "an object";
    case nlohmann::json::value_t::array:
      return "an array";
    case nlohmann::json::value_t::string:
      return "a string";
    case nlohmann::json::value_t::boolean:
      return "a boolean";
    default:
      return "a number";
  }
}

void JsonNode::requireObject() const {
  if (!value_->is_object()) fail("expected an object, found " + describe(*value_));
}

void JsonNode::allowKeys(std::initializer_list<std::string_view> keys) const {
  requireObject();
  for (auto it = value_->begin(); it != value_->end(); ++it) {
    bool known = false;
    for (std::string_view k : keys) known = known || it.key() == k;
    if (known) continue;
    std::string valid;
    for (std::string_view k : keys) valid.append(valid.empty() ? "" : ", ").append(k);
    JsonNode(*it, path_.empty() ? it.key() : path_ + "." + it.key(), file_)
        .fail("unknown key; valid keys here are: " + valid);
  }
}

bool JsonNode::has(std::string_view key) const {
  return value_->is_object() && value_->contains(key);
}

JsonNode JsonNode::at(std::string_view key) const {
  requireObject();
  const std::string child = path_.empty() ? std::string(key) : path_ + "." + std::string(key);
  if (!value_->contains(key)) JsonNode(*value_, child, file_).fail("required but missing");
  return JsonNode((*value_)[std::string(key)], child, file_);
}

std::optional<JsonNode> JsonNode::find(std::string_view key) const {
  if (!has(key)) return std::nullopt;
  return at(key);
}

size_t JsonNode::arraySize() const {
  if (!value_->is_array()) fail("expected an array, found " + describe(*value_));
  return value_->size();
}

JsonNode JsonNode::operator[](size_t i) const {
  arraySize();
  return JsonNode((*value_)[i], path_ + "[" + std::to_string(i) + "]", file_);
}

float JsonNode::number() const {
  if (!value_->is_number()) fail("expected a number, found " + describe(*value_));
  const double v = value_->get<double>();
  if (!std::isfinite(v) || std::abs(v) > 3.0e38) fail("expected a finite number");
  return float(v);
}

float JsonNode::positive() const {
  const float v = value_->is_number() ? number() : 0.0f;
  if (!value_->is_number() || !(v > 0.0f)) fail("expected a number > 0");
  return v;
}

float JsonNode::nonNegative() const {
  const float v = value_->is_number() ? number() : -1.0f;
  if (!value_->is_number() || !(v >= 0.0f)) fail("expected a number >= 0");
  return v;
}

int JsonNode::integer(int min, int max) const {
  const std::string range =
      "expected an integer in [" + std::to_string(min) + ", " + std::to_string(max) + "]";
  if (!value_->is_number()) fail(range);
  const double v = value_->get<double>();
  if (!std::isfinite(v) || v != std::floor(v) || v < min || v > max) fail(range);
  return int(v);
}

uint64_t JsonNode::unsignedInteger() const {
  if (!value_->is_number_unsigned()) fail("expected an integer >= 0");
  return value_->get<uint64_t>();
}

bool JsonNode::boolean() const {
  if (!value_->is_boolean()) fail("expected true or false, found " + describe(*value_));
  return value_->get<bool>();
}

std::string JsonNode::string() const {
  if (!value_->is_string()) fail("expected a string, found " + describe(*value_));
  return value_->get<std::string>();
}

Vec2 JsonNode::vec2() const {
  if (!value_->is_array() || value_->size() != 2) fail("expected an array of 2 numbers");
  return {(*this)[0].number(), (*this)[1].number()};
}

Vec3 JsonNode::vec3() const {
  if (!value_->is_array() || value_->size() != 3) fail("expected an array of 3 numbers");
  return {(*this)[0].number(), (*this)[1].number(), (*this)[2].number()};
}

Vec3 JsonNode::direction() const {
  const Vec3 v = vec3();
  const float len = glm::length(v);
  if (!(len > 0.0f) || !std::isfinite(len)) fail("expected a non-zero direction");
  return v / len;
}

Color JsonNode::color() const {
  if (value_->is_number()) return Color(nonNegative());
  if (!value_->is_array() || value_->size() != 3)
    fail("expected a colour: an array of 3 numbers >= 0, or one number >= 0");
  return {(*this)[0].nonNegative(), (*this)[1].nonNegative(), (*this)[2].nonNegative()};
}

float JsonNode::number(std::string_view key, float fallback) const {
  return has(key) ? at(key).number() : fallback;
}
float JsonNode::positive(std::string_view key, float fallback) const {
  return has(key) ? at(key).positive() : fallback;
}
float JsonNode::nonNegative(std::string_view key, float fallback) const {
  return has(key) ? at(key).nonNegative() : fallback;
}
bool JsonNode::boolean(std::string_view key, bool fallback) const {
  return has(key) ? at(key).boolean() : fallback;
}
Color JsonNode::color(std::string_view key, const Color& fallback) const {
  return has(key) ? at(key).color() : fallback;
}

}  // namespace ember
