#pragma once
// Strict JSON reading for igi's files (docs/file-formats.md): an unknown key, a wrong type, a
// missing required key or an out-of-range value is a problem that names the file, the key path
// (e.g. `lights.lamp.intensity[2]`) and the rule broken. Problems are collected in a
// ProblemList so that one load reports every problem, not only the first.
//
// Objects keep the order of their keys (nlohmann::ordered_json), so files written back read
// like the ones the user wrote.

#include <Eigen/Core>
#include <filesystem>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "tools/common/error.h"

namespace igi {

using Json = nlohmann::ordered_json;

// Parses a JSON file; a syntax error is an InputError "FILE: line L, column C: REASON".
Json ReadJsonFile(const std::filesystem::path& path);
// Parses JSON text; `source` names it in errors.
Json ParseJson(std::string_view text, const std::string& source);
// Writes `value` with `indent` spaces atomically.
void WriteJsonFile(const std::filesystem::path& path, const Json& value, int indent = 1);

// Allowed range of a number. Bounds are inclusive unless marked exclusive; NaN and infinity are
// always rejected.
struct NumberRule {
  double min = -std::numeric_limits<double>::infinity();
  double max = std::numeric_limits<double>::infinity();
  bool min_exclusive = false;
  bool max_exclusive = false;

  static NumberRule Any() { return {}; }
  static NumberRule NonNegative() { return {0.0}; }
  static NumberRule Positive() { return {0.0, std::numeric_limits<double>::infinity(), true}; }
  static NumberRule Between(double lo, double hi) { return {lo, hi}; }
  // The rule in words, e.g. "must be > 0".
  std::string Describe() const;
  bool Accepts(double v) const;
};

// A read-only view of one value in a JSON document: where it is (file and key path) and where
// its problems go. A view of a missing key is "absent"; reading it as required reports it.
class JsonCursor {
 public:
  JsonCursor(const Json* value, std::string file, std::string path, ProblemList* problems);
  // The root of a document.
  static JsonCursor Root(const Json& document, std::string file, ProblemList* problems);

  const std::string& file() const { return file_; }
  const std::string& path() const { return path_; }
  // Present and not null (`"mask": null` counts as absent).
  bool present() const { return value_ != nullptr && !value_->is_null(); }
  const Json* raw() const { return value_; }
  ProblemList* problems() const { return problems_; }

  JsonCursor operator[](std::string_view key) const;
  JsonCursor operator[](size_t index) const;

  bool IsObject() const { return present() && value_->is_object(); }
  bool IsArray() const { return present() && value_->is_array(); }
  bool IsString() const { return present() && value_->is_string(); }
  bool IsNumber() const { return present() && value_->is_number(); }

  // Requires an object whose keys are all in `allowed`; reports each unknown key. Returns
  // whether the value is an object at all.
  bool ExpectObject(const std::vector<std::string_view>& allowed) const;
  // Requires an object (any keys); returns its keys in file order.
  std::vector<std::string> ObjectKeys() const;
  // Requires an array; returns its size (0 when not an array). `min_size` is checked too.
  size_t ArraySize(size_t min_size = 0) const;

  // Required reads: a missing key, wrong type or bad value is reported and nullopt returned.
  std::optional<double> Number(const NumberRule& rule = {}) const;
  std::optional<int64_t> Integer(const NumberRule& rule = {}) const;
  std::optional<std::string> String() const;
  std::optional<std::string> NonEmptyString() const;
  std::optional<bool> Bool() const;
  // One of a fixed set of strings.
  std::optional<std::string> Enum(std::initializer_list<std::string_view> choices) const;
  // An array of exactly `count` numbers (count 0 = any length).
  std::optional<std::vector<double>> Numbers(size_t count, const NumberRule& rule = {}) const;
  std::optional<Eigen::Vector3d> Vec3(const NumberRule& rule = {}) const;
  // A non-zero 3-vector, returned normalised.
  std::optional<Eigen::Vector3d> Direction() const;
  // An RGB triple, or one number meaning grey (docs/scene-format.md).
  std::optional<Eigen::Vector3d> Rgb(const NumberRule& rule = {}) const;

  // Reports a problem about this value: "FILE: PATH: VALUE: RULE".
  void Problem(const std::string& rule) const;
  // The value shortened for messages (at most ~40 characters).
  std::string Excerpt() const;

 private:
  bool RequirePresent() const;
  const Json* value_;
  std::string file_;
  std::string path_;
  ProblemList* problems_;
};

}  // namespace igi
