// igi-diagnose on concealed data (CI size): igi-synth captures each hiding one effect
// that scene.json does not declare, and a control hiding none. For each: the first step
// igi-diagnose keeps names the hidden effect (docs/diagnose-effects.md names), and its final
// residual comes within 1.2× the noise floor — the residual of the TRUE model (truth/scene.json
// plus the photo effects of truth.json) rendered at the same samples per pixel, over the same
// pixels. The control reports no effect.
//
// Size: 4 cameras of 160×120, photos at 64 paths per pixel, a point lamp (its glossy reflections
// are sampled by next-event estimation only, so the photos carry no fireflies), materials given
// (so no solve; the full suite with unknown materials is bench/diagnose/run_concealed_suite.sh).
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "tests/diagnose/concealed_fixture.h"
#include "tests/e2e/chromium_check.h"

namespace igi::diagnose {
namespace {

namespace fs = std::filesystem;
using test::ConcealedOutcome;
using test::DiagnoseConcealed;
using test::Quote;
using test::RunTool;

class ConcealedEffectTest : public testing::TestWithParam<const char*> {};

TEST_P(ConcealedEffectTest, FirstStepNamesItAndTheResidualReachesTheFloor) {
  const std::string effect = GetParam();
  const ConcealedOutcome o = DiagnoseConcealed(effect, 11);
  const Json& d = o.diagnosis;
  ASSERT_FALSE(d["steps"].empty()) << d.dump(1);
  EXPECT_EQ(d["steps"][0]["effect"], effect) << d.dump(1);
  test::ExpectReachesTheFloor(o);
}

// fresnel needs a capture that sees a glossy surface at grazing incidence, where Schlick's weight
// departs from 1 (at the default views' 35-50 deg it is within 2 %, and the true model's residual
// is the declared one's): the lamp 0.6 m above the floor and one more camera on the mirror view of
// the floor's highlight at 60-80 deg (igi-synth --lamp-position, --grazing-cameras). Only the
// floor is Fresnel-weighted (at that lamp height every region would be, and the glossy box's top
// face, lit at 90 deg, would send a narrow lobe 25x brighter into the box's camera). Measured
// (seed 11): fresnel first, ior 1.5 (truth 1.5), amplitude 1.03, held-out residual² down 36.8 %
// (4.0 standard errors); specular_lobe_shape also passed (29.7 %) and was not applied; final
// 0.0536 against a baseline of 0.0591.
TEST(ConcealedFresnelTest, GrazingViewOfTheFloorNamesFresnelFirst) {
  const ConcealedOutcome o = DiagnoseConcealed("fresnel:regions=floor", 11, nullptr,
                                               " --lamp-position 2,2,0.6 --grazing-cameras 1");
  const Json& d = o.diagnosis;
  ASSERT_FALSE(d["steps"].empty()) << d.dump(1);
  EXPECT_EQ(d["steps"][0]["effect"], "fresnel") << d.dump(1);
  EXPECT_EQ(d["steps"][0]["params"]["region"], "floor") << d.dump(1);
  EXPECT_NEAR(d["steps"][0]["params"]["ior"].get<double>(), 1.5, 0.25) << d.dump(1);
  test::ExpectReachesTheFloor(o);
}

// A microfacet lobe in photos of regions declared Ward: the glossy regions are truly GGX (their
// ρs as F0 and α kept), and specular_lobe_shape, which tries each of the other lobes, names GGX
// first.
TEST(ConcealedLobeFamilyTest, AGgxLobeDeclaredWardIsNamedGgx) {
  const ConcealedOutcome o = DiagnoseConcealed("specular_lobe_shape:to=ggx", 11);
  const Json& d = o.diagnosis;
  ASSERT_FALSE(d["steps"].empty()) << d.dump(1);
  EXPECT_EQ(d["steps"][0]["effect"], "specular_lobe_shape") << d.dump(1);
  EXPECT_EQ(d["steps"][0]["params"]["to"], "ggx") << d.dump(1);
  test::ExpectReachesTheFloor(o);
}

// The same for a Beckmann lobe declared Ward (slow-labelled below: the same candidate and
// search as GGX's).
class ConcealedLobeFamilyNameTest : public testing::TestWithParam<const char*> {};
TEST_P(ConcealedLobeFamilyNameTest, ALobeDeclaredWardIsNamedAsItIs) {
  const std::string lobe = GetParam();
  const ConcealedOutcome o = DiagnoseConcealed("specular_lobe_shape:to=" + lobe, 11);
  const Json& d = o.diagnosis;
  ASSERT_FALSE(d["steps"].empty()) << d.dump(1);
  EXPECT_EQ(d["steps"][0]["effect"], "specular_lobe_shape") << d.dump(1);
  EXPECT_EQ(d["steps"][0]["params"]["to"], lobe) << d.dump(1);
  test::ExpectReachesTheFloor(o);
}
INSTANTIATE_TEST_SUITE_P(SlowEffects, ConcealedLobeFamilyNameTest, testing::Values("beckmann"));

// light_emission_profile, anisotropic_reflection and light_source_extent:
// concealed_brdf_light_test.cpp; missing_geometry and pose_error: concealed_geometry_test.cpp.
// Labelled slow: the photo effects (CI names them in another renderer's photos,
// concealed_outside_test.cpp) and the Ward lobe's shape (CI names a GGX lobe declared Ward,
// ConcealedLobeFamilyTest above).
INSTANTIATE_TEST_SUITE_P(SlowEffects, ConcealedEffectTest,
                         testing::Values("vignetting", "exposure_scale", "camera_response",
                                         "specular_lobe_shape"));

TEST(ConcealedControlTest, NothingHiddenNothingReported) {
  test::PageCheck page;  // report.html in headless Chromium
  const ConcealedOutcome o = DiagnoseConcealed("", 12, [&](const fs::path& diag) {
    page = test::CheckPageInChromium(diag / "report.html", diag.parent_path() / "chromium");
  });
  const Json& d = o.diagnosis;
  EXPECT_TRUE(d["steps"].empty()) << d.dump(1);
  EXPECT_LE(d["final"]["residual"].get<double>(), 1.2 * o.floor);
  // The report loads in a browser: no console error, every image decoded (photo, render,
  // residual at least).
  ASSERT_TRUE(page.chromium_found) << "chromium not found: install it (scripts/setup.sh does)";
  EXPECT_TRUE(page.console_errors.empty()) << page.console_errors.front();
  ASSERT_GE(page.image_widths.size(), 3u);
  for (int w : page.image_widths) EXPECT_GT(w, 0);
}

}  // namespace
}  // namespace igi::diagnose

