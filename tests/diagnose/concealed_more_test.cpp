// igi-diagnose on concealed data (issue 8): the effects of the suite not proven elsewhere —
// fresnel, ambient_light, light_intensity, specular_reflection — and two captures hiding a PAIR
// of effects. Same fixture and size as diagnose_concealed_test (4 cameras of 160×120, photos at
// 64 paths per pixel, a point lamp, materials given, seed 11).
#include <gtest/gtest.h>

#include <string>

#include "tests/diagnose/concealed_fixture.h"

namespace igi {
namespace {

using test::ConcealedOutcome;
using test::DiagnoseConcealed;
using test::ExpectReachesTheFloor;

void Print(const ConcealedOutcome& o) {
  const Json& d = o.diagnosis;
  std::string steps;
  for (const Json& s : d["steps"]) steps += s.dump() + "\n";
  std::printf("baseline %.4f final %.4f floor %.4f ratio %.3f\n%s",
              d["baseline"]["residual"].get<double>(), d["final"]["residual"].get<double>(),
              o.floor, d["final"]["residual"].get<double>() / o.floor, steps.c_str());
}

class ConcealedMoreTest : public testing::TestWithParam<const char*> {};

TEST_P(ConcealedMoreTest, FirstStepNamesIt) {
  const std::string effect = GetParam();
  const ConcealedOutcome o = DiagnoseConcealed(effect, 11);
  const Json& d = o.diagnosis;
  Print(o);
  ASSERT_FALSE(d["steps"].empty()) << d.dump(1);
  EXPECT_EQ(d["steps"][0]["effect"], effect.substr(0, effect.find('+'))) << d.dump(1);
  ExpectReachesTheFloor(o);
}

INSTANTIATE_TEST_SUITE_P(Effects, ConcealedMoreTest,
                         testing::Values("fresnel", "ambient_light", "light_intensity",
                                         "specular_reflection",
                                         "vignetting+exposure_scale",
                                         "light_emission_profile+camera_response"));

}  // namespace
}  // namespace igi
