// igi-calib intrinsics end to end: exit codes, camera.json contents, rejected views.
#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "calib/camera_file.h"
#include "tests/e2e/run.h"
#include "tests/temp_dir.h"

namespace igi::calib {
namespace {

using test::Quote;
using test::RunTool;

const std::filesystem::path kBoardDir =
    std::filesystem::path(IGI_SHARED_DATA_DIR) / "real" / "chessboard_left";

std::string BoardArgs(int count) {
  std::string args;
  for (int i = 1; i <= count; ++i) {
    args += Quote((kBoardDir / ("left0" + std::to_string(i) + ".jpg")).string()) + " ";
  }
  return args;
}

TEST(IntrinsicsE2eTest, WritesCameraJson) {
  const auto dir = test::UniqueTempDir("igi_intrinsics_e2e");
  const auto out = dir / "camera.json";
  const auto r = RunTool("igi-calib", "intrinsics " + BoardArgs(9) +
                                          "--board 9x6 --square 0.025 --fix-aspect-ratio --out " +
                                          Quote(out.string()));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const CameraFile camera = ReadCameraFile(out);
  EXPECT_EQ(camera.model, ColmapCameraModel::kOpenCv);
  EXPECT_EQ(camera.width, 640);
  EXPECT_EQ(camera.views.size(), 9u);
  EXPECT_EQ(camera.per_view_rms_px.size(), 9u);
  EXPECT_GT(camera.rms_px, 0.0);
  EXPECT_LT(camera.rms_px, 1.0);  // real views of a good board: well under a pixel
  std::filesystem::remove_all(dir);
}

TEST(IntrinsicsE2eTest, ViewWithoutBoardIsRejectedAndListed) {
  const auto dir = test::UniqueTempDir("igi_intrinsics_e2e");
  // A view of the right size with no board in it: a plain grey image.
  const auto blank = dir / "blank.png";
  {
    cv::Mat grey(480, 640, CV_8UC1, cv::Scalar(128));
    cv::imwrite(blank.string(), grey);
  }
  const auto out = dir / "camera.json";
  const auto r =
      RunTool("igi-calib", "intrinsics " + BoardArgs(5) + Quote(blank.string()) +
                               " --board 9x6 --square 0.025 --out " + Quote(out.string()));
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_NE(r.err.find("blank.png"), std::string::npos) << r.err;
  const CameraFile camera = ReadCameraFile(out);
  EXPECT_EQ(camera.views.size(), 5u);
  ASSERT_EQ(camera.rejected_views.size(), 1u);
  EXPECT_EQ(camera.rejected_views[0].file, "blank.png");
  EXPECT_EQ(camera.rejected_views[0].reason, "board not found");
  std::filesystem::remove_all(dir);
}

TEST(IntrinsicsE2eTest, BadUsageAndTooFewViews) {
  const auto dir = test::UniqueTempDir("igi_intrinsics_e2e");
  const auto out = dir / "camera.json";
  auto r = RunTool("igi-calib", "intrinsics " + BoardArgs(3) +
                                    "--board 9by6 --square 0.025 --out " + Quote(out.string()));
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("--board"), std::string::npos) << r.err;
  r = RunTool("igi-calib", "intrinsics " + Quote((dir / "missing.jpg").string()) +
                               " --board 9x6 --square 0.025 --out " + Quote(out.string()));
  EXPECT_EQ(r.exit_code, 2) << r.err;
  r = RunTool("igi-calib", "intrinsics " + BoardArgs(2) + "--board 9x6 --square 0.025 --out " +
                               Quote(out.string()));
  EXPECT_EQ(r.exit_code, 1) << r.err;  // two views: too few to calibrate
  EXPECT_FALSE(std::filesystem::exists(out));
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace igi::calib
