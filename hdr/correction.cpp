#include "hdr/correction.h"

#include <fmt/format.h>

#include "tools/common/error.h"

namespace igi::hdr {

RadianceCorrection::RadianceCorrection(const std::filesystem::path& camera_json,
                                       const std::filesystem::path& colour_json)
    : camera_json_(camera_json), colour_json_(colour_json) {
  if (!camera_json.empty()) {
    calib::CameraFile camera = calib::ReadCameraFile(camera_json);
    if (!camera.vignetting) {
      throw InputError(DescribeProblem(camera_json.string(), "vignetting", "absent",
                                       "measure it with igi-calib vignetting"));
    }
    vignetting_ = std::move(camera);
  }
  if (!colour_json.empty()) colour_ = calib::ReadColourFile(colour_json);
}

void RadianceCorrection::Check(const std::string& file, int width, int height, int channels,
                               bool raw) const {
  if (vignetting_ && (width != vignetting_->width || height != vignetting_->height)) {
    throw InputError(DescribeProblem(
        file, "", fmt::format("{}x{}", width, height),
        fmt::format("must be {}x{}, the size whose vignetting {} holds", vignetting_->width,
                    vignetting_->height, camera_json_.string())));
  }
  if (colour_ && channels != 3) {
    throw InputError(DescribeProblem(file, "", fmt::format("{} channels", channels),
                                     "a colour matrix needs RGB images"));
  }
  if (colour_ && raw != (colour_->input == calib::ColourInput::kCameraRaw)) {
    throw InputError(DescribeProblem(colour_json_.string(), "input",
                                     std::string(calib::ColourInputName(colour_->input)),
                                     fmt::format("the matrix was fitted to {} but {} is {}",
                                                 raw ? "linear images" : "raw camera RGB", file,
                                                 raw ? "a raw file" : "not a raw file")));
  }
}

RawDecodeOptions RadianceCorrection::RawInputOptions(RawDecodeOptions options) const {
  if (colour_ && colour_->input == calib::ColourInput::kCameraRaw) {
    options.color = RawColor::kRaw;
    options.white_balance = RawWhiteBalance::kNone;
  }
  return options;
}

void RadianceCorrection::Apply(float* rows, int y0, int y1, int width, int channels) const {
  const size_t row_values = size_t(width) * size_t(channels);
  if (vignetting_) {
    const calib::Vignetting& v = vignetting_->vignetting->model;
    const double cx = vignetting_->principal_x_px(), cy = vignetting_->principal_y_px();
    for (int y = y0; y < y1; ++y) {
      float* row = rows + size_t(y - y0) * row_values;
      for (int x = 0; x < width; ++x) {
        const double r2 =
            calib::VignettingRadius2(x + 0.5, y + 0.5, cx, cy, width, vignetting_->height);
        const float gain = float(1.0 / v.Factor(r2));
        for (int c = 0; c < channels; ++c) row[size_t(x) * size_t(channels) + size_t(c)] *= gain;
      }
    }
  }
  if (colour_) calib::ApplyColourMatrix(rows, size_t(y1 - y0) * size_t(width), colour_->matrix);
}

}  // namespace igi::hdr
