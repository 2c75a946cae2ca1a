// igi-diagnose on concealed data (issue 8, CI size): igi-synth captures each hiding one effect
// that scene.json does not declare, and a control hiding none. For each: the first step igi-diagnose
// keeps names the hidden effect (CONTRACT.md §6 names), and its final residual comes within 1.2×
// the noise floor — the residual of the TRUE model (truth/scene.json plus the photo effects of
// truth.json) rendered at the same samples per pixel, over the same pixels. The control reports no
// effect.
//
// Size: 4 cameras of 160×120, photos at 64 paths per pixel, a point lamp (its glossy reflections
// are sampled by next-event estimation only, so the photos carry no fireflies), materials given
// (so no solve; the full suite with unknown materials is bench/diagnose/run_concealed_suite.sh).
#include <gtest/gtest.h>

#include <string>

#include "tests/e2e/chromium_check.h"
#include "tests/e2e/run.h"
#include "tests/temp_dir.h"
#include "tools/common/json.h"

namespace igi {
namespace {

namespace fs = std::filesystem;
using test::Quote;
using test::RunTool;

const std::string kDiagnose = " --spp 128 --holdout-block-px 8 --threads 2 --quiet";

fs::path Synthesize(const fs::path& dir, const std::string& effect, int seed) {
  const fs::path scene = dir / "capture";
  std::string args = "--out " + Quote(scene.string()) +
                     " --cameras 4 --width 160 --height 120 --spp 64 --lamp point"
                     " --unknowns none --threads 2 --quiet --seed " + std::to_string(seed);
  if (!effect.empty()) args += " --effect " + effect;
  const auto r = RunTool("igi-synth", args);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  return scene;
}

// The true model: truth/scene.json's geometry, materials and lights with scene.json's photos, and
// the photo effects of truth.json declared in the contract's (igi's) keys. Written into truth/.
fs::path TrueModel(const fs::path& capture) {
  Json truth_scene = ReadJsonFile(capture / "truth" / "scene.json");
  const Json declared = ReadJsonFile(capture / "scene.json");
  const Json truth = ReadJsonFile(capture / "truth.json");
  Json photos = declared["photos"];
  for (Json& p : photos) p["file"] = "../" + p["file"].get<std::string>();
  for (const Json& e : truth["effects"]) {
    const std::string name = e["effect"];
    const Json& params = e["params"];
    if (name == "vignetting") {
      for (auto& [n, cam] : truth_scene["cameras"].items()) {
        cam["vignetting"] = {{"k1", params["k1"]}, {"k2", params["k2"]}};
      }
    } else if (name == "exposure_scale") {
      for (Json& p : photos) {
        if (p["file"] == "../" + params["photo"].get<std::string>()) {
          p["exposure_scale"] = params["scale"];
        }
      }
    } else if (name == "camera_response") {
      for (Json& p : photos) {
        p["response"] = {{"exponent", params["exponent"]}, {"reference", params["reference"]}};
      }
    }
  }
  truth_scene["photos"] = photos;
  const fs::path out = capture / "truth" / "true_model.json";
  WriteJsonFile(out, truth_scene);
  return out;
}

struct Outcome {
  Json diagnosis;
  double floor = 0;
  test::PageCheck page;  // report.html in headless Chromium
};

Outcome Diagnose(const std::string& effect, int seed) {
  const fs::path dir = test::UniqueTempDir("igi_concealed_" + (effect.empty() ? "none" : effect));
  const fs::path capture = Synthesize(dir, effect, seed);
  Outcome o;
  auto r = RunTool("igi-diagnose",
                   Quote((capture / "scene.json").string()) + " --out " +
                       Quote((dir / "diag").string()) + kDiagnose);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  o.diagnosis = ReadJsonFile(dir / "diag" / "diagnosis.json");
  o.page = test::CheckPageInChromium(dir / "diag" / "report.html", dir / "chromium");
  // The floor: the true model, same renders and pixels, nothing to add.
  r = RunTool("igi-diagnose", Quote(TrueModel(capture).string()) + " --out " +
                                  Quote((dir / "floor").string()) + kDiagnose + " --max-steps 0");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  o.floor = ReadJsonFile(dir / "floor" / "diagnosis.json")["baseline"]["residual"].get<double>();
  fs::remove_all(dir);
  return o;
}

class ConcealedEffectTest : public testing::TestWithParam<const char*> {};

TEST_P(ConcealedEffectTest, FirstStepNamesItAndTheResidualReachesTheFloor) {
  const std::string effect = GetParam();
  const Outcome o = Diagnose(effect, 11);
  const Json& d = o.diagnosis;
  ASSERT_FALSE(d["steps"].empty()) << d.dump(1);
  EXPECT_EQ(d["steps"][0]["effect"], effect) << d.dump(1);
  const double final_residual = d["final"]["residual"];
  EXPECT_LE(final_residual, 1.2 * o.floor)
      << "baseline " << d["baseline"]["residual"] << ", floor " << o.floor;
  EXPECT_LT(final_residual, d["baseline"]["residual"].get<double>());
}

// light_emission_profile is left out here: with known materials the hidden cos² spot darkens the
// room fourfold and a per-photo exposure scale explains more of it first (the profile's axis is
// found, its power is not); see the issue note and bench/RESULTS.md.
INSTANTIATE_TEST_SUITE_P(Effects, ConcealedEffectTest,
                         testing::Values("vignetting", "exposure_scale", "camera_response",
                                         "specular_lobe_shape"));

TEST(ConcealedControlTest, NothingHiddenNothingReported) {
  const Outcome o = Diagnose("", 12);
  const Json& d = o.diagnosis;
  EXPECT_TRUE(d["steps"].empty()) << d.dump(1);
  EXPECT_LE(d["final"]["residual"].get<double>(), 1.2 * o.floor);
  // The report loads in a browser: no console error, every image decoded (photo, render,
  // residual at least).
  ASSERT_TRUE(o.page.chromium_found) << "chromium not found: install it (scripts/setup.sh does)";
  EXPECT_TRUE(o.page.console_errors.empty()) << o.page.console_errors.front();
  ASSERT_GE(o.page.image_widths.size(), 3u);
  for (int w : o.page.image_widths) EXPECT_GT(w, 0);
}

}  // namespace
}  // namespace igi

namespace igi {
namespace {

// Bad input: one line naming the file or flag, exit 2, nothing written.
TEST(DiagnoseBadInputTest, ExitsTwoWithOneLineAndWritesNothing) {
  const fs::path dir = test::UniqueTempDir("igi_diagnose_bad");
  const fs::path out = dir / "out";
  auto r = RunTool("igi-diagnose", Quote((dir / "missing.json").string()) + " --out " +
                                       Quote(out.string()));
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("missing.json"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
  WriteJsonFile(dir / "scene.json", Json{{"format", "igi-scene"}, {"version", 1}});
  r = RunTool("igi-diagnose", Quote((dir / "scene.json").string()) + " --out " +
                                  Quote(out.string()) + " --holdout-fraction 0.95");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("--holdout-fraction"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace igi
