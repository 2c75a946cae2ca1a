// Registration with COLMAP 3.8 on real photos (Sceaux castle, openMVG sample, © 2012 Pierre
// Moulon; ../shared/data/real/sceaux_castle), downscaled 4x to keep the test fast, and the
// command lines igi gives COLMAP (a fake COLMAP that logs them).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "recon/colmap_runner.h"
#include "recon/registration.h"
#include "tests/e2e/run.h"
#include "tests/temp_dir.h"
#include "tools/common/atomic_file.h"
#include "tools/common/error.h"
#include "tools/common/json.h"

namespace igi::recon {
namespace {

namespace fs = std::filesystem;

const fs::path kSceaux = fs::path(IGI_SHARED_DATA_DIR) / "real" / "sceaux_castle";
constexpr int kDownscale = 4;  // 2832x2128 -> 708x532

// The Sceaux photos downscaled kDownscale times (area averaging) into `dir`.
void WriteDownscaledSceaux(const fs::path& dir) {
  fs::create_directories(dir);
  for (const auto& entry : fs::directory_iterator(kSceaux)) {
    if (entry.path().extension() != ".JPG") continue;
    const cv::Mat full = cv::imread(entry.path().string());
    cv::Mat small;
    cv::resize(full, small, cv::Size(full.cols / kDownscale, full.rows / kDownscale), 0, 0,
               cv::INTER_AREA);
    cv::imwrite((dir / entry.path().filename()).string(), small, {cv::IMWRITE_JPEG_QUALITY, 95});
  }
}

TEST(ColmapRunnerTest, ParsesVersionBanner) {
  EXPECT_EQ(ParseColmapVersion("COLMAP 3.8 -- Structure-from-Motion and Multi-View Stereo\n"),
            "3.8");
  EXPECT_EQ(ParseColmapVersion("COLMAP 3.9.1 -- Structure-from-Motion"), "3.9.1");
  EXPECT_FALSE(ParseColmapVersion("bash: colmap: command not found").has_value());
}

TEST(ColmapRunnerTest, MissingOrWrongColmapIsReported) {
  const fs::path dir = test::UniqueTempDir("igi_colmap_runner");
  EXPECT_THROW(ColmapVersion((dir / "no-colmap").string()), Error);
  const fs::path fake = dir / "fake-colmap";
  std::ofstream(fake) << "#!/bin/sh\necho 'COLMAP 3.6 -- Structure-from-Motion'\n";
  fs::permissions(fake, fs::perms::owner_all);
  EXPECT_EQ(ColmapVersion(fake.string()), "3.6");
  WriteDownscaledSceaux(dir / "images");
  ColmapRunOptions options;
  options.executable = fake.string();
  try {
    RunColmap(dir / "images", dir / "work", options);
    FAIL() << "COLMAP 3.6 accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("3.6"), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}

// The self-calibrated camera model, guided matching and the feature cap reach COLMAP's command line
// (a fake COLMAP that logs its arguments and reconstructs nothing); a model igi cannot read is
// refused before anything runs.
TEST(ColmapRunnerTest, CameraModelGuidedMatchingAndFeatureCapArePassed) {
  const fs::path dir = test::UniqueTempDir("igi_colmap_runner_args");
  const fs::path fake = dir / "fake-colmap";
  std::ofstream(fake) << "#!/bin/sh\necho 'COLMAP 3.8 -- Structure-from-Motion'\n";
  fs::permissions(fake, fs::perms::owner_all);
  fs::create_directories(dir / "images");
  ColmapRunOptions options;
  options.executable = fake.string();
  EXPECT_EQ(options.camera_model, calib::ColmapCameraModel::kSimpleRadial);
  EXPECT_FALSE(options.guided_matching);
  options.guided_matching = true;
  options.camera_model = calib::ColmapCameraModel::kRadial;
  EXPECT_THROW(RunColmap(dir / "images", dir / "work", options), Error);  // nothing mapped
  const std::string log = ReadFileToString(dir / "work" / "colmap.log");
  EXPECT_NE(log.find("--ImageReader.camera_model RADIAL"), std::string::npos) << log;
  EXPECT_NE(log.find("--SiftMatching.guided_matching 1"), std::string::npos) << log;
  options.guided_matching = false;
  options.intrinsics =
      KnownIntrinsics{calib::ColmapCameraModel::kPinhole, 640, 480, {500, 500, 320, 240}};
  EXPECT_THROW(RunColmap(dir / "images", dir / "work", options), Error);
  const std::string known = ReadFileToString(dir / "work" / "colmap.log");
  EXPECT_NE(known.find("--ImageReader.camera_model PINHOLE"), std::string::npos) << known;
  EXPECT_EQ(known.find("--ImageReader.camera_model RADIAL"), std::string::npos) << known;
  EXPECT_NE(known.find("--SiftMatching.guided_matching 0"), std::string::npos) << known;
  options.guided_matching = true;  // with known intrinsics too
  EXPECT_THROW(RunColmap(dir / "images", dir / "work", options), Error);
  const std::string asked = ReadFileToString(dir / "work" / "colmap.log");
  EXPECT_NE(asked.find("--SiftMatching.guided_matching 1"), std::string::npos) << asked;
  EXPECT_NE(asked.find("--SiftExtraction.max_num_features 8192"), std::string::npos) << asked;
  options.max_features = 1024;  // the demo's
  EXPECT_THROW(RunColmap(dir / "images", dir / "work", options), Error);
  const std::string fewer = ReadFileToString(dir / "work" / "colmap.log");
  EXPECT_NE(fewer.find("--SiftExtraction.max_num_features 1024"), std::string::npos) << fewer;
  options.max_features = 50;
  EXPECT_THROW(options.Validate(), InputError);
  options.max_features = 1024;
  options.camera_model = calib::ColmapCameraModel::kFullOpenCv;
  try {
    options.Validate();
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.problems(),
              std::vector<std::string>{"--camera-model: FULL_OPENCV: must be one of "
                                       "SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL, RADIAL, OPENCV"});
  }
  fs::remove_all(dir);
}

// Every Sceaux photo registers with igi's defaults (SIMPLE_RADIAL, no guided matching) in one
// shared camera, each with enough well-fitting observations. (The self-calibrated intrinsics are
// measured against real ground truth on Herz-Jesu-P8: herzjesu_register_test.cpp. Sceaux's K.txt
// does not say its distortion model, on which its focal length depends.)
TEST(ColmapRunnerTest, SceauxRegisters) {
  const fs::path dir = test::UniqueTempDir("igi_colmap_sceaux");
  WriteDownscaledSceaux(dir / "images");
  const ColmapRunSummary run = RunColmap(dir / "images", dir / "work", ColmapRunOptions{});
  EXPECT_EQ(run.version, "3.8");
  EXPECT_EQ(run.images.size(), 11u);
  EXPECT_TRUE(run.unregistered.empty());
  EXPECT_EQ(run.model.images.size(), 11u);
  ASSERT_EQ(run.model.cameras.size(), 1u);  // one camera shared by every photo
  EXPECT_EQ(run.model.cameras.begin()->second.model, "SIMPLE_RADIAL");
  for (const ImageReprojection& r : ReprojectionErrors(run.model)) {
    EXPECT_GT(r.observations, 50) << r.name;
    EXPECT_LT(r.rms_px, 1.5) << r.name;  // COLMAP's default filter keeps errors under 4 px
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace igi::recon
