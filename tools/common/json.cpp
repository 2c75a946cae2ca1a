#include "tools/common/json.h"

#include <cmath>
#include <sstream>

#include "tools/common/atomic_file.h"

namespace igi {

Json ParseJson(std::string_view text, const std::string& source) {
  try {
    return Json::parse(text.begin(), text.end());
  } catch (const nlohmann::json::exception& e) {
    // nlohmann's message: "[json.exception.parse_error.101] parse error at line 3, column 5: ..."
    // (number overflow, e.g. 1e999, arrives as out_of_range.406).
    std::string message = e.what();
    const auto at = message.find("] ");
    if (at != std::string::npos) message = message.substr(at + 2);
    throw InputError(DescribeProblem(source, "", "", "invalid JSON: " + message));
  }
}

Json ReadJsonFile(const std::filesystem::path& path) {
  return ParseJson(ReadFileToString(path), path.string());
}

void WriteJsonFile(const std::filesystem::path& path, const Json& value, int indent) {
  WriteFileAtomic(path, value.dump(indent) + "\n");
}

std::string NumberRule::Describe() const {
  std::ostringstream out;
  out.precision(10);
  const bool has_min = std::isfinite(min);
  const bool has_max = std::isfinite(max);
  if (has_min && has_max) {
    out << "must be in " << (min_exclusive ? "(" : "[") << min << ", " << max
        << (max_exclusive ? ")" : "]");
  } else if (has_min) {
    out << "must be " << (min_exclusive ? "> " : ">= ") << min;
  } else if (has_max) {
    out << "must be " << (max_exclusive ? "< " : "<= ") << max;
  } else {
    out << "must be a finite number";
  }
  return out.str();
}

bool NumberRule::Accepts(double v) const {
  if (!std::isfinite(v)) return false;
  if (min_exclusive ? !(v > min) : !(v >= min)) return false;
  if (max_exclusive ? !(v < max) : !(v <= max)) return false;
  return true;
}

JsonCursor::JsonCursor(const Json* value, std::string file, std::string path,
                       ProblemList* problems)
    : value_(value), file_(std::move(file)), path_(std::move(path)), problems_(problems) {}

JsonCursor JsonCursor::Root(const Json& document, std::string file, ProblemList* problems) {
  return JsonCursor(&document, std::move(file), "", problems);
}

JsonCursor JsonCursor::operator[](std::string_view key) const {
  std::string child_path = path_.empty() ? std::string(key) : path_ + "." + std::string(key);
  const Json* child = nullptr;
  if (value_ != nullptr && value_->is_object()) {
    auto it = value_->find(std::string(key));
    if (it != value_->end()) child = &*it;
  }
  return JsonCursor(child, file_, std::move(child_path), problems_);
}

JsonCursor JsonCursor::operator[](size_t index) const {
  std::string child_path = path_ + "[" + std::to_string(index) + "]";
  const Json* child = nullptr;
  if (value_ != nullptr && value_->is_array() && index < value_->size()) child = &(*value_)[index];
  return JsonCursor(child, file_, std::move(child_path), problems_);
}

void JsonCursor::Problem(const std::string& rule) const {
  if (problems_ == nullptr) throw InputError(DescribeProblem(file_, path_, Excerpt(), rule));
  problems_->Add(file_, path_.empty() ? "(top level)" : path_, Excerpt(), rule);
}

std::string JsonCursor::Excerpt() const {
  if (value_ == nullptr) return "";
  std::string text = value_->dump();
  if (text.size() > 40) text = text.substr(0, 37) + "...";
  return text;
}

bool JsonCursor::RequirePresent() const {
  if (present()) return true;
  Problem(value_ == nullptr ? "missing required key" : "must not be null");
  return false;
}

bool JsonCursor::ExpectObject(const std::vector<std::string_view>& allowed) const {
  if (!RequirePresent()) return false;
  if (!value_->is_object()) {
    Problem("must be an object");
    return false;
  }
  for (const auto& item : value_->items()) {
    bool known = false;
    for (std::string_view a : allowed) known = known || item.key() == a;
    if (known) continue;
    std::string list;
    for (std::string_view a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
    (*this)[item.key()].Problem("unknown key (allowed: " + list + ")");
  }
  return true;
}

std::vector<std::string> JsonCursor::ObjectKeys() const {
  std::vector<std::string> keys;
  if (!RequirePresent()) return keys;
  if (!value_->is_object()) {
    Problem("must be an object");
    return keys;
  }
  for (const auto& item : value_->items()) keys.push_back(item.key());
  return keys;
}

size_t JsonCursor::ArraySize(size_t min_size) const {
  if (!RequirePresent()) return 0;
  if (!value_->is_array()) {
    Problem("must be an array");
    return 0;
  }
  if (value_->size() < min_size) {
    Problem("must have at least " + std::to_string(min_size) + " element(s)");
  }
  return value_->size();
}

std::optional<double> JsonCursor::Number(const NumberRule& rule) const {
  if (!RequirePresent()) return std::nullopt;
  if (!value_->is_number()) {
    Problem("must be a number");
    return std::nullopt;
  }
  const double v = value_->get<double>();
  if (!rule.Accepts(v)) {
    Problem(rule.Describe());
    return std::nullopt;
  }
  return v;
}

std::optional<int64_t> JsonCursor::Integer(const NumberRule& rule) const {
  if (!RequirePresent()) return std::nullopt;
  if (!value_->is_number_integer()) {
    Problem("must be an integer");
    return std::nullopt;
  }
  const int64_t v = value_->get<int64_t>();
  if (!rule.Accepts(static_cast<double>(v))) {
    Problem(rule.Describe());
    return std::nullopt;
  }
  return v;
}

std::optional<std::string> JsonCursor::String() const {
  if (!RequirePresent()) return std::nullopt;
  if (!value_->is_string()) {
    Problem("must be a string");
    return std::nullopt;
  }
  return value_->get<std::string>();
}

std::optional<std::string> JsonCursor::NonEmptyString() const {
  auto s = String();
  if (s && s->empty()) {
    Problem("must not be empty");
    return std::nullopt;
  }
  return s;
}

std::optional<bool> JsonCursor::Bool() const {
  if (!RequirePresent()) return std::nullopt;
  if (!value_->is_boolean()) {
    Problem("must be true or false");
    return std::nullopt;
  }
  return value_->get<bool>();
}

std::optional<std::string> JsonCursor::Enum(std::initializer_list<std::string_view> choices) const {
  auto s = String();
  if (!s) return std::nullopt;
  for (std::string_view c : choices) {
    if (*s == c) return s;
  }
  std::string list;
  for (std::string_view c : choices) list += (list.empty() ? "" : ", ") + std::string(c);
  Problem("must be one of: " + list);
  return std::nullopt;
}

std::optional<std::vector<double>> JsonCursor::Numbers(size_t count, const NumberRule& rule) const {
  if (!RequirePresent()) return std::nullopt;
  if (!value_->is_array() || (count != 0 && value_->size() != count)) {
    Problem(count != 0 ? "must be an array of " + std::to_string(count) + " numbers"
                       : "must be an array of numbers");
    return std::nullopt;
  }
  std::vector<double> out;
  bool ok = true;
  for (size_t i = 0; i < value_->size(); ++i) {
    auto v = (*this)[i].Number(rule);
    ok = ok && v.has_value();
    out.push_back(v.value_or(0.0));
  }
  if (!ok) return std::nullopt;
  return out;
}

std::optional<Eigen::Vector3d> JsonCursor::Vec3(const NumberRule& rule) const {
  auto v = Numbers(3, rule);
  if (!v) return std::nullopt;
  return Eigen::Vector3d((*v)[0], (*v)[1], (*v)[2]);
}

std::optional<Eigen::Vector3d> JsonCursor::Direction() const {
  auto v = Vec3();
  if (!v) return std::nullopt;
  const double n = v->norm();
  if (!(n > 1e-12)) {
    Problem("must be a non-zero direction");
    return std::nullopt;
  }
  return Eigen::Vector3d(*v / n);
}

std::optional<Eigen::Vector3d> JsonCursor::Rgb(const NumberRule& rule) const {
  if (IsNumber()) {
    auto v = Number(rule);
    if (!v) return std::nullopt;
    return Eigen::Vector3d(*v, *v, *v);
  }
  if (present() && !value_->is_array()) {
    Problem("must be a number or an RGB array of 3 numbers");
    return std::nullopt;
  }
  return Vec3(rule);
}

}  // namespace igi
