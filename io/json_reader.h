// A read-only view of one JSON value that knows its path in the document, so every complaint about
// bad input can name the file and the exact place ("shapes[3].radius: expected a number > 0").
// Objects are checked for unknown keys, which are reported with the list of valid ones.
#pragma once

#include "core/math.h"
#include "io/input_error.h"

#include <nlohmann/json.hpp>

#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>

namespace ember {

class JsonNode {
 public:
  JsonNode(const nlohmann::json& value, std::string path, std::string file)
      : value_(&value), path_(std::move(path)), file_(std::move(file)) {}

  // Parses a whole file; a syntax error names the line and column.
  static nlohmann::json parseFile(const std::string& file);

  [[noreturn]] void fail(std::string_view message) const;
  const std::string& path() const { return path_; }
  const std::string& file() const { return file_; }
  const nlohmann::json& raw() const { return *value_; }

  // Object access.
  void requireObject() const;
  void allowKeys(std::initializer_list<std::string_view> keys) const;
  bool has(std::string_view key) const;
  JsonNode at(std::string_view key) const;  // required member
  std::optional<JsonNode> find(std::string_view key) const;

  // Array access.
  size_t arraySize() const;
  JsonNode operator[](size_t i) const;

  bool isObject() const { return value_->is_object(); }
  bool isArray() const { return value_->is_array(); }
  bool isString() const { return value_->is_string(); }
  bool isNumber() const { return value_->is_number(); }

  // Typed values; each checks type, finiteness and the stated range.
  float number() const;
  float positive() const;     // > 0
  float nonNegative() const;  // >= 0
  int integer(int min, int max) const;
  uint64_t unsignedInteger() const;
  bool boolean() const;
  std::string string() const;
  Vec2 vec2() const;
  Vec3 vec3() const;
  Vec3 direction() const;  // non-zero, returned normalised
  Color color() const;     // three numbers >= 0, or one number >= 0 for grey

  // Shorthands for optional members with defaults.
  float number(std::string_view key, float fallback) const;
  float positive(std::string_view key, float fallback) const;
  float nonNegative(std::string_view key, float fallback) const;
  bool boolean(std::string_view key, bool fallback) const;
  Color color(std::string_view key, const Color& fallback) const;

 private:
  const nlohmann::json* value_;
  std::string path_;
  std::string file_;
};

}  // namespace ember
