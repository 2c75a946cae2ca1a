#include "calib/intrinsics.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <opencv2/aruco/charuco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>

#include "tools/common/enum_names.h"
#include "tools/common/error.h"
#include "tools/common/image.h"
#include "tools/common/parallel.h"

namespace igi::calib {
namespace {

// An image as 8-bit grey for corner detection (Rec. 601 luma of the first three channels).
cv::Mat GreyImage(const Image& image) {
  cv::Mat grey(image.height, image.width, CV_8UC1);
  const int c = image.channels;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      const float* p = &image.pixels[(static_cast<size_t>(y) * image.width + x) * c];
      const float v = c >= 3 ? 0.299f * p[0] + 0.587f * p[1] + 0.114f * p[2] : p[0];
      grey.at<uint8_t>(y, x) = cv::saturate_cast<uint8_t>(std::lround(v * 255.0f));
    }
  }
  return grey;
}

struct Detection {
  int width = 0;
  int height = 0;
  std::optional<std::vector<cv::Point2f>> corners;  // nullopt: board not found
  std::vector<cv::Point3f> object_points;           // board frame, metres, per corner
  std::string reason = "board not found";
};

const std::map<std::string, cv::aruco::PREDEFINED_DICTIONARY_NAME>& Dictionaries() {
  using namespace cv::aruco;  // NOLINT: the enum's names
  static const std::map<std::string, PREDEFINED_DICTIONARY_NAME> kNames = {
      {"DICT_4X4_50", DICT_4X4_50},
      {"DICT_4X4_100", DICT_4X4_100},
      {"DICT_4X4_250", DICT_4X4_250},
      {"DICT_4X4_1000", DICT_4X4_1000},
      {"DICT_5X5_50", DICT_5X5_50},
      {"DICT_5X5_100", DICT_5X5_100},
      {"DICT_5X5_250", DICT_5X5_250},
      {"DICT_5X5_1000", DICT_5X5_1000},
      {"DICT_6X6_50", DICT_6X6_50},
      {"DICT_6X6_100", DICT_6X6_100},
      {"DICT_6X6_250", DICT_6X6_250},
      {"DICT_6X6_1000", DICT_6X6_1000},
      {"DICT_7X7_50", DICT_7X7_50},
      {"DICT_7X7_100", DICT_7X7_100},
      {"DICT_7X7_250", DICT_7X7_250},
      {"DICT_7X7_1000", DICT_7X7_1000},
      {"DICT_ARUCO_ORIGINAL", DICT_ARUCO_ORIGINAL}};
  return kNames;
}

cv::Ptr<cv::aruco::CharucoBoard> MakeCharucoBoard(const IntrinsicsOptions& options) {
  return cv::aruco::CharucoBoard::create(
      options.board_cols, options.board_rows, static_cast<float>(options.square_m),
      static_cast<float>(options.marker_m),
      cv::aruco::getPredefinedDictionary(Dictionaries().at(options.dictionary)));
}

// ArUco markers, then the chessboard corners between them (by id, so partial views count).
void DetectCharuco(const cv::Mat& grey, const IntrinsicsOptions& options, Detection* detection) {
  const cv::Ptr<cv::aruco::CharucoBoard> board = MakeCharucoBoard(options);
  std::vector<std::vector<cv::Point2f>> marker_corners;
  std::vector<int> marker_ids;
  cv::aruco::detectMarkers(grey, board->dictionary, marker_corners, marker_ids);
  if (marker_ids.empty()) {
    detection->reason = "no ArUco marker of " + options.dictionary + " found";
    return;
  }
  std::vector<cv::Point2f> corners;
  std::vector<int> ids;
  cv::aruco::interpolateCornersCharuco(marker_corners, marker_ids, grey, board, corners, ids);
  if (static_cast<int>(ids.size()) < kMinCharucoCorners) {
    detection->reason = "only " + std::to_string(ids.size()) + " ChArUco corners found (needs " +
                        std::to_string(kMinCharucoCorners) + ")";
    return;
  }
  for (int id : ids) detection->object_points.push_back(board->chessboardCorners[id]);
  detection->corners = std::move(corners);
}

