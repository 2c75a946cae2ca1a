// igi-run end to end, the fast cases: bad input exits 2 with one line per problem and writes
// nothing; --help documents the PHOTOS_DIR layout. (The demo with its truth, resuming and the
// report in Chromium: run_demo_e2e_test.cpp; the DiLiGenT ball: run_diligent_e2e_test.cpp.)
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "tests/e2e/run.h"
#include "tests/temp_dir.h"

namespace igi {
namespace {

namespace fs = std::filesystem;
using test::Quote;
using test::RunTool;

const fs::path kScene = fs::path(IGI_SOURCE_DIR) / "tests/data/scenes/mini/scene.json";

int ErrorLines(const std::string& err) {
  int n = 0;
  for (size_t pos = 0; (pos = err.find("igi-run: error:", pos)) != std::string::npos; ++pos) ++n;
  return n;
}

TEST(RunE2eTest, HelpDocumentsTheLayout) {
  const auto r = RunTool("igi-run", "--help");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE(r.out.find("NAME_LIGHTING"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("exposures.txt"), std::string::npos);
  EXPECT_NE(r.out.find("--skip-diagnose"), std::string::npos);
}

TEST(RunE2eTest, MissingPhotosDirExits2AndWritesNothing) {
  const fs::path dir = test::UniqueTempDir("igi_run_e2e");
  const fs::path out = dir / "out";
  const auto r = RunTool("igi-run", Quote((dir / "none").string()) + " --scene " +
                                        Quote(kScene.string()) + " --out " + Quote(out.string()));
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_EQ(ErrorLines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("PHOTOS_DIR"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
  fs::remove_all(dir);
}

// A photo folder naming a lighting the scene lacks, and a bracket without enough exposures:
// each one line "FILE: KEY: VALUE: RULE", exit 2, nothing written.
TEST(RunE2eTest, BadLayoutExits2WithOneLinePerProblem) {
  const fs::path dir = test::UniqueTempDir("igi_run_e2e");
  const fs::path photos = dir / "photos";
  fs::create_directories(photos / "cam0_L7");
  std::ofstream(photos / "cam0_L7" / "a.exr") << "x";
  fs::create_directories(photos / "cam1_L0");
  std::ofstream(photos / "cam1_L0" / "00.png") << "x";
  std::ofstream(photos / "cam1_L0" / "01.png") << "x";
  std::ofstream(photos / "cam1_L0" / "exposures.txt") << "0.01\n";
  const fs::path out = dir / "out";
  const auto r = RunTool("igi-run", Quote(photos.string()) + " --scene " + Quote(kScene.string()) +
                                        " --skip-diagnose --out " + Quote(out.string()));
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_EQ(ErrorLines(r.err), 2) << r.err;
  EXPECT_NE(r.err.find("cam0_L7: lighting: cam0_L7: folder name must end in _LIGHTING"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("exposures.txt: 1 exposures: must list one per image (2)"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(out));
  fs::remove_all(dir);
}

TEST(RunE2eTest, BadRadianceScaleExits2AndWritesNothing) {
  const fs::path dir = test::UniqueTempDir("igi_run_e2e");
  fs::create_directories(dir / "photos");
  const fs::path out = dir / "out";
  const auto r =
      RunTool("igi-run", Quote((dir / "photos").string()) + " --scene " + Quote(kScene.string()) +
                             " --radiance-scale 0 --out " + Quote(out.string()));
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_EQ(ErrorLines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("--radiance-scale"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
  fs::remove_all(dir);
}

TEST(RunE2eTest, BadSceneExits2) {
  const fs::path dir = test::UniqueTempDir("igi_run_e2e");
  std::ofstream(dir / "scene.json") << R"({"format": "igi-scene", "version": 1, "bogus": 1})";
  fs::create_directories(dir / "photos");
  const auto r = RunTool("igi-run", Quote((dir / "photos").string()) + " --scene " +
                                        Quote((dir / "scene.json").string()) + " --out " +
                                        Quote((dir / "out").string()));
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("bogus"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "out"));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace igi
