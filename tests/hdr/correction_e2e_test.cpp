// igi-hdr's corrections (hdr/correction.h): --camera divides the vignetting out, --colour
// applies the colour matrix, and a correction that does not fit the input is refused before
// anything is written.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <filesystem>

#include "calib/camera_file.h"
#include "calib/colour_chart.h"
#include "calib/vignetting.h"
#include "tests/e2e/run.h"
#include "tests/temp_dir.h"
#include "tools/common/image.h"

namespace igi::calib {
namespace {

namespace fs = std::filesystem;
using test::Quote;
using test::RunTool;

class HdrCorrectionTest : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = test::UniqueTempDir("igi_hdr_correction"); }
  void TearDown() override { fs::remove_all(dir_); }

  // Two 16-bit frames (exposures 1 and 2) of `value`(x, y) RGB; their paths, quoted.
  template <typename Value>
  std::string WriteBracket(int w, int h, const Value& value) {
    std::string images;
    for (int j = 0; j < 2; ++j) {
      Image frame(w, h, 3);
      for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
          const Eigen::Vector3d v = value(x, y);
          for (int c = 0; c < 3; ++c) frame.at(x, y, c) = float((j + 1) * v[c]);
        }
      }
      const fs::path path = dir_ / ("f" + std::to_string(j) + ".png");
      WriteImageOptions o;
      o.type = PixelType::kUInt16;
      WriteImage(path, frame, o);
      images += Quote(path.string()) + " ";
    }
    return images;
  }

  fs::path dir_;
};

// igi-hdr --camera divides the fall-off out of a merged bracket: a uniform grey recorded through
// the fall-off comes out uniform; a camera.json of another size is refused before anything is
// written.
TEST_F(HdrCorrectionTest, CameraDividesTheFallOffOut) {
  const int w = 160, h = 120;
  CameraFile camera;
  camera.width = w;
  camera.height = h;
  camera.vignetting = CameraVignetting{{-0.3, 0.05}, "flat_field", 0, 0, 0};
  WriteCameraFile(dir_ / "camera.json", camera);
  const std::string images = WriteBracket(w, h, [&](int x, int y) {
    const double v = camera.vignetting->model.Factor(
        VignettingRadius2(x + 0.5, y + 0.5, w / 2.0, h / 2.0, w, h));
    return Eigen::Vector3d::Constant(0.3 * v);
  });
  const fs::path out = dir_ / "radiance.exr";
  const auto r = RunTool("igi-hdr", images + "--linear --exposures 1,2 --camera " +
                                        Quote((dir_ / "camera.json").string()) + " --out " +
                                        Quote(out.string()));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Image radiance = ReadImage(out);
  double lo = 1e9, hi = 0;
  for (float v : radiance.pixels) {
    lo = std::min(lo, double(v));
    hi = std::max(hi, double(v));
  }
  EXPECT_NEAR(lo, 0.3, 0.001);
  EXPECT_NEAR(hi, 0.3, 0.001);

  camera.width = 320;
  camera.height = 240;
  WriteCameraFile(dir_ / "other.json", camera);
  const fs::path refused = dir_ / "refused.exr";
  const auto bad = RunTool("igi-hdr", images + "--linear --exposures 1,2 --camera " +
                                          Quote((dir_ / "other.json").string()) + " --out " +
                                          Quote(refused.string()));
  EXPECT_EQ(bad.exit_code, 2) << bad.err;
  EXPECT_NE(bad.err.find("160x120: must be 320x240"), std::string::npos) << bad.err;
  EXPECT_FALSE(fs::exists(refused));
}

// A matrix fitted to linear images turns each merged pixel's RGB; one fitted to raw camera RGB
// is refused for 16-bit frames, naming the file and the key.
TEST_F(HdrCorrectionTest, ColourAppliesTheMatrixToTheInputItWasFittedTo) {
  ColourFile colour;
  colour.matrix << 1.6, -0.4, -0.2, -0.3, 1.5, -0.2, 0.0, -0.5, 1.5;
  colour.input = ColourInput::kLinear;
  colour.delta_e2000.per_patch.assign(24, 1.0);
  WriteColourFile(dir_ / "colour.json", colour);
  const Eigen::Vector3d rgb(0.2, 0.3, 0.25);
  const std::string images = WriteBracket(40, 30, [&](int, int) { return rgb; });
  const fs::path out = dir_ / "radiance.exr";
  const auto r = RunTool("igi-hdr", images + "--linear --exposures 1,2 --colour " +
                                        Quote((dir_ / "colour.json").string()) + " --out " +
                                        Quote(out.string()));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Image radiance = ReadImage(out);
  const Eigen::Vector3d expected = colour.matrix * rgb;
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(radiance.at(20, 15, c), expected[c], 1e-4) << c;

  colour.input = ColourInput::kCameraRaw;
  WriteColourFile(dir_ / "raw.json", colour);
  const fs::path refused = dir_ / "refused.exr";
  const auto bad = RunTool("igi-hdr", images + "--linear --exposures 1,2 --colour " +
                                          Quote((dir_ / "raw.json").string()) + " --out " +
                                          Quote(refused.string()));
  EXPECT_EQ(bad.exit_code, 2) << bad.err;
  EXPECT_NE(bad.err.find("raw.json: input: camera_raw"), std::string::npos) << bad.err;
  EXPECT_FALSE(fs::exists(refused));
}

}  // namespace
}  // namespace igi::calib
