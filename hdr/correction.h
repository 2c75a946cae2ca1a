#pragma once
// What igi-hdr takes off a merged radiance map so that it is the scene's radiance in linear sRGB:
//   - the camera's vignetting, measured by igi-calib vignetting into camera.json: each pixel is
//     divided by V(r) = 1 + k1 r² + k2 r⁴ at its centre (calib/vignetting.h), r from the camera's
//     principal point (the image centre when camera.json holds no intrinsics);
//   - the camera's colour, measured by igi-calib colour into colour.json: each pixel's camera RGB
//     is multiplied by the 3×3 matrix to linear sRGB (calib/colour_chart.h). A matrix fitted to
//     raw camera RGB (input "camera_raw") needs raw input decoded without white balance or colour
//     matrix (RawInputOptions says so); one fitted to linear images ("linear") needs non-raw input.
// Both are linear, per pixel, so their order does not matter.

#include <filesystem>
#include <optional>
#include <string>

#include "calib/camera_file.h"
#include "calib/colour_chart.h"
#include "hdr/raw_decode.h"

namespace igi::hdr {

class RadianceCorrection {
 public:
  RadianceCorrection() = default;  // changes nothing
  // `camera_json` (its vignetting) and `colour_json` (its matrix), either empty for none.
  // Throws InputError naming the file when camera.json holds no vignetting, or a file breaks
  // its format's rules.
  RadianceCorrection(const std::filesystem::path& camera_json,
                     const std::filesystem::path& colour_json);

  bool empty() const { return !vignetting_ && !colour_; }
  const std::optional<calib::CameraFile>& camera() const { return vignetting_; }
  const std::optional<calib::ColourFile>& colour() const { return colour_; }
  // Throws InputError naming `file` when the image is not the size camera.json states, or, with
  // a colour matrix, not RGB or not the input kind (raw or not) the matrix was fitted to.
  void Check(const std::string& file, int width, int height, int channels, bool raw) const;
  // How raw files must be decoded for the colour matrix: `options` with camera RGB and no white
  // balance when the matrix expects them; unchanged otherwise.
  RawDecodeOptions RawInputOptions(RawDecodeOptions options) const;
  // Corrects rows [y0, y1) of a width × channels image held in `rows` (channels 3 with a colour
  // matrix, as Check requires).
  void Apply(float* rows, int y0, int y1, int width, int channels) const;

 private:
  std::filesystem::path camera_json_, colour_json_;
  std::optional<calib::CameraFile> vignetting_;  // with its vignetting set
  std::optional<calib::ColourFile> colour_;
};

}  // namespace igi::hdr