std::vector<cv::Point3f> BoardPoints(const IntrinsicsOptions& options) {
  std::vector<cv::Point3f> points;
  for (int i = 0; i < options.board_rows; ++i) {
    for (int j = 0; j < options.board_cols; ++j) {
      points.emplace_back(static_cast<float>(j * options.square_m),
                          static_cast<float>(i * options.square_m), 0.0f);
    }
  }
  return points;
}

Detection DetectBoard(const std::filesystem::path& path, const IntrinsicsOptions& options) {
  const Image image = ReadImage(path);
  Detection detection;
  detection.width = image.width;
  detection.height = image.height;
  const cv::Mat grey = GreyImage(image);
  if (options.board_type == BoardType::kCharuco) {
    DetectCharuco(grey, options, &detection);
    return detection;
  }
  detection.object_points = BoardPoints(options);
  const cv::Size board(options.board_cols, options.board_rows);
  std::vector<cv::Point2f> corners;
  const int flags =
      cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_FAST_CHECK | cv::CALIB_CB_NORMALIZE_IMAGE;
  if (!cv::findChessboardCorners(grey, board, corners, flags)) return detection;
  const int w = options.subpix_window;
  cv::cornerSubPix(grey, corners, cv::Size(w, w), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 30, 1e-4));
  detection.corners = std::move(corners);
  return detection;
}

int CalibrationFlags(const IntrinsicsOptions& options) {
  int flags = 0;
  if (options.fix_aspect_ratio) flags |= cv::CALIB_FIX_ASPECT_RATIO;
  const bool pinhole = options.model == ColmapCameraModel::kPinhole;
  if (options.zero_tangent_dist || pinhole) flags |= cv::CALIB_ZERO_TANGENT_DIST;
  if (options.fix_principal_point) flags |= cv::CALIB_FIX_PRINCIPAL_POINT;
  if (pinhole) {
    flags |= cv::CALIB_FIX_K1 | cv::CALIB_FIX_K2 | cv::CALIB_FIX_K3;
  } else if (options.model == ColmapCameraModel::kOpenCv) {
    flags |= cv::CALIB_FIX_K3;
  }
  return flags;
}

// OpenCV's K and distortion -> COLMAP params (pixel centre convention shifted by 0.5).
std::vector<double> ColmapParams(ColmapCameraModel model, const cv::Mat& k, const cv::Mat& d) {
  std::vector<double> params = {k.at<double>(0, 0), k.at<double>(1, 1), k.at<double>(0, 2) + 0.5,
                                k.at<double>(1, 2) + 0.5};
  if (model == ColmapCameraModel::kPinhole) return params;
  for (int i = 0; i < 4; ++i) params.push_back(d.at<double>(i));
  if (model == ColmapCameraModel::kFullOpenCv) {
    params.push_back(d.at<double>(4));
    params.insert(params.end(), {0.0, 0.0, 0.0});
  }
  return params;
}

std::vector<std::string> FlagNames(const IntrinsicsOptions& options) {
  std::vector<std::string> names;
  if (options.fix_aspect_ratio) names.push_back("fix_aspect_ratio");
  if (options.zero_tangent_dist) names.push_back("zero_tangent_dist");
  if (options.fix_principal_point) names.push_back("fix_principal_point");
  return names;
}

}  // namespace

constexpr EnumNames<BoardType, 2> kBoardTypeNames{
    {{BoardType::kChessboard, "chessboard"}, {BoardType::kCharuco, "charuco"}}};

std::string_view BoardTypeName(BoardType type) { return kBoardTypeNames.Name(type); }
std::optional<BoardType> BoardTypeFromName(std::string_view name) {
  return kBoardTypeNames.FromName(name);
}

