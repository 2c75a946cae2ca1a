#pragma once
// Camera intrinsics from photos of a planar chessboard (Zhang's method, through OpenCV's
// findChessboardCorners + cornerSubPix + calibrateCamera, as OpenCV's own calibration sample
// does it), or of a ChArUco board (OpenCV's aruco module: detectMarkers +
// interpolateCornersCharuco; the corners found, by id, go to the same calibrateCamera).
//
// Views where the board is not found are rejected and listed, not fatal; calibration needs at
// least kMinCalibrationViews views with the board. Results follow COLMAP's conventions: params in
// the order of the chosen COLMAP model, and the centre of the top-left pixel at (0.5, 0.5)
// (OpenCV puts it at (0, 0), so cx, cy are OpenCV's + 0.5).

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "calib/camera_file.h"

namespace igi::calib {

inline constexpr int kMinCalibrationViews = 3;

// A ChArUco view needs this many interpolated chessboard corners to be used.
inline constexpr int kMinCharucoCorners = 6;

// The calibration target: a chessboard, or a ChArUco board (a chessboard with ArUco markers).
enum class BoardType { kChessboard, kCharuco };
// "chessboard", "charuco" (the --board-type flag's spelling).
std::string_view BoardTypeName(BoardType type);
std::optional<BoardType> BoardTypeFromName(std::string_view name);

struct IntrinsicsOptions {
  BoardType board_type = BoardType::kChessboard;  // kChessboard (default) or kCharuco
  // chessboard: inner corners along a row / a column (OpenCV's board size), e.g. 9 x 6.
  // charuco: squares along X / Y (OpenCV's CharucoBoard squaresX, squaresY), e.g. 5 x 7.
  int board_cols = 0;
  int board_rows = 0;
  double square_m = 0;                     // side of one square in metres
  std::string dictionary = "DICT_4X4_50";  // charuco: OpenCV predefined ArUco dictionary name
  double marker_m = 0;                     // charuco: side of a marker in metres (< square_m)
  // COLMAP model of the result: kPinhole (no distortion), kOpenCv (k1, k2, p1, p2; the default)
  // or kFullOpenCv (k1, k2, p1, p2, k3; k4..k6 = 0 — OpenCV's default 5-coefficient model).
  ColmapCameraModel model = ColmapCameraModel::kOpenCv;
  bool fix_aspect_ratio = false;     // fx = fy (OpenCV CALIB_FIX_ASPECT_RATIO with ratio 1)
  bool zero_tangent_dist = false;    // p1 = p2 = 0
  bool fix_principal_point = false;  // cx, cy at the image centre
  int subpix_window = 11;            // cornerSubPix half window (OpenCV sample: 11)

  // Throws InputError naming the bad option.
  void Validate() const;
};

struct IntrinsicsSummary {
  CameraFile camera;              // model, size, params, rms_px, views, per-view, rejected
  std::vector<int> used_indices;  // index in the input list of every used view
};

// Detects the board in every image and calibrates. Throws InputError for an unreadable image or
// images of different sizes, and igi::Error (exit 1) when fewer than kMinCalibrationViews views
// show the board. Image names in the result are the file names (no folder).
IntrinsicsSummary CalibrateIntrinsics(const std::vector<std::filesystem::path>& images,
                                      const IntrinsicsOptions& options);

}  // namespace igi::calib
