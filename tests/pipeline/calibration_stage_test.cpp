// igi-run's HDR stage applies PHOTOS_DIR/camera.json's vignetting (igi-calib vignetting): the
// RADIANCE reference room's photo with a fall-off multiplied in comes out of 02-hdr as the
// photo RADIANCE rendered, the stage's marker records the calibration, and the report shows it.
// A camera.json that breaks its rules stops the run before anything is written.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "calib/camera_file.h"
#include "calib/vignetting.h"
#include "tests/temp_dir.h"
#include "tools/common/error.h"
#include "tools/common/image.h"
#include "tools/common/json.h"
#include "tools/pipeline/pipeline.h"
#include "tools/pipeline/run_report.h"
#include "tools/pipeline/stage_marker.h"

namespace igi::pipeline {
namespace {
namespace fs = std::filesystem;

const fs::path kRoom = fs::path(IGI_SHARED_DATA_DIR) / "reference" / "radiance_room";

TEST(CalibrationStageTest, HdrStageDividesOutTheCamerasVignetting) {
  const fs::path dir = test::UniqueTempDir("igi_calibration_stage");
  const fs::path photos = dir / "photos";
  fs::create_directories(photos / "cam0_L0");
  const Image truth = ReadImage(kRoom / "photos" / "cam0_L0.exr", 3);
  const calib::Vignetting v{-0.3, 0.05};
  Image vignetted = truth;
  for (int y = 0; y < truth.height; ++y) {
    for (int x = 0; x < truth.width; ++x) {
      const double f = v.Factor(calib::VignettingRadius2(
          x + 0.5, y + 0.5, truth.width / 2.0, truth.height / 2.0, truth.width, truth.height));
      for (int c = 0; c < 3; ++c) vignetted.at(x, y, c) *= float(f);
    }
  }
  WriteImage(photos / "cam0_L0" / "radiance.exr", vignetted);
  calib::CameraFile camera;
  camera.width = truth.width;
  camera.height = truth.height;
  camera.vignetting = calib::CameraVignetting{v, "flat_field", 0.003, 1000, 4};
  calib::WriteCameraFile(photos / "camera.json", camera);

  RunOptions o;
  o.photos_dir = photos;
  o.scene = kRoom / "scene.json";
  o.out = dir / "run";
  o.bin_dir = IGI_BIN_DIR;
  o.skip_diagnose = true;
  o.stop_after = "02-hdr";
  RunPipeline(o);
  const Image hdr = ReadImage(o.out / "02-hdr" / "cam0_L0.exr");
  ASSERT_EQ(hdr.pixels.size(), truth.pixels.size());
  double worst = 0;
  for (size_t i = 0; i < hdr.pixels.size(); ++i) {
    worst = std::max(worst, std::abs(double(hdr.pixels[i]) - truth.pixels[i]) /
                                std::max(1e-3, double(truth.pixels[i])));
  }
  EXPECT_LT(worst, 1e-5);
  const auto marker = ReadStageMarker(o.out / "02-hdr");
  ASSERT_TRUE(marker);
  EXPECT_DOUBLE_EQ(marker->details["vignetting"]["k1"].get<double>(), -0.3);
  WriteRunReport({o.out});
  std::ifstream report(o.out / "report.html");
  const std::string html((std::istreambuf_iterator<char>(report)), {});
  EXPECT_NE(html.find("k1 -0.3000, k2 0.0500 (corner -25.0 %)"), std::string::npos);

  // A camera.json whose fall-off turns negative in the image: one line, nothing written.
  std::ofstream(photos / "camera.json") << R"({"format": "igi-camera", "width": 320, "height": 240,
            "vignetting": {"k1": -1.2, "k2": 0.1}})";
  o.out = dir / "refused";
  EXPECT_THROW(RunPipeline(o), InputError);
  EXPECT_FALSE(fs::exists(o.out));
  fs::remove_all(dir);
}

// Calibrated lights (igi-calib lights' lights.json) replace the scene's entries of the same names
// in the scene igi-solve gets, the solve stage records them and the report lists them; a
// lights.json naming a light the scene lacks stops the run before anything is written.
TEST(CalibrationStageTest, CalibratedLightsReplaceTheScenesInTheSolve) {
  const fs::path dir = test::UniqueTempDir("igi_calibration_lights");
  const Json lamp = {{"type", "sphere"},
                     {"center", {2.01, 1.99, 2.6}},
                     {"radius", 0.1},
                     {"radiance", {990.0, 990.0, 990.0}}};
  WriteJsonFile(dir / "lights.json",
                Json{{"format", "igi-lights"}, {"version", 1}, {"lights", {{"lamp", lamp}}}});
  RunOptions o;
  o.hdr_photos = true;
  o.scene = kRoom / "scene.json";
  o.lights = dir / "lights.json";
  o.out = dir / "run";
  o.bin_dir = IGI_BIN_DIR;
  o.skip_diagnose = true;
  o.stop_after = "04-solve";
  o.solve_args = {"--refine-iterations=0", "--indirect-rays=16"};
  RunPipeline(o);
  const Json solved_input = ReadJsonFile(o.out / "04-solve" / "input" / "scene.json");
  EXPECT_EQ(solved_input["lights"]["lamp"], lamp);
  EXPECT_EQ(solved_input["lights"]["lamp2"]["radiance"][0].get<double>(), 1500.0);
  WriteRunReport({o.out});
  std::ifstream report(o.out / "report.html");
  const std::string html((std::istreambuf_iterator<char>(report)), {});
  EXPECT_NE(html.find("lights (replace the scene&#39;s)"), std::string::npos);

  WriteJsonFile(dir / "bad.json", Json{{"format", "igi-lights"},
                                       {"version", 1},
                                       {"lights", {{"lamp9", lamp}}}});
  o.lights = dir / "bad.json";
  o.out = dir / "refused";
  try {
    RunPipeline(o);
    ADD_FAILURE() << "a light the scene lacks was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.json: lights.lamp9"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(o.out));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace igi::pipeline
