// Chessboard calibration against OpenCV's own reference calibration of the same real views
// (../shared/data/real/chessboard_left/left_intrinsics.yml, written by OpenCV's calibration
// sample with flags = CALIB_FIX_ASPECT_RATIO and its default 5-coefficient distortion).
#include "calib/intrinsics.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "calib/camera_file.h"
#include "tests/temp_dir.h"
#include "tools/common/error.h"
#include "tools/common/json.h"

namespace igi::calib {
namespace {

const std::filesystem::path kBoardDir =
    std::filesystem::path(IGI_SHARED_DATA_DIR) / "real" / "chessboard_left";

std::vector<std::filesystem::path> BoardImages() {
  std::vector<std::filesystem::path> images;
  for (const auto& entry : std::filesystem::directory_iterator(kBoardDir)) {
    if (entry.path().extension() == ".jpg") images.push_back(entry.path());
  }
  std::sort(images.begin(), images.end());
  return images;
}

struct Reference {
  double fx, fy, cx, cy, rms;
  std::vector<double> per_view;
};

Reference ReadReference() {
  cv::FileStorage fs((kBoardDir / "left_intrinsics.yml").string(), cv::FileStorage::READ);
  cv::Mat k, per_view;
  fs["camera_matrix"] >> k;
  fs["per_view_reprojection_errors"] >> per_view;
  Reference ref{k.at<double>(0, 0),
                k.at<double>(1, 1),
                k.at<double>(0, 2),
                k.at<double>(1, 2),
                static_cast<double>(fs["avg_reprojection_error"]),
                {}};
  for (int i = 0; i < per_view.rows; ++i) ref.per_view.push_back(per_view.at<float>(i));
  return ref;
}

IntrinsicsOptions ReferenceOptions() {
  IntrinsicsOptions options;
  options.board_cols = 9;
  options.board_rows = 6;
  options.square_m = 0.025;
  options.model =
      ColmapCameraModel::kFullOpenCv;  // OpenCV's default k1 k2 p1 p2 k3, as the reference
  options.fix_aspect_ratio = true;
  return options;
}

TEST(IntrinsicsTest, MatchesOpenCvReferenceOnRealChessboard) {
  const Reference ref = ReadReference();
  const IntrinsicsSummary summary = CalibrateIntrinsics(BoardImages(), ReferenceOptions());
  const CameraFile& camera = summary.camera;
  ASSERT_EQ(camera.views.size(), 13u);  // the board is in all 13 views
  EXPECT_TRUE(camera.rejected_views.empty());
  ASSERT_EQ(camera.params.size(), 12u);
  // Target: fx within 0.5 % and RMS within 0.05 px of OpenCV's reference.
  EXPECT_NEAR(camera.params[0], ref.fx, 0.005 * ref.fx);
  EXPECT_DOUBLE_EQ(camera.params[0], camera.params[1]);  // fixed aspect ratio 1
  EXPECT_NEAR(camera.rms_px, ref.rms, 0.05);
  // Principal point: COLMAP's convention is OpenCV's + 0.5 px; 2 px tolerance covers corner
  // detection differing slightly between decoders.
  EXPECT_NEAR(camera.params[2], ref.cx + 0.5, 2.0);
  EXPECT_NEAR(camera.params[3], ref.cy + 0.5, 2.0);
  ASSERT_EQ(camera.per_view_rms_px.size(), ref.per_view.size());
  // Per view: 0.1 px. OpenCV 4.6 places left13's corners slightly differently from the OpenCV
  // that wrote the reference (0.46 vs 0.38 px; identical with OpenCV's own imread), the other
  // twelve agree within 0.02 px.
  for (size_t i = 0; i < ref.per_view.size(); ++i) {
    EXPECT_NEAR(camera.per_view_rms_px[i], ref.per_view[i], 0.1) << camera.views[i];
  }
  std::printf("fx %.4f (reference %.4f), RMS %.4f px (reference %.4f)\n", camera.params[0], ref.fx,
              camera.rms_px, ref.rms);
}

TEST(IntrinsicsTest, OpenCvModelWithoutK3IsCloseToReference) {
  IntrinsicsOptions options = ReferenceOptions();
  options.model = ColmapCameraModel::kOpenCv;
  const CameraFile camera = CalibrateIntrinsics(BoardImages(), options).camera;
  ASSERT_EQ(camera.params.size(), 8u);
  // Without k3 the fit has one distortion term fewer: fx within 1 %, RMS within 0.1 px.
  const Reference ref = ReadReference();
  EXPECT_NEAR(camera.params[0], ref.fx, 0.01 * ref.fx);
  EXPECT_NEAR(camera.rms_px, ref.rms, 0.1);
}

TEST(IntrinsicsTest, RejectsViewsWithoutBoard) {
  std::vector<std::filesystem::path> images = BoardImages();
  IntrinsicsOptions options = ReferenceOptions();
  options.board_cols = 12;  // no 12x6 board in any view: every view rejected, too few left
  EXPECT_THROW(CalibrateIntrinsics(images, options), Error);
}

TEST(IntrinsicsTest, OptionsAreValidated) {
  IntrinsicsOptions options = ReferenceOptions();
  options.square_m = 0;
  EXPECT_THROW(options.Validate(), InputError);
  options = ReferenceOptions();
  options.model = ColmapCameraModel::kSimpleRadial;  // a model intrinsics does not calibrate
  EXPECT_THROW(options.Validate(), InputError);
  options = ReferenceOptions();
  options.board_type = static_cast<BoardType>(7);  // no such board
  EXPECT_THROW(options.Validate(), InputError);
  for (BoardType t : {BoardType::kChessboard, BoardType::kCharuco}) {
    EXPECT_EQ(BoardTypeFromName(BoardTypeName(t)), t);
  }
  EXPECT_EQ(BoardTypeName(BoardType::kCharuco), "charuco");
  EXPECT_FALSE(BoardTypeFromName("Chessboard"));
}

TEST(CameraFileTest, RoundTripsAndRejectsBadFiles) {
  const auto dir = test::UniqueTempDir("igi_camera_file");
  CameraFile camera;
  camera.model = ColmapCameraModel::kOpenCv;
  camera.width = 640;
  camera.height = 480;
  camera.params = {500, 500, 320, 240, -0.1, 0.01, 0.001, -0.001};
  camera.rms_px = 0.3;
  camera.views = {"a.jpg", "b.jpg"};
  camera.per_view_rms_px = {0.2, 0.4};
  camera.rejected_views = {{"c.jpg", "board not found"}};
  WriteCameraFile(dir / "camera.json", camera);
  const CameraFile back = ReadCameraFile(dir / "camera.json");
  EXPECT_EQ(back.model, camera.model);
  EXPECT_EQ(back.params, camera.params);
  EXPECT_EQ(back.views, camera.views);
  EXPECT_EQ(back.per_view_rms_px, camera.per_view_rms_px);
  ASSERT_EQ(back.rejected_views.size(), 1u);
  EXPECT_EQ(back.rejected_views[0].file, "c.jpg");

  camera.params.pop_back();
  EXPECT_THROW(WriteCameraFile(dir / "bad.json", camera), InputError);
  EXPECT_FALSE(std::filesystem::exists(dir / "bad.json"));
  std::ofstream(dir / "unknown.json")
      << R"({"format": "igi-camera", "model": "PINHOLE", "width": 4, "height": 4,
             "params": [1, 1, 2, 2], "colour": 1})";
  try {
    ReadCameraFile(dir / "unknown.json");
    FAIL() << "unknown key accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("colour"), std::string::npos) << e.what();
  }
  std::filesystem::remove_all(dir);
}