namespace igi::diagnose {
namespace {

// Photos larger than --analysis-megapixels are diagnosed as the means of pixel blocks: a capture
// of 320 x 240 photos at 16 paths per pixel analysed at 0.02 MP (2 x 2 blocks: the CI size, 64
// paths per analysed pixel) names the hidden vignetting first, with the corners' fall-off of the
// truth, and reaches the floor measured the same way; the improved scene.json names the photos
// and intrinsics as declared.
TEST(ConcealedLargePhotosTest, VignettingIsNamedOnBlockMeansAndTheSceneKeepsTheDeclaredPhotos) {
  const fs::path dir = test::UniqueTempDir("igi_concealed_large");
  const fs::path capture = dir / "capture";
  const test::RunResult synth = RunTool(
      "igi-synth", "--out " + Quote(capture.string()) +
                       " --cameras 4 --width 320 --height 240 --spp 16 --lamp point --unknowns "
                       "none --threads 2 --quiet --seed 11 --effect vignetting");
  ASSERT_EQ(synth.exit_code, 0) << synth.err;
  const std::string analysis = " --analysis-megapixels 0.02";
  const Json d = test::RunDiagnose(capture / "scene.json", dir / "diag", analysis);
  ASSERT_TRUE(d.contains("analysis")) << d.dump(1);
  for (const auto& [name, cam] : d["analysis"]["cameras"].items()) {
    EXPECT_EQ(cam["factor"], 2) << name;
    EXPECT_EQ(cam["width"], 160) << name;
  }
  ASSERT_FALSE(d["steps"].empty()) << d.dump(1);
  EXPECT_EQ(d["steps"][0]["effect"], "vignetting") << d.dump(1);
  const Json truth = ReadJsonFile(capture / "truth.json");
  ASSERT_EQ(truth["effects"].size(), 1u);
  const Json& tp = truth["effects"][0]["params"];
  const Json& fp = d["steps"][0]["params"];
  EXPECT_NEAR(fp["k1"].get<double>() + fp["k2"].get<double>(),
              tp["k1"].get<double>() + tp["k2"].get<double>(), 0.05)
      << d["steps"][0].dump(1);
  // The improved scene: the declared photos and intrinsics, the fitted vignetting.
  const Json declared = ReadJsonFile(capture / "scene.json");
  const Json improved = ReadJsonFile(dir / "diag" / "scene.json");
  for (size_t i = 0; i < declared["photos"].size(); ++i) {
    const fs::path file = dir / "diag" / improved["photos"][i]["file"].get<std::string>();
    EXPECT_TRUE(fs::equivalent(file, capture / declared["photos"][i]["file"].get<std::string>()))
        << file;
  }
  for (const auto& [name, cam] : declared["cameras"].items()) {
    EXPECT_EQ(improved["cameras"][name]["width"], 320);
    EXPECT_EQ(improved["cameras"][name]["params"], cam["params"]);
    EXPECT_TRUE(improved["cameras"][name].contains("vignetting"));
  }
  const test::RunResult info = RunTool("igi-info", Quote((dir / "diag" / "scene.json").string()));
  EXPECT_EQ(info.exit_code, 0) << info.err;
  // The floor: the true model diagnosed the same way, no step.
  const Json floor =
      test::RunDiagnose(test::WriteTrueModel(capture), dir / "floor", " --max-steps 0" + analysis);
  ASSERT_TRUE(floor.contains("baseline"));
  test::ConcealedOutcome o{d, floor["baseline"]["residual"].get<double>()};
  std::printf("[large photos] k1 + k2 %.4f (truth %.4f); final %.4f, floor %.4f\n",
              fp["k1"].get<double>() + fp["k2"].get<double>(),
              tp["k1"].get<double>() + tp["k2"].get<double>(), d["final"]["residual"].get<double>(),
              o.floor);
  test::ExpectReachesTheFloor(o);
  fs::remove_all(dir);
}

// Bad input: one line naming the file or flag, exit 2, nothing written.
TEST(DiagnoseBadInputTest, ExitsTwoWithOneLineAndWritesNothing) {
  const fs::path dir = test::UniqueTempDir("igi_diagnose_bad");
  const fs::path out = dir / "out";
  auto r = RunTool("igi-diagnose",
                   Quote((dir / "missing.json").string()) + " --out " + Quote(out.string()));
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
}  // namespace igi::diagnose
