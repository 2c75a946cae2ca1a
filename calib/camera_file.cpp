#include "calib/camera_file.h"

#include <array>
#include <string_view>
#include <utility>

#include "tools/common/error.h"
#include "tools/common/json.h"

namespace igi::calib {
namespace {

// The COLMAP perspective models a camera.json may name, with their parameter counts. (Fisheye
// models are left out: nothing in igi calibrates them.)
constexpr std::array<std::pair<std::string_view, size_t>, 6> kModels = {{{"SIMPLE_PINHOLE", 3},
                                                                         {"PINHOLE", 4},
                                                                         {"SIMPLE_RADIAL", 4},
                                                                         {"RADIAL", 5},
                                                                         {"OPENCV", 8},
                                                                         {"FULL_OPENCV", 12}}};

size_t NumParams(std::string_view model) {
  for (const auto& [name, count] : kModels) {
    if (name == model) return count;
  }
  return 0;
}

void Validate(const CameraFile& camera, const std::string& file) {
  ProblemList problems;
  const size_t count = NumParams(camera.model);
  if (count == 0) {
    problems.Add(file, "model", camera.model,
                 "must be SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL, RADIAL, OPENCV or FULL_OPENCV");
  } else if (camera.params.size() != count) {
    problems.Add(file, "params", std::to_string(camera.params.size()) + " values",
                 camera.model + " needs " + std::to_string(count));
  }
  if (camera.width <= 0) problems.Add(file, "width", std::to_string(camera.width), "must be > 0");
  if (camera.height <= 0) {
    problems.Add(file, "height", std::to_string(camera.height), "must be > 0");
  }
  if (!camera.params.empty() && !(camera.params[0] > 0)) {
    problems.Add(file, "params[0]", std::to_string(camera.params[0]), "focal length must be > 0");
  }
  problems.ThrowIfAny();
}

}  // namespace

void WriteCameraFile(const std::filesystem::path& path, const CameraFile& camera) {
  Validate(camera, path.string());
  Json json;
  json["format"] = "igi-camera";
  json["version"] = 1;
  json["model"] = camera.model;
  json["width"] = camera.width;
  json["height"] = camera.height;
  json["params"] = camera.params;
  json["rms_px"] = camera.rms_px;
  json["views"] = camera.views;
  if (!camera.per_view_rms_px.empty()) json["per_view_rms_px"] = camera.per_view_rms_px;
  Json rejected = Json::array();
  for (const RejectedView& view : camera.rejected_views) {
    rejected.push_back({{"file", view.file}, {"reason", view.reason}});
  }
  json["rejected_views"] = rejected;
  if (camera.board_cols > 0) {
    json["board"] = {
        {"cols", camera.board_cols}, {"rows", camera.board_rows}, {"square_m", camera.square_m}};
  }
  json["flags"] = camera.flags;
  WriteJsonFile(path, json, 1);
}

CameraFile ReadCameraFile(const std::filesystem::path& path) {
  const std::string file = path.string();
  const Json json = ReadJsonFile(path);
  ProblemList problems;
  const JsonCursor root = JsonCursor::Root(json, file, &problems);
  CameraFile camera;
  if (!root.ExpectObject({"format", "version", "model", "width", "height", "params", "rms_px",
                          "views", "per_view_rms_px", "rejected_views", "board", "flags"})) {
    problems.ThrowIfAny();
  }
  if (auto format = root["format"].Enum({"igi-camera"})) (void)format;
  if (root["version"].present()) root["version"].Integer(NumberRule::Between(1, 1));
  if (auto model = root["model"].NonEmptyString()) camera.model = *model;
  if (auto w = root["width"].Integer(NumberRule::Positive())) camera.width = static_cast<int>(*w);
  if (auto h = root["height"].Integer(NumberRule::Positive())) camera.height = static_cast<int>(*h);
  if (auto params = root["params"].Numbers(0)) camera.params = *params;
  if (root["rms_px"].present()) camera.rms_px = root["rms_px"].Number().value_or(-1);
  if (root["views"].present()) {
    const size_t n = root["views"].ArraySize();
    for (size_t i = 0; i < n; ++i) {
      if (auto v = root["views"][i].String()) camera.views.push_back(*v);
    }
  }
  if (root["per_view_rms_px"].present()) {
    camera.per_view_rms_px = root["per_view_rms_px"]
                                 .Numbers(0, NumberRule::NonNegative())
                                 .value_or(std::vector<double>{});
  }
  if (root["rejected_views"].present()) {
    const size_t n = root["rejected_views"].ArraySize();
    for (size_t i = 0; i < n; ++i) {
      const JsonCursor view = root["rejected_views"][i];
      view.ExpectObject({"file", "reason"});
      camera.rejected_views.push_back(
          {view["file"].String().value_or(""), view["reason"].String().value_or("")});
    }
  }
  if (root["board"].present()) {
    const JsonCursor board = root["board"];
    board.ExpectObject({"cols", "rows", "square_m"});
    camera.board_cols = static_cast<int>(board["cols"].Integer(NumberRule::Positive()).value_or(0));
    camera.board_rows = static_cast<int>(board["rows"].Integer(NumberRule::Positive()).value_or(0));
    camera.square_m = board["square_m"].Number(NumberRule::Positive()).value_or(0);
  }
  if (root["flags"].present()) {
    const size_t n = root["flags"].ArraySize();
    for (size_t i = 0; i < n; ++i) {
      if (auto f = root["flags"][i].String()) camera.flags.push_back(*f);
    }
  }
  problems.ThrowIfAny();
  Validate(camera, file);
  return camera;
}

}  // namespace igi::calib
