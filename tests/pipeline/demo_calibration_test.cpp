// igi-run --demo's absolute calibration (pipeline/demo.h MeasureRadianceScale): the median ratio
// of the HDR maps to igi-synth's noise-free radiance, whatever a few outliers do.
#include <gtest/gtest.h>

#include <filesystem>

#include "pipeline/demo.h"
#include "tests/temp_dir.h"
#include "tools/common/error.h"
#include "tools/common/image.h"
#include "tools/common/json.h"

namespace igi {
namespace {
namespace fs = std::filesystem;

Image Constant(int w, int h, float v) {
  Image im;
  im.width = w;
  im.height = h;
  im.channels = 3;
  im.pixels.assign(size_t(w) * h * 3, v);
  return im;
}

TEST(DemoCalibrationTest, MedianRatioOfHdrToTrueRadiance) {
  const fs::path dir = test::UniqueTempDir("demo_calibration");
  const fs::path synth = dir / "synth", hdr = dir / "hdr";
  fs::create_directories(synth / "truth" / "radiance");
  fs::create_directories(hdr);
  Json sets = Json::array();
  for (int i = 0; i < 2; ++i) {
    const std::string name = "cam" + std::to_string(i) + "_L0";
    Image truth = Constant(20, 10, 0.5f + i);
    for (size_t k = 0; k < truth.pixels.size(); ++k) truth.pixels[k] += 0.001f * float(k % 50);
    Image measured = truth;
    for (float& v : measured.pixels) v *= 0.25f;
    measured.pixels[0] = 1e6f;   // a hot pixel
    measured.pixels[7] = -1.0f;  // a masked one
    WriteImage(synth / "truth" / "radiance" / (name + ".exr"), truth);
    WriteImage(hdr / (name + ".exr"), measured);
    sets.push_back({{"dir", "brackets/" + name}, {"radiance", "truth/radiance/" + name + ".exr"}});
  }
  WriteJsonFile(synth / "truth.json", Json{{"brackets", {{"sets", sets}}}});
  EXPECT_NEAR(MeasureRadianceScale(hdr, synth), 0.25, 1e-6);
  fs::remove_all(hdr);
  fs::create_directories(hdr);
  EXPECT_THROW(MeasureRadianceScale(hdr, synth), Error);  // no HDR map to compare
  fs::remove_all(dir);
}

// The comparison leaves out regions whose material was given (the reference) from both the
// table and the median k, and --demo-calibration takes only its three values.
TEST(DemoCalibrationTest, ComparisonLeavesOutTheGivenReference) {
  const fs::path dir = test::UniqueTempDir("demo_compare");
  fs::create_directories(dir);
  WriteJsonFile(dir / "truth.json",
                Json{{"materials",
                      {{"a", {{"rho_d", {0.5, 0.5, 0.5}}}},
                       {"b", {{"rho_d", {0.2, 0.2, 0.2}}, {"rho_s", 0.1}}},
                       {"ref", {{"rho_d", {0.7, 0.7, 0.7}}}}}}});
  WriteJsonFile(dir / "scene.json",
                Json{{"materials",
                      {{"a", {{"rho_d", {1.0, 1.0, 1.0}}}},
                       {"b", {{"rho_d", {0.4, 0.4, 0.4}}, {"rho_s", 0.2}}},
                       {"ref", {{"rho_d", {0.7, 0.7, 0.7}}}}}}});
  const Json all = CompareWithTruth(dir / "scene.json", dir / "truth.json");
  EXPECT_EQ(all["regions"].size(), 3u);
  const Json without = CompareWithTruth(dir / "scene.json", dir / "truth.json", {"ref"});
  ASSERT_EQ(without["regions"].size(), 2u);
  // a and b are both 2x their truth: k = 2 once the reference (1x) is out of the median.
  EXPECT_NEAR(without["photometric_scale_k"].get<double>(), 2.0, 1e-9);
  for (const Json& r : without["regions"]) {
    EXPECT_NE(r["region"], "ref");
    EXPECT_NEAR(r["rho_d"]["relative_error"].get<double>(), 0.0, 1e-9);
  }
  fs::remove_all(dir);
  DemoOptions o;
  o.out = dir;
  EXPECT_NO_THROW(o.Validate());
  o.calibration = "guess";
  EXPECT_THROW(o.Validate(), InputError);
}

}  // namespace
}  // namespace igi
