// light_intensity (solver/diagnose/effects/light_intensity.cpp) on floor records the renderer
// path-traces: a soft shadow is not read as a weaker light (the light's intensity is fitted away
// from where its size shows). And its Write: the light's value is scaled by the fitted factor.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "solver/diagnose/candidates.h"
#include "solver/diagnose/effects/effects.h"
#include "solver/diagnose/pixel_records.h"
#include "solver/diagnose/residual_fit.h"
#include "tests/diagnose/one_light_record.h"
#include "tests/diagnose/shadow_records.h"

namespace igi::diagnose {
namespace {

using Eigen::Vector3f;
using namespace test::shadow;

// A soft shadow read as a weaker light: a source larger than declared darkens the lit side of
// every penumbra, where a point model's basis (its simulated radiance) is large, and brightens the
// shadowed side, where it is 0 (nothing else lights this floor): a fit of the light's intensity
// over every record reads the extent as a weaker light (igi-synth's room: 0.952 for a sphere of
// 0.25 m with the same intensity, kept before the extent itself). light_intensity fits away from
// where the light's size shows (WhereLightSizeShows) and finds the intensity unchanged.
TEST(LightIntensityTest, ASoftShadowIsNotAWeakerLight) {
  const recon::Scene model = ShadowScene(0);
  const Json declared = Json{{"lights", {{"lamp", {{"type", "point"}}}}}};
  std::vector<PixelRecord> records = ShadowRecords(model, 0.3);
  for (PixelRecord& r : records) {  // every record lit by the lamp alone (the photo's lighting)
    const Vector3f to = kLamp.cast<float>() - r.position;
    r.lights = {RecordLightSample{0, to.normalized(), Vector3f::Ones(), to.norm()}};
  }
  const CandidateContext cx{model, declared, false};
  const std::vector<bool> shows = WhereLightSizeShows(cx, records, 0);
  const int at_edges = int(std::count(shows.begin(), shows.end(), true));
  EXPECT_GT(at_edges, 20);
  EXPECT_LT(at_edges, int(records.size()) / 2);  // a 0.5 m sphere 1.2 m above the blocker
  // Over every record the fitted scale of the lamp is biased low.
  const ResidualFitter all(records, std::vector<int>(records.size(), 0), 1, false, 8);
  const ResidualFit plain =
      all.Fit(1, [](const PixelRecord& r, int c, double* b) { b[0] = r.sim[c]; });
  ASSERT_EQ(plain.coef.size(), 1);
  const double plain_factor = 1 + plain.coef[0];
  // The candidate, the others excluded.
  std::vector<std::string> excluded = {"exposure_scale",
                                       "vignetting",
                                       "camera_response",
                                       "ambient_light",
                                       "light_emission_profile:lamp",
                                       "light_source_extent:lamp",
                                       "diffuse_shape"};
  for (const char* region : {"floor", "blocker"}) {
    for (const char* e :
         {"specular_lobe_shape:", "fresnel:", "anisotropic_reflection:", "specular_reflection:",
          "diffuse_shape:"}) {
      excluded.push_back(std::string(e) + region);
    }
  }
  const std::vector<CandidateResult> cands =
      EvaluateCandidates(MakeEffects(), cx, records, excluded);
  ASSERT_EQ(cands.size(), 1u);
  const CandidateResult& c = cands[0];
  ASSERT_EQ(c.effect, "light_intensity");
  std::printf("lamp's scale over every record %.4f, away from its penumbrae %.4f (%d left out)\n",
              plain_factor, c.valid ? c.params["factor"].get<double>() : 0.0, at_edges);
  EXPECT_LT(plain_factor, 0.98);
  // Fitted away from the penumbrae the light's scale is its true one (a valid fit of factor 1,
  // not a rejected one: the records left out must still leave a fit).
  ASSERT_TRUE(c.valid) << c.note;
  EXPECT_NEAR(c.params["factor"].get<double>(), 1.0, 0.01);
  EXPECT_NE(c.evidence.find("left out of the fit"), std::string::npos) << c.evidence;
}

// Write multiplies the named light's value by the factor, whichever its type carries: a point's
// intensity, a sphere's radiance, a directional light's irradiance, each channel; its other keys
// and the other lights are left as they were.
TEST(LightIntensityTest, WriteScalesTheLightsValueWhateverItsType) {
  Json doc = {
      {"lights",
       {{"lamp", {{"type", "point"}, {"position", {0, 0, 2}}, {"intensity", {4.0, 2.0, 1.0}}}},
        {"globe",
         {{"type", "sphere"},
          {"center", {1, 0, 2}},
          {"radius", 0.1},
          {"radiance", {100.0, 50.0, 25.0}}}},
        {"sun",
         {{"type", "directional"}, {"direction", {0, 0, -1}}, {"irradiance", {3.0, 3.0, 3.0}}}}}}};
  Json expected = doc;
  expected["lights"]["lamp"]["intensity"] = {4.0 * 0.5, 2.0 * 0.5, 1.0 * 0.5};
  expected["lights"]["globe"]["radiance"] = {100.0 * 1.25, 50.0 * 1.25, 25.0 * 1.25};
  expected["lights"]["sun"]["irradiance"] = {3.0 * 2.0, 3.0 * 2.0, 3.0 * 2.0};
  for (const auto& [light, factor] :
       std::vector<std::pair<std::string, double>>{{"lamp", 0.5}, {"globe", 1.25}, {"sun", 2.0}}) {
    CandidateResult c;
    c.effect = "light_intensity";
    c.params = {{"light", light}, {"factor", factor}};
    test::WriteCandidate(c, &doc);
  }
  EXPECT_EQ(doc, expected) << doc.dump();
}

}  // namespace
}  // namespace igi::diagnose
