// igi-register end to end: failures are reported with the contract's exit codes and nothing is
// written on bad input. (The COLMAP runs on real photos are in tests/recon/register_test.cpp;
// photos that do not register (exit 3, listed in report.json) and known intrinsics from
// --camera are checked on synthetic photos in tests/recon/registration_synth_test.cpp.)
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "tests/e2e/run.h"
#include "tests/temp_dir.h"

namespace igi {
namespace {

namespace fs = std::filesystem;
using test::Quote;
using test::RunTool;

const fs::path kScene = fs::path(IGI_SOURCE_DIR) / "tests/data/scenes/mini/scene.json";

// Two featureless images: COLMAP can match nothing between them.
fs::path FlatImages(const fs::path& dir) {
  fs::create_directories(dir / "images");
  for (int i = 0; i < 2; ++i) {
    cv::Mat image(240, 320, CV_8UC3, cv::Scalar(90 + 40 * i, 100, 110));
    cv::imwrite((dir / "images" / ("flat" + std::to_string(i) + ".png")).string(), image);
  }
  return dir / "images";
}

TEST(RegisterE2eTest, BadInputExits2AndWritesNothing) {
  const fs::path dir = test::UniqueTempDir("igi_register_e2e");
  const fs::path out = dir / "out";
  auto r = RunTool("igi-register",
                   "--images " + Quote((dir / "none").string()) + " --out " + Quote(out.string()));
  EXPECT_EQ(r.exit_code, 2) << r.err;
  const fs::path images = FlatImages(dir);
  std::ofstream(dir / "markers.json") << R"({"format": "igi-markers", "version": 1,
    "points": {"a": [0, 0, 0]}, "pixels": {"flat0.png": {"ghost": [3, 4]}}})";
  r = RunTool("igi-register", "--images " + Quote(images.string()) + " --scene " +
                                  Quote(kScene.string()) + " --markers " +
                                  Quote((dir / "markers.json").string()) + " --out " +
                                  Quote(out.string()));
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("ghost"), std::string::npos) << r.err;
  std::ofstream(dir / "camera.json") << R"({"format": "igi-camera", "version": 1,
    "model": "PINHOLE", "width": 640, "height": 480, "params": [500, 500, 320, 240]})";
  r = RunTool("igi-register", "--images " + Quote(images.string()) + " --camera " +
                                  Quote((dir / "camera.json").string()) + " --out " +
                                  Quote(out.string()));
  EXPECT_EQ(r.exit_code, 2) << r.err;  // 320x240 photos, 640x480 camera
  EXPECT_NE(r.err.find("320x240"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
  fs::remove_all(dir);
}

// Lines of stderr that are igi-register's error message (spdlog lines left out).
int ErrorLines(const std::string& err) {
  int n = 0;
  size_t pos = 0;
  while ((pos = err.find("igi-register: error:", pos)) != std::string::npos) ++n, ++pos;
  return n;
}

// A markers file naming a point the scene lacks: a pixel entry for an undeclared point, or a
// point far outside the scene's geometry. Exit 2 with one line naming it; nothing written.
TEST(RegisterE2eTest, MarkersNamingPointsTheSceneLacksExit2) {
  const fs::path dir = test::UniqueTempDir("igi_register_e2e");
  const fs::path out = dir / "out";
  const fs::path images = FlatImages(dir);
  auto run = [&](const std::string& markers) {
    std::ofstream(dir / "markers.json") << markers;
    return RunTool("igi-register", "--images " + Quote(images.string()) + " --scene " +
                                       Quote(kScene.string()) + " --markers " +
                                       Quote((dir / "markers.json").string()) + " --out " +
                                       Quote(out.string()));
  };
  auto r = run(R"({"format": "igi-markers", "version": 1,
    "points": {"a": [0, 0, 0]}, "pixels": {"flat0.png": {"ghost": [3, 4]}}})");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_EQ(ErrorLines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("pixels.flat0.png.ghost"), std::string::npos) << r.err;
  r = run(R"({"format": "igi-markers", "version": 1,
    "points": {"far": [1000, 0, 0]}, "pixels": {"flat0.png": {"far": [3, 4]}}})");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_EQ(ErrorLines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("points.far"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("is not in the scene"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
  fs::remove_all(dir);
}

// The joint refinement's and the model's flags: a --colmap-model that is not a folder, a
// non-positive --marker-sigma or --mesh-sigma, too few --min-pose-inliers, a --camera-model
// igi cannot read, an unknown --refine-principal-point. Exit 2 with one line, nothing written.
TEST(RegisterE2eTest, BadRefinementFlagsExit2) {
  const fs::path dir = test::UniqueTempDir("igi_register_e2e");
  const fs::path out = dir / "out";
  const fs::path images = FlatImages(dir);
  const std::string base = "--images " + Quote(images.string()) + " --out " + Quote(out.string());
  auto r = RunTool("igi-register", base + " --colmap-model " + Quote((dir / "none").string()));
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("--colmap-model"), std::string::npos) << r.err;
  for (const std::string flag :
       {"--marker-sigma 0", "--mesh-sigma -1", "--min-pose-inliers 3", "--camera-model FULL_OPENCV",
        "--refine-principal-point sometimes"}) {
    r = RunTool("igi-register", base + " " + flag);
    EXPECT_EQ(r.exit_code, 2) << flag << ": " << r.err;
    EXPECT_EQ(ErrorLines(r.err), 1) << flag << ": " << r.err;
  }
  EXPECT_FALSE(fs::exists(out));
  fs::remove_all(dir);
}

TEST(RegisterE2eTest, MissingOrUnknownColmapExits1) {
  const fs::path dir = test::UniqueTempDir("igi_register_e2e");
  const fs::path images = FlatImages(dir);
  auto r = RunTool("igi-register", "--images " + Quote(images.string()) + " --colmap " +
                                       Quote((dir / "no-colmap").string()) + " --out " +
                                       Quote((dir / "out").string()));
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("COLMAP not found"), std::string::npos) << r.err;
  const fs::path fake = dir / "fake-colmap";
  std::ofstream(fake) << "#!/bin/sh\necho 'COLMAP 3.6 -- Structure-from-Motion'\n";
  fs::permissions(fake, fs::perms::owner_all);
  r = RunTool("igi-register", "--images " + Quote(images.string()) + " --colmap " +
                                  Quote(fake.string()) + " --out " + Quote((dir / "out").string()));
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("3.6"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "out" / "report.json"));
  fs::remove_all(dir);
}

TEST(RegisterE2eTest, TooFewMatchesExits1) {
  const fs::path dir = test::UniqueTempDir("igi_register_e2e");
  const fs::path images = FlatImages(dir);
  const auto r = RunTool("igi-register", "--images " + Quote(images.string()) + " --out " +
                                             Quote((dir / "out").string()));
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("reconstructed nothing"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "out" / "report.json"));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace igi