TEST(CameraFileTest, ModelNamesAreCOLMAPsAndUnknownModelsAreRejected) {
  for (ColmapCameraModel m : {ColmapCameraModel::kSimplePinhole, ColmapCameraModel::kPinhole,
                              ColmapCameraModel::kSimpleRadial, ColmapCameraModel::kRadial,
                              ColmapCameraModel::kOpenCv, ColmapCameraModel::kFullOpenCv}) {
    EXPECT_EQ(ColmapCameraModelFromName(ColmapCameraModelName(m)), m);
  }
  EXPECT_EQ(ColmapCameraModelName(ColmapCameraModel::kFullOpenCv), "FULL_OPENCV");
  EXPECT_FALSE(ColmapCameraModelFromName("opencv"));
  const auto dir = test::UniqueTempDir("igi_camera_file_model");
  CameraFile camera;
  camera.model = ColmapCameraModel::kSimpleRadial;
  camera.width = 64;
  camera.height = 48;
  camera.params = {50, 32, 24, 0.01};
  WriteCameraFile(dir / "camera.json", camera);
  EXPECT_EQ(ReadJsonFile(dir / "camera.json")["model"], "SIMPLE_RADIAL");
  EXPECT_EQ(ReadCameraFile(dir / "camera.json").model, ColmapCameraModel::kSimpleRadial);
  std::ofstream(dir / "fisheye.json")
      << R"({"format": "igi-camera", "model": "OPENCV_FISHEYE", "width": 4, "height": 4,
             "params": [1, 1, 2, 2, 0, 0, 0, 0]})";
  try {
    ReadCameraFile(dir / "fisheye.json");
    FAIL() << "unknown model accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("model: OPENCV_FISHEYE: must be SIMPLE_PINHOLE"),
              std::string::npos)
        << e.what();
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace igi::calib
