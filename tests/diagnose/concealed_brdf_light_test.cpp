// igi-diagnose on concealed data for the effects that change the shape of reflected or emitted
// light: an igi-synth capture hiding anisotropic_reflection (glossy_box's lobe
// stretched along a surface direction), light_source_extent (the declared point lamp is a 0.25 m
// sphere of the same intensity) or light_emission_profile (the lamp is a cos² spot pointing down,
// of the same peak intensity). The first step igi-diagnose keeps names the hidden effect, with the
// hidden parameters recovered roughly, and the final residual comes within 1.2× of the true
// model's (truth/scene.json with the capture's photos, rendered the same way).
//
// Size as diagnose_concealed_test: 4 cameras of 160×120 (the first ones aimed at the glossy
// regions' highlights), photos at 64 paths per pixel, a point lamp, materials given.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "tests/diagnose/concealed_fixture.h"

namespace igi::diagnose {
namespace {

using test::ConcealedOutcome;
using test::DiagnoseConcealed;
using test::ExpectReachesTheFloor;

// The candidate finds glossy_box's stretch (seed 11: tangent (0.911, 0.413, 0) against the true
// (0.906, 0.423, 0), alpha 0.029 / 0.147 against 0.03 / 0.15) and its refit lowers the held-out
// residual² by 75.2 %, nearly all of it in the 4 held-out blocks of cam0 that show the highlight
// (each 90–99 % down). Measured with a gate over every held-out block: the step gate's mean
// relative gain per block puts that at 2.2 standard errors (changing a lobe's sampling changes the
// path tracer's random paths in every block whose paths meet the box, and those blocks score
// noise), the error-weighted gain at 6.3, the gate's combination (BlockGainZ) at 6.2: kept, the
// only step; final residual 0.1484 against the true model's 0.1481 (1.00×). The gate of a
// region's material change counts only the held-out blocks that see the region: 45.2 standard
// errors (same gain and residual).
TEST(ConcealedBrdfLightTest, AnisotropicReflection) {
  const ConcealedOutcome o = DiagnoseConcealed("anisotropic_reflection", 11);
  const Json& d = o.diagnosis;
  ASSERT_FALSE(d["steps"].empty()) << d.dump(1);
  const Json& step = d["steps"][0];
  EXPECT_EQ(step["effect"], "anisotropic_reflection") << d.dump(1);
  // The narrow direction (alpha_x = 0.03 along glossy_box's 25° yaw, alpha_y = 0.15 across):
  // within 10° and a factor 1.5 (the highlights of 4 small photos constrain the lobe loosely).
  const Json& p = step["params"];
  const std::vector<double> t = p["tangent"].get<std::vector<double>>();
  double ax = p["alpha_x"], ay = p["alpha_y"];
  double angle = std::atan2(t[1], t[0]) * 180 / std::numbers::pi;
  if (ax > ay) std::swap(ax, ay), angle += 90;
  angle = std::fmod(angle + 360, 180);
  EXPECT_NEAR(angle, 25, 10) << p.dump();
  EXPECT_LT(std::abs(std::log(ax / 0.03)), std::log(1.5)) << p.dump();
  EXPECT_LT(std::abs(std::log(ay / 0.15)), std::log(1.5)) << p.dump();
  ExpectReachesTheFloor(o);
}

TEST(ConcealedBrdfLightTest, LightSourceExtent) {
  const ConcealedOutcome o = DiagnoseConcealed("light_source_extent", 11);
  const Json& d = o.diagnosis;
  ASSERT_FALSE(d["steps"].empty()) << d.dump(1);
  const Json& step = d["steps"][0];
  EXPECT_EQ(step["effect"], "light_source_extent") << d.dump(1);
  EXPECT_EQ(step["params"]["light"], "lamp");
  EXPECT_NEAR(step["params"]["radius"].get<double>(), 0.25, 0.06) << step["params"].dump();
  ExpectReachesTheFloor(o);
}

// The lamp is a spot, I·cos²(angle from −z): the room is 4× darker than the model, its ceiling lit
// only by bounces. The candidate fits the lamp's whole direct term (diffuse and specular) as
// cos^n with a free scale per region for what the light sends after a bounce (and, in the search
// of the axis and n only, a camera response as a nuisance); seed 11 measured: axis 1.1° from −z,
// cos power 1.92, held-out residual² down 99.9 %, then a small vignetting step (k1 −0.07,
// k2 0.05: what the power's error leaves), which this test allows; final residual 0.0502 against
// the true model's 0.0482 (1.04×).
TEST(ConcealedBrdfLightTest, LightEmissionProfile) {
  const ConcealedOutcome o = DiagnoseConcealed("light_emission_profile", 11);
  const Json& d = o.diagnosis;
  ASSERT_FALSE(d["steps"].empty()) << d.dump(1);
  const Json& step = d["steps"][0];
  EXPECT_EQ(step["effect"], "light_emission_profile") << d.dump(1);
  // The axis within 5° of −z and the power within 20 % of 2 (measured 1.1°, 1.92: the power
  // trades against the bounce light's free scales).
  const std::vector<double> axis = step["params"]["direction"].get<std::vector<double>>();
  EXPECT_GT(-axis[2], std::cos(5 * std::numbers::pi / 180)) << step["params"].dump();
  EXPECT_NEAR(step["params"]["cos_power"].get<double>(), 2.0, 0.4) << step["params"].dump();
  ExpectReachesTheFloor(o);
}

}  // namespace
}  // namespace igi::diagnose
