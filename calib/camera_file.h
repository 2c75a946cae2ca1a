#pragma once
// camera.json (docs/file-formats.md, "format": "igi-camera", "version": 1): a camera's
// intrinsics as igi-calib intrinsics measures them and igi-register uses them, and its
// vignetting as igi-calib vignetting measures it and igi-hdr removes it. A file holds the
// intrinsics, the vignetting, or both.
//
//   {"format": "igi-camera", "version": 1, "model": "OPENCV", "width": 640, "height": 480,
//    "params": [fx, fy, cx, cy, k1, k2, p1, p2], "rms_px": 0.39, "views": ["left01.jpg", …],
//    "per_view_rms_px": [0.19, …], "rejected_views": [{"file": …, "reason": …}], "board": {…},
//    "vignetting": {"k1": -0.31, "k2": 0.04, "method": "flat_field", "rms_ln": 0.004,
//                   "samples": 6912, "photos": 4}}
//
// `params` follow COLMAP's model and order and COLMAP's pixel convention (the centre of the
// top-left pixel is (0.5, 0.5)); focal lengths and the principal point are in pixels.
// The reader is strict (unknown keys, wrong types, a wrong number of params are InputErrors naming
// the file and key).

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "calib/vignetting.h"

namespace igi::calib {

// The COLMAP perspective camera models a camera.json may name (fisheye models are left out:
// nothing in igi calibrates them), with their parameter counts: SIMPLE_PINHOLE 3, PINHOLE 4,
// SIMPLE_RADIAL 4, RADIAL 5, OPENCV 8, FULL_OPENCV 12.
enum class ColmapCameraModel {
  kSimplePinhole,
  kPinhole,
  kSimpleRadial,
  kRadial,
  kOpenCv,
  kFullOpenCv,
};
// COLMAP's name: "SIMPLE_PINHOLE", "PINHOLE", "SIMPLE_RADIAL", "RADIAL", "OPENCV", "FULL_OPENCV".
std::string_view ColmapCameraModelName(ColmapCameraModel model);
// The model a COLMAP name spells (exact case); nullopt for any other name.
std::optional<ColmapCameraModel> ColmapCameraModelFromName(std::string_view name);

struct RejectedView {
  std::string file;
  std::string reason;
};

// camera.json's "vignetting": the fall-off (calib/vignetting.h) and how it was measured.
struct CameraVignetting {
  Vignetting model;
  std::string method;  // "flat_field" or "overlap"
  double rms_ln = 0;   // RMS residual of the fit, ln units
  int samples = 0;     // blocks or pairs fitted
  int photos = 0;
};

struct CameraFile {
  // The intrinsics: `params` empty when the file holds the vignetting only.
  ColmapCameraModel model = ColmapCameraModel::kPinhole;  // "model": the COLMAP model name
  int width = 0;                                          // pixels
  int height = 0;                                         // pixels
  std::vector<double> params;                             // COLMAP order, pixels
  double rms_px = -1;                   // RMS reprojection error over every used view; -1 = unknown
  std::vector<std::string> views;       // files used
  std::vector<double> per_view_rms_px;  // one per used view (may be empty)
  std::vector<RejectedView> rejected_views;
  // Optional description of the target: cols x rows inner corners and the square size.
  int board_cols = 0;
  int board_rows = 0;
  double square_m = 0;
  std::vector<std::string> flags;  // calibration flags, e.g. "fix_aspect_ratio"
  std::optional<CameraVignetting> vignetting;

  bool HasIntrinsics() const { return !params.empty(); }
  // The principal point: the intrinsics' (cx, cy), else the image centre.
  double principal_x_px() const;
  double principal_y_px() const;
};

// Validates and writes `camera` atomically. Throws InputError when it breaks a rule (unknown
// model, wrong params count, non-positive size, neither intrinsics nor vignetting).
void WriteCameraFile(const std::filesystem::path& path, const CameraFile& camera);
// Reads and validates a camera.json; throws InputError listing every problem.
CameraFile ReadCameraFile(const std::filesystem::path& path);

}  // namespace igi::calib
