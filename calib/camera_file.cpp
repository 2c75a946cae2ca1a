#include "calib/camera_file.h"

#include <fmt/format.h>

#include <cmath>
#include <optional>
#include <string_view>

#include "tools/common/enum_names.h"
#include "tools/common/error.h"
#include "tools/common/json.h"

namespace igi::calib {
namespace {

// 0 for a value outside the enum.
size_t NumParams(ColmapCameraModel model) {
  switch (model) {
    case ColmapCameraModel::kSimplePinhole:
      return 3;
    case ColmapCameraModel::kPinhole:
    case ColmapCameraModel::kSimpleRadial:
      return 4;
    case ColmapCameraModel::kRadial:
      return 5;
    case ColmapCameraModel::kOpenCv:
      return 8;
    case ColmapCameraModel::kFullOpenCv:
      return 12;
  }
  return 0;
}

// `unknown_model`: the "model" text of a file that names no model of ColmapCameraModel.
void Validate(const CameraFile& camera, const std::string& file,
              const std::optional<std::string>& unknown_model = std::nullopt) {
  ProblemList problems;
  const std::string model(ColmapCameraModelName(camera.model));
  const size_t count = unknown_model ? 0 : NumParams(camera.model);
  if (!camera.HasIntrinsics() && !unknown_model) {
    if (!camera.vignetting) {
      problems.Add(file, "params", "absent", "a camera.json holds intrinsics, vignetting or both");
    }
  } else if (count == 0) {
    problems.Add(file, "model", unknown_model.value_or(model),
                 "must be SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL, RADIAL, OPENCV or FULL_OPENCV");
  } else if (camera.params.size() != count) {
    problems.Add(file, "params", std::to_string(camera.params.size()) + " values",
                 model + " needs " + std::to_string(count));
  }
  if (camera.width <= 0) problems.Add(file, "width", std::to_string(camera.width), "must be > 0");
  if (camera.height <= 0) {
    problems.Add(file, "height", std::to_string(camera.height), "must be > 0");
  }
  if (!camera.params.empty() && !(camera.params[0] > 0)) {
    problems.Add(file, "params[0]", std::to_string(camera.params[0]), "focal length must be > 0");
  }
  if (camera.vignetting) {
    const Vignetting& v = camera.vignetting->model;
    // V must stay positive over the image (r² ≤ 1) for the fall-off to be divided out.
    if (!(std::abs(v.k1) <= 2) || !(std::abs(v.k2) <= 2) || !(v.Factor(1.0) > 0.01) ||
        !(v.Factor(0.5) > 0.01)) {
      problems.Add(file, "vignetting", fmt::format("k1 {:g}, k2 {:g}", v.k1, v.k2),
                   "|k1|, |k2| ≤ 2 and 1 + k1 r² + k2 r⁴ > 0.01 over the image");
    }
  }
  problems.ThrowIfAny();
}

// Whether the model's parameters begin (f, cx, cy) rather than (fx, fy, cx, cy).
bool OneFocal(ColmapCameraModel model) {
  return model == ColmapCameraModel::kSimplePinhole || model == ColmapCameraModel::kSimpleRadial ||
         model == ColmapCameraModel::kRadial;
}

}  // namespace

double CameraFile::principal_x_px() const {
  return HasIntrinsics() ? params[OneFocal(model) ? 1 : 2] : 0.5 * width;
}
double CameraFile::principal_y_px() const {
  return HasIntrinsics() ? params[OneFocal(model) ? 2 : 3] : 0.5 * height;
}

constexpr EnumNames<ColmapCameraModel, 6> kColmapCameraModelNames{
    {{ColmapCameraModel::kSimplePinhole, "SIMPLE_PINHOLE"},
     {ColmapCameraModel::kPinhole, "PINHOLE"},
     {ColmapCameraModel::kSimpleRadial, "SIMPLE_RADIAL"},
     {ColmapCameraModel::kRadial, "RADIAL"},
     {ColmapCameraModel::kOpenCv, "OPENCV"},
     {ColmapCameraModel::kFullOpenCv, "FULL_OPENCV"}}};

std::string_view ColmapCameraModelName(ColmapCameraModel model) {
  return kColmapCameraModelNames.Name(model);
}
std::optional<ColmapCameraModel> ColmapCameraModelFromName(std::string_view name) {
  return kColmapCameraModelNames.FromName(name);
}

void WriteCameraFile(const std::filesystem::path& path, const CameraFile& camera) {
  Validate(camera, path.string());
  Json json;
  json["format"] = "igi-camera";
  json["version"] = 1;
  if (camera.HasIntrinsics()) json["model"] = std::string(ColmapCameraModelName(camera.model));
  json["width"] = camera.width;
  json["height"] = camera.height;
  if (camera.HasIntrinsics()) json["params"] = camera.params;
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
  if (const auto& v = camera.vignetting) {
    json["vignetting"] = {{"k1", v->model.k1},   {"k2", v->model.k2},     {"method", v->method},
                          {"rms_ln", v->rms_ln}, {"samples", v->samples}, {"photos", v->photos}};
  }
  WriteJsonFile(path, json, 1);
}

CameraFile ReadCameraFile(const std::filesystem::path& path) {
  const std::string file = path.string();
  const Json json = ReadJsonFile(path);
  ProblemList problems;
  const JsonCursor root = JsonCursor::Root(json, file, &problems);
  CameraFile camera;
  if (!root.ExpectObject({"format", "version", "model", "width", "height", "params", "rms_px",
                          "views", "per_view_rms_px", "rejected_views", "board", "flags",
                          "vignetting"})) {
    problems.ThrowIfAny();
  }
  if (auto format = root["format"].Enum({"igi-camera"})) (void)format;
  if (root["version"].present()) root["version"].Integer(NumberRule::Between(1, 1));
  std::optional<std::string> unknown_model;
  // The intrinsics are optional as a pair: a file may hold the vignetting alone.
  const bool intrinsics =
      root["model"].present() || root["params"].present() || !root["vignetting"].present();
  if (!intrinsics) {
    // Neither key: HasIntrinsics() is false.
  } else if (auto model = root["model"].NonEmptyString()) {
    if (const auto known = ColmapCameraModelFromName(*model)) {
      camera.model = *known;
    } else {
      unknown_model = *model;
    }
  }
  if (auto w = root["width"].Integer(NumberRule::Positive())) camera.width = static_cast<int>(*w);
  if (auto h = root["height"].Integer(NumberRule::Positive())) camera.height = static_cast<int>(*h);
  if (intrinsics) {
    if (auto params = root["params"].Numbers(0)) camera.params = *params;
  }
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
  if (root["vignetting"].present()) {
    const JsonCursor v = root["vignetting"];
    v.ExpectObject({"k1", "k2", "method", "rms_ln", "samples", "photos"});
    CameraVignetting vignetting;
    vignetting.model.k1 = v["k1"].Number().value_or(0);
    vignetting.model.k2 = v["k2"].Number().value_or(0);
    if (v["method"].present()) vignetting.method = v["method"].String().value_or("");
    if (v["rms_ln"].present()) {
      vignetting.rms_ln = v["rms_ln"].Number(NumberRule::NonNegative()).value_or(0);
    }
    if (v["samples"].present()) {
      vignetting.samples = int(v["samples"].Integer(NumberRule::NonNegative()).value_or(0));
    }
    if (v["photos"].present()) {
      vignetting.photos = int(v["photos"].Integer(NumberRule::NonNegative()).value_or(0));
    }
    camera.vignetting = vignetting;
  }
  problems.ThrowIfAny();
  Validate(camera, file, unknown_model);
  return camera;
}

}  // namespace igi::calib
