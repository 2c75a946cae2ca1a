// igi-diagnose on concealed data: the effects of the suite not proven elsewhere —
// light_intensity, specular_reflection, ambient_light — and captures hiding a PAIR of effects.
// Same fixture and size as diagnose_concealed_test (4 cameras of 160×120, photos at 64 paths per
// pixel, a point lamp, materials given, seed 11). For each: the first step igi-diagnose keeps names
// the hidden effect (for a pair, one of the two, and both are kept), and the final residual comes
// within 1.2× of the true model's (ExpectReachesTheFloor).
//
// Measured (load average 5–6, 2–4 min per case):
// - light_intensity (the lamp 1.25× brighter): light_intensity first, factor 1.241; final
//   residual 0.1444 against the true model's 0.1446 (1.00×; baseline 0.2410). The lamp is the
//   only light of every photo, so with the materials given a common scale of all photos IS its
//   intensity: exposure_scale is fitted relative to the median photo (before, it took the common
//   scale with 4 parameters and was kept first).
// - specular_reflection (wall_y4 declared lambert; truly ward ρs 0.05, α 0.07): specular_reflection
//   first, its ρs and α solved by the refit; final 0.1451 against the true model's 0.1451 (1.00×;
//   baseline 0.1884). With the candidate's own ρs 0.053 and grid α 0.12 written instead: 1.07×.
// - vignetting + exposure_scale: exposure_scale first (cam1 1.148× the median photo; truth
//   1.3, the rest absorbed by the vignetting's different mean in each photo), then vignetting
//   (k1 0.113, k2 −0.419; truth −0.25, −0.05), which had passed the first round too but explained
//   less; final 0.1516 against 0.1436 (1.06×; baseline 0.1858).
// - ambient_light:kind=uniform (scene.json's ambient light, radiance 0.4, in every lighting;
//   measured): ambient_light first and alone, radiance 0.394 (each
//   channel), final residual 0.1260 against the true model's 0.1260 (1.00×; baseline 0.2461).
//   It passes since the renderer evaluates the ambient light exactly (before, its uniform-sphere
//   samples made the true model noisier than the declared one at radiance 0.1) and the candidate
//   fits the rendered response to a unit ambient light (bounces included).
// - light_emission_profile + camera_response: light_emission_profile first (axis
//   1.3° from −z, cos power 1.81; truth −z, 2), then camera_response (exponent 0.817; 0.8),
//   light_intensity (1.047) and exposure_scale; final 0.0554 against 0.0510 (1.09×; baseline
//   2.2915). The profile is searched with the response as a nuisance (before: axis 11° off,
//   power 2.38, the response then not provable, 3.2× the floor).
// Not proven here (bench/RESULTS.md): ambient_light as a stray-light panel (igi-synth's
// ambient_light:kind=panel: an area light, not scene.json's ambient light). fresnel is proven
// in concealed_test.cpp, on a capture with a grazing view (at the default views it is invisible:
// the true model's residual is 0.991× the declared one's).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "tests/diagnose/concealed_fixture.h"

namespace igi::diagnose {
namespace {

using test::ConcealedOutcome;
using test::DiagnoseConcealed;
using test::ExpectReachesTheFloor;

// "a:k=v+b" -> {"a", "b"}.
std::vector<std::string> EffectNames(const std::string& spec) {
  std::vector<std::string> out;
  for (size_t begin = 0; begin < spec.size();) {
    const size_t end = std::min(spec.find('+', begin), spec.size());
    const std::string one = spec.substr(begin, end - begin);
    out.push_back(one.substr(0, one.find(':')));
    begin = end + 1;
  }
  return out;
}

class ConcealedMoreTest : public testing::TestWithParam<const char*> {};

TEST_P(ConcealedMoreTest, FirstStepNamesItAndTheResidualReachesTheFloor) {
  const std::vector<std::string> hidden = EffectNames(GetParam());
  const ConcealedOutcome o = DiagnoseConcealed(GetParam(), 11);
  const Json& d = o.diagnosis;
  ASSERT_FALSE(d["steps"].empty()) << d.dump(1);
  std::vector<std::string> kept;
  for (const Json& s : d["steps"]) kept.push_back(s["effect"]);
  EXPECT_NE(std::find(hidden.begin(), hidden.end(), kept[0]), hidden.end()) << d.dump(1);
  for (const std::string& h : hidden) {
    EXPECT_NE(std::find(kept.begin(), kept.end(), h), kept.end()) << h << " not kept";
  }
  ExpectReachesTheFloor(o);
}

INSTANTIATE_TEST_SUITE_P(Effects, ConcealedMoreTest, testing::Values("ambient_light:kind=uniform"));
// Labelled slow: CI names a light's intensity and a floor's hidden lobe (its ρs and α solved by
// the refit) in another renderer's photos (concealed_cycles_test.cpp).
INSTANTIATE_TEST_SUITE_P(SlowEffects, ConcealedMoreTest,
                         testing::Values("light_intensity", "specular_reflection"));

INSTANTIATE_TEST_SUITE_P(Pairs, ConcealedMoreTest, testing::Values("vignetting+exposure_scale"));
// Labelled slow: CI names each of the two in another renderer's photos (the profile in
// concealed_cycles_test.cpp, the response in concealed_outside_test.cpp), and two effects at once
// in the pair above.
INSTANTIATE_TEST_SUITE_P(SlowPairs, ConcealedMoreTest,
                         testing::Values("light_emission_profile+camera_response"));

}  // namespace
}  // namespace igi::diagnose