void IntrinsicsOptions::Validate() const {
  ProblemList problems;
  if (board_cols < 2) problems.Add("", "--board", std::to_string(board_cols), "cols must be >= 2");
  if (board_rows < 2) problems.Add("", "--board", std::to_string(board_rows), "rows must be >= 2");
  if (!(square_m > 0) || !std::isfinite(square_m)) {
    problems.Add("", "--square", std::to_string(square_m), "must be > 0 (metres)");
  }
  if (model != ColmapCameraModel::kPinhole && model != ColmapCameraModel::kOpenCv &&
      model != ColmapCameraModel::kFullOpenCv) {
    problems.Add("", "--model", std::string(ColmapCameraModelName(model)),
                 "must be PINHOLE, OPENCV or FULL_OPENCV");
  }
  if (!BoardTypeFromName(BoardTypeName(board_type))) {
    problems.Add("", "--board-type", std::to_string(int(board_type)),
                 "must be chessboard or charuco");
  }
  if (board_type == BoardType::kCharuco) {
    if (Dictionaries().count(dictionary) == 0) {
      problems.Add("", "--dictionary", dictionary,
                   "is not an OpenCV predefined ArUco dictionary (e.g. DICT_4X4_50)");
    }
    if (!(marker_m > 0) || !(marker_m < square_m)) {
      problems.Add("", "--marker", std::to_string(marker_m),
                   "must be > 0 and smaller than --square (metres)");
    }
  }
  if (subpix_window < 1) {
    problems.Add("", "--subpix-window", std::to_string(subpix_window), "must be >= 1");
  }
  problems.ThrowIfAny();
}

IntrinsicsSummary CalibrateIntrinsics(const std::vector<std::filesystem::path>& images,
                                      const IntrinsicsOptions& options) {
  options.Validate();
  std::vector<Detection> detections(images.size());
  ParallelFor(0, static_cast<int64_t>(images.size()),
              [&](int64_t i) { detections[i] = DetectBoard(images[i], options); });
  ProblemList problems;
  for (size_t i = 1; i < images.size(); ++i) {
    if (detections[i].width != detections[0].width ||
        detections[i].height != detections[0].height) {
      problems.Add(images[i].string(), "",
                   std::to_string(detections[i].width) + "x" + std::to_string(detections[i].height),
                   "every view must have the size of the first (" +
                       std::to_string(detections[0].width) + "x" +
                       std::to_string(detections[0].height) + ")");
    }
  }
  problems.ThrowIfAny();

  IntrinsicsSummary summary;
  CameraFile& camera = summary.camera;
  std::vector<std::vector<cv::Point2f>> image_points;
  std::vector<std::vector<cv::Point3f>> object_points;
  for (size_t i = 0; i < images.size(); ++i) {
    const std::string name = images[i].filename().string();
    if (!detections[i].corners) {
      camera.rejected_views.push_back({name, detections[i].reason});
      spdlog::warn("{}: {}x{} {}: {}; view rejected", images[i].string(), options.board_cols,
                   options.board_rows, BoardTypeName(options.board_type), detections[i].reason);
      continue;
    }
    image_points.push_back(*detections[i].corners);
    object_points.push_back(detections[i].object_points);
    camera.views.push_back(name);
    summary.used_indices.push_back(static_cast<int>(i));
  }
  if (static_cast<int>(image_points.size()) < kMinCalibrationViews) {
    throw Error("the board was found in " + std::to_string(image_points.size()) + " of " +
                std::to_string(images.size()) + " views; calibration needs at least " +
                std::to_string(kMinCalibrationViews));
  }
  const cv::Size size(detections[0].width, detections[0].height);
  cv::Mat k = cv::Mat::eye(3, 3, CV_64F);  // with CALIB_FIX_ASPECT_RATIO: fx / fy = 1
  cv::Mat d = cv::Mat::zeros(5, 1, CV_64F);
  std::vector<cv::Mat> rvecs, tvecs;
  cv::Mat std_intrinsics, std_extrinsics, per_view;
  camera.rms_px =
      cv::calibrateCamera(object_points, image_points, size, k, d, rvecs, tvecs, std_intrinsics,
                          std_extrinsics, per_view, CalibrationFlags(options));
  camera.model = options.model;
  camera.width = size.width;
  camera.height = size.height;
  camera.params = ColmapParams(options.model, k, d);
  for (int i = 0; i < per_view.rows; ++i) camera.per_view_rms_px.push_back(per_view.at<double>(i));
  camera.board_cols = options.board_cols;
  camera.board_rows = options.board_rows;
  camera.square_m = options.square_m;
  camera.flags = FlagNames(options);
  spdlog::info("calibrated {} views ({} rejected): fx {:.3f} fy {:.3f} RMS {:.4f} px",
               camera.views.size(), camera.rejected_views.size(), camera.params[0],
               camera.params[1], camera.rms_px);
  return summary;
}

}  // namespace igi::calib
