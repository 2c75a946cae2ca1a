// ChArUco calibration (igi-calib intrinsics --board-type charuco) on synthetic views with known
// intrinsics: OpenCV draws a 5 x 7 ChArUco board (DICT_4X4_50, 4 cm squares, 3 cm markers), which
// is warped into 640 x 480 views of a pinhole camera (fx = fy = 800, cx = 320, cy = 240 in
// OpenCV's convention) from known tilted poses. The recovered fx must be within 0.5 % (the
// bar; the exact rendering leaves far less), a view without the board is rejected (exit 3).
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <filesystem>
#include <opencv2/aruco/charuco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "calib/camera_file.h"
#include "calib/intrinsics.h"
#include "tests/e2e/run.h"
#include "tests/temp_dir.h"
#include "tools/common/error.h"

namespace igi::calib {
namespace {

namespace fs = std::filesystem;

constexpr double kFx = 800, kCx = 320, kCy = 240;
constexpr int kWidth = 640, kHeight = 480;
constexpr double kSquareM = 0.04, kMarkerM = 0.03;
constexpr int kSquaresX = 5, kSquaresY = 7;

// The drawn board and the affine map from its pixels to the board frame (metres), found by
// detecting the ChArUco corners in the frontal drawing (so the test does not depend on OpenCV's
// drawing conventions).
struct DrawnBoard {
  cv::Mat image;
  cv::Mat board_from_pixel;  // 3 x 3
};

DrawnBoard DrawBoard() {
  const auto board =
      cv::aruco::CharucoBoard::create(kSquaresX, kSquaresY, kSquareM, kMarkerM,
                                      cv::aruco::getPredefinedDictionary(cv::aruco::DICT_4X4_50));
  DrawnBoard drawn;
  board->draw(cv::Size(kSquaresX * 200 + 200, kSquaresY * 200 + 200), drawn.image, 100, 1);
  std::vector<std::vector<cv::Point2f>> marker_corners;
  std::vector<int> marker_ids;
  cv::aruco::detectMarkers(drawn.image, board->dictionary, marker_corners, marker_ids);
  std::vector<cv::Point2f> corners;
  std::vector<int> ids;
  cv::aruco::interpolateCornersCharuco(marker_corners, marker_ids, drawn.image, board, corners,
                                       ids);
  EXPECT_EQ(ids.size(), static_cast<size_t>((kSquaresX - 1) * (kSquaresY - 1)));
  std::vector<cv::Point2f> object;
  for (int id : ids) {
    object.emplace_back(board->chessboardCorners[id].x, board->chessboardCorners[id].y);
  }
  const cv::Mat affine = cv::estimateAffine2D(corners, object, cv::noArray(), cv::LMEDS);
  drawn.board_from_pixel = cv::Mat::eye(3, 3, CV_64F);
  affine.copyTo(drawn.board_from_pixel.rowRange(0, 2));
  return drawn;
}

constexpr int kSupersample = 4;  // views are rendered 4x larger and area-averaged down

// A view of the board from a camera tilted by (ax, ay) radians at `distance_m`.
cv::Mat RenderView(const DrawnBoard& drawn, double ax, double ay, double distance_m) {
  const Eigen::Matrix3d r = (Eigen::AngleAxisd(ax, Eigen::Vector3d::UnitX()) *
                             Eigen::AngleAxisd(ay, Eigen::Vector3d::UnitY()))
                                .toRotationMatrix();
  // Board centre on the optical axis at distance_m.
  const Eigen::Vector3d centre(kSquaresX * kSquareM / 2, kSquaresY * kSquareM / 2, 0);
  const Eigen::Vector3d t = Eigen::Vector3d(0, 0, distance_m) - r * centre;
  // Pixel centre u of the small image is at kSupersample * u + (kSupersample - 1) / 2 in the big.
  const double s = kSupersample, shift = (kSupersample - 1) / 2.0;
  cv::Mat k =
      (cv::Mat_<double>(3, 3) << s * kFx, 0, s * kCx + shift, 0, s * kFx, s * kCy + shift, 0, 0, 1);
  cv::Mat rt = (cv::Mat_<double>(3, 3) << r(0, 0), r(0, 1), t.x(), r(1, 0), r(1, 1), t.y(), r(2, 0),
                r(2, 1), t.z());
  const cv::Mat h = k * rt * drawn.board_from_pixel;
  cv::Mat big, view;
  cv::warpPerspective(drawn.image, big, h, cv::Size(kWidth * kSupersample, kHeight * kSupersample),
                      cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(255));
  cv::resize(big, view, cv::Size(kWidth, kHeight), 0, 0, cv::INTER_AREA);
  return view;
}

std::vector<fs::path> WriteViews(const fs::path& dir) {
  fs::create_directories(dir);
  const DrawnBoard drawn = DrawBoard();
  const double tilts[][2] = {{0.0, 0.0},  {0.5, 0.0},  {-0.5, 0.1},  {0.1, 0.5},
                             {0.0, -0.5}, {0.4, 0.4},  {-0.4, -0.3}, {0.3, -0.4},
                             {-0.3, 0.4}, {0.6, -0.2}, {-0.2, -0.6}, {0.2, 0.2}};
  std::vector<fs::path> paths;
  int i = 0;
  for (const auto& tilt : tilts) {
    const fs::path p = dir / ("view" + std::to_string(i++) + ".png");
    cv::imwrite(p.string(), RenderView(drawn, tilt[0], tilt[1], 0.5));
    paths.push_back(p);
  }
  const fs::path blank = dir / "blank.png";
  cv::imwrite(blank.string(), cv::Mat(kHeight, kWidth, CV_8UC1, cv::Scalar(200)));
  paths.push_back(blank);
  return paths;
}

IntrinsicsOptions CharucoOptions() {
  IntrinsicsOptions o;
  o.board_type = BoardType::kCharuco;
  o.board_cols = kSquaresX;
  o.board_rows = kSquaresY;
  o.square_m = kSquareM;
  o.marker_m = kMarkerM;
  o.dictionary = "DICT_4X4_50";
  o.model = ColmapCameraModel::kOpenCv;
  return o;
}

TEST(CharucoIntrinsicsTest, RecoversKnownFocalLength) {
  const fs::path dir = test::UniqueTempDir("igi_charuco");
  const std::vector<fs::path> views = WriteViews(dir);
  const IntrinsicsSummary s = CalibrateIntrinsics(views, CharucoOptions());
  const CameraFile& c = s.camera;
  EXPECT_EQ(c.views.size(), views.size() - 1);
  ASSERT_EQ(c.rejected_views.size(), 1u);
  EXPECT_EQ(c.rejected_views[0].file, "blank.png");
  const double fx_error = std::abs(c.params[0] / kFx - 1);
  const double fy_error = std::abs(c.params[1] / kFx - 1);
  std::printf("ChArUco: fx %.3f (error %.4f %%), fy %.3f, cx %.3f, cy %.3f, RMS %.4f px\n",
              c.params[0], 100 * fx_error, c.params[1], c.params[2], c.params[3], c.rms_px);
  EXPECT_LT(fx_error, 0.005);
  EXPECT_LT(fy_error, 0.005);
  // COLMAP convention: OpenCV's principal point + 0.5; within 2 px (less constrained than fx by
  // 12 views with 4 free distortion coefficients; ~1 px seen).
  EXPECT_NEAR(c.params[2], kCx + 0.5, 2.0);
  EXPECT_NEAR(c.params[3], kCy + 0.5, 2.0);
  EXPECT_LT(c.rms_px, 0.5);
  fs::remove_all(dir);
}

TEST(CharucoIntrinsicsTest, BadOptionsAreInputErrors) {
  IntrinsicsOptions o = CharucoOptions();
  o.dictionary = "DICT_9X9_1";
  EXPECT_THROW(o.Validate(), InputError);
  o = CharucoOptions();
  o.marker_m = 0.05;  // larger than the square
  EXPECT_THROW(o.Validate(), InputError);
}

TEST(CharucoIntrinsicsTest, CommandLineWritesCameraJsonAndRejectsBlankView) {
  const fs::path dir = test::UniqueTempDir("igi_charuco_e2e");
  std::string args = "intrinsics ";
  for (const fs::path& p : WriteViews(dir / "views")) args += test::Quote(p.string()) + " ";
  args +=
      "--board 5x7 --board-type charuco --dictionary DICT_4X4_50 --square 0.04 --marker 0.03 "
      "--out " +
      test::Quote((dir / "camera.json").string());
  const auto r = test::RunTool("igi-calib", args);
  EXPECT_EQ(r.exit_code, 3) << r.err;  // blank.png rejected
  EXPECT_NE(r.err.find("blank.png"), std::string::npos) << r.err;
  const CameraFile c = ReadCameraFile(dir / "camera.json");
  EXPECT_NEAR(c.params[0], kFx, 0.005 * kFx);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace igi::calib
