// igi-diagnose on concealed data with the materials unknown: scene.json leaves ρd, ρs
// and α out and igi-diagnose solves them at every step (igi-synth's default unknowns). Same size
// as diagnose_concealed_more_test otherwise (4 cameras of 160×120, 64-spp photos, seed 11);
// 3–6 min per case on 2 cores, so labelled slow (IGI_SLOW=1 runs them). The same effects with the
// materials given run in CI (concealed_more_test.cpp, concealed_test.cpp).
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "tests/diagnose/concealed_fixture.h"

namespace igi::diagnose {
namespace {

using test::ConcealedOutcome;
using test::DiagnoseConcealed;
using test::ExpectReachesTheFloor;

// The first kept step that is not albedo_texture (igi-synth's floor is textured: its maps may
// come first), or null.
const Json* FirstPhysicalStep(const Json& diagnosis) {
  for (const Json& s : diagnosis["steps"]) {
    if (s["effect"] != "albedo_texture") return &s;
  }
  return nullptr;
}

// ambient_light with the materials unknown (solved at every step), both lightings photographed
// (under one lighting an ambient term's shape on a surface is an albedo texture). The candidate's
// basis is then the ambient light's first reflection: the solved albedos already carry its share
// of the interreflections. Its whole response (bounces too) had fitted about a third of the
// radiance on the full-size suite's capture (0.11–0.13 for 0.4), and a false exposure_scale
// followed (bench/RESULTS.md, "The suite, materials unknown"). With the whole response as the
// basis it fails (camera_response is kept first); it passes in about 4 minutes on 2 cores.
TEST(ConcealedUnknownMaterialsTest, AmbientLightIsNamedFirstAtItsRadiance) {
  const ConcealedOutcome o = DiagnoseConcealed("ambient_light:kind=uniform", 11, nullptr,
                                               " --photo-lightings L0,L1", false);
  const Json& d = o.diagnosis;
  ASSERT_FALSE(d["steps"].empty()) << d.dump(1);
  // igi-synth's floor is textured: its maps come first here (the texture test's coarser cells),
  // and the hidden effect is the first step after them.
  size_t k = 0;
  while (k + 1 < d["steps"].size() && d["steps"][k]["effect"] == "albedo_texture") ++k;
  const Json& first = d["steps"][k];
  EXPECT_EQ(first["effect"], "ambient_light") << d.dump(1);
  if (first["effect"] == "ambient_light") {
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(first["params"]["radiance"][c].get<double>(), 0.4, 0.1) << c;  // truth 0.4
    }
  }
  ExpectReachesTheFloor(o);
}

// light_emission_profile with the materials unknown (solved at every step), both lightings
// photographed: the albedos are shared by the lamp's photos and lamp2's, so the baseline's are a
// compromise between them, and the lamp's photos (its bounced light too) are darker as a whole.
// The profile's axis and power are searched on the lamp's photos alone (their own albedo
// nuisance), per-photo exposure scales are credited only beyond a scale per lighting, and a kept
// profile is refitted once. Before, the full-size suite's capture applied 11 photo
// scales first (1.85× the floor) and the profile's search on every record gave cos^14 about an
// axis pointing up.
// Measured (seed 11, 4.6 min on 2 cores): the profile first (axis 2.2° off, cos^1.40,
// held-out residual² −89 %); the texture test, missed at the baseline under the profile's error,
// run again on that model: the floor alone textured, its maps kept (−23 %); the profile's refit
// (2.2° off, cos^1.81, −24 %); final 0.1305 against the true model's 0.1322: 0.99× (held out
// 1.04×). Before the texture test was repeated the maps came only as the last
// resort, for every region whose albedo varies, were rejected, and the run ended at 1.215×.
TEST(ConcealedUnknownMaterialsTest, EmissionProfileIsNamedFirstUnderTwoLightings) {
  const ConcealedOutcome o =
      DiagnoseConcealed("light_emission_profile", 11, nullptr, " --photo-lightings L0,L1", false);
  const Json& d = o.diagnosis;
  ASSERT_FALSE(d["steps"].empty()) << d.dump(1);
  const Json& first = d["steps"][0];
  EXPECT_EQ(first["effect"], "light_emission_profile") << d.dump(1);
  const Json* last_profile = nullptr;
  for (const Json& s : d["steps"]) {
    if (s["effect"] == "light_emission_profile") last_profile = &s;
  }
  ASSERT_NE(last_profile, nullptr) << d.dump(1);
  const std::vector<double> axis = (*last_profile)["params"]["direction"];
  EXPECT_GT(-axis[2], std::cos(6 * 3.14159265358979 / 180)) << last_profile->dump(1);  // −z
  EXPECT_NEAR((*last_profile)["params"]["cos_power"].get<double>(), 2.0, 0.3)
      << last_profile->dump(1);
  const double final_residual = d["final"]["residual"];
  EXPECT_LE(final_residual, 1.2 * o.floor) << "floor " << o.floor;
  EXPECT_LT(final_residual, 0.4 * d["baseline"]["residual"].get<double>());
  bool floor_map = false;
  for (const Json& s : d["steps"]) {
    if (s["effect"] == "albedo_texture" && s["params"].contains("regions")) {
      for (const Json& r : s["params"]["regions"]) floor_map = floor_map || r == "floor";
    }
  }
  EXPECT_TRUE(floor_map) << d.dump(1);  // the textured floor's maps, once the profile is in
}

// specular_lobe_shape with the materials unknown (ρs and α solved at every step): at the default
// views a Ward lobe refitted in ρs and α stands in for the true Ward-GMD lobe (the full-size
// suite's capture named nothing and ended at 1.07× the floor held out). On a capture
// that sees the floor at grazing incidence (the lamp 0.6 m high, one camera on the mirror view of
// its highlight at 60-80°, as for fresnel) the lobes differ where the photos look. Every glossy
// region is truly Ward-GMD. The first step after the real textures (albedo maps, which the
// texture test may name first) must name it.
// Measured (seed 11, 2.7 min on 2 cores): specular_lobe_shape on glossy_sphere first
// (held-out residual² −56.7 %, 68.6 standard errors; fresnel on the sphere passed too, −55.3 %,
// and was not applied), the albedo maps, specular_lobe_shape on the floor (−20.5 %, 3.4); final
// 0.0611 against the true model's 0.0571 (1.07×; held out 1.23×). Re-measured with
// the texture test repeated after each kept step (6.4 min for the three slow cases):
// albedo_texture, specular_lobe_shape, fresnel, specular_lobe_shape; final 0.0639 against 0.0571
// (1.12×).
// Rough diffuse surfaces in photos of regions declared Lambertian, every value unknown: every
// region without a lobe is truly an Oren–Nayar surface of σ 0.4; diffuse_shape is the first step
// and the refit's solve recovers σ. Measured (seed 11, 3.7 min): the regions without a lobe
// together (candidate σ 0.51), held-out residual² down 4.3 %; solved σ matte box 0.434, walls
// 0.353–0.396. The ceiling, which no photo sees, is not checked (its solved σ is 0.29).
TEST(ConcealedUnknownMaterialsTest, OrenNayarSurfacesDeclaredLambertianAreNamed) {
  const ConcealedOutcome o = DiagnoseConcealed("diffuse_shape", 11, nullptr, "", false);
  const Json& d = o.diagnosis;
  ASSERT_FALSE(d["steps"].empty()) << d.dump(1);
  const Json& step = d["steps"][0];
  EXPECT_EQ(step["effect"], "diffuse_shape") << d.dump(1);
  EXPECT_EQ(step["params"]["to"], "oren_nayar") << step.dump(1);
  ASSERT_TRUE(step["params"].contains("sigma_solved")) << step.dump(1);
  for (const auto& [region, sigma] : step["params"]["sigma_solved"].items()) {
    if (region != "ceiling") {
      EXPECT_NEAR(sigma.get<double>(), 0.4, 0.06) << region;
    }
  }
  test::ExpectReachesTheFloor(o);
}

// Coated paints in photos of regions declared Lambertian, every value unknown: every region
// without a lobe is truly a Lambertian base under a clear coat (ρd/π·T(cosθi)·T(cosθo)); the
// first physical step is diffuse_shape with the coat, not Oren–Nayar's surface.
TEST(ConcealedUnknownMaterialsTest, CoatedSurfacesDeclaredLambertianAreNamed) {
  const ConcealedOutcome o = DiagnoseConcealed("diffuse_shape:to=coated", 11, nullptr, "", false);
  const Json& d = o.diagnosis;
  const Json* first = FirstPhysicalStep(d);
  ASSERT_NE(first, nullptr) << d.dump(1);
  EXPECT_EQ((*first)["effect"], "diffuse_shape") << d.dump(1);
  EXPECT_EQ((*first)["params"]["to"], "coated") << d.dump(1);
  ExpectReachesTheFloor(o);
}

TEST(ConcealedUnknownMaterialsTest, SpecularLobeShapeIsNamedOnAGrazingView) {
  const ConcealedOutcome o = DiagnoseConcealed(
      "specular_lobe_shape", 11, nullptr, " --lamp-position 2,2,0.6 --grazing-cameras 1", false);
  const Json& d = o.diagnosis;
  const Json* first = FirstPhysicalStep(d);
  ASSERT_NE(first, nullptr) << d.dump(1);
  EXPECT_EQ((*first)["effect"], "specular_lobe_shape") << d.dump(1);
  EXPECT_EQ((*first)["params"]["to"], "ward_gmd") << d.dump(1);
  ExpectReachesTheFloor(o);
}

}  // namespace
}  // namespace igi::diagnose
