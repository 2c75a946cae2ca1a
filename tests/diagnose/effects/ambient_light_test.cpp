// ambient_light (solver/diagnose/effects/ambient_light.cpp) on floor records the renderer
// path-traces: with the materials solved, the first reflection of an ambient light gives its
// radiance back. And its Write: a new ambient light in every lighting.
#include <gtest/gtest.h>

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

// With the materials solved (the albedo nuisance on), an ambient light's basis is its first
// reflection at the point: the solved albedos already carry its share of the interreflections.
// Photos that hold the model plus ρd·L (a lambert floor's first reflection of an ambient light L)
// in the lamp's light and in the blocker's shadow give L back, whatever albedo scale the
// nuisance takes.
TEST(AmbientLightTest, WithSolvedMaterialsTheFirstReflectionGivesTheRadianceBack) {
  recon::Scene model = ShadowScene(0);
  recon::Camera camera;
  camera.name = "cam";
  camera.width = camera.height = 120;
  camera.params = {100, 100, 60, 60};
  model.cameras = {camera};
  model.photos[0].camera = 0;
  const Json declared =
      Json{{"lights", {{"lamp", {{"type", "point"}}}}}, {"lightings", {{"L0", {"lamp"}}}}};
  std::vector<PixelRecord> records = ShadowRecords(model, 0);
  const Vector3f ambient(0.3f, 0.2f, 0.1f);
  int shadowed = 0;
  for (PixelRecord& r : records) {
    r.recorded += r.albedo.cwiseProduct(ambient);
    shadowed += r.sim.maxCoeff() == 0.0f;
  }
  ASSERT_GT(shadowed, 50);
  const ResidualFitter f(records, std::vector<int>(records.size(), 0), 1, true, 8);
  const CandidateResult c = AmbientLight({model, declared, true}, f);
  ASSERT_TRUE(c.valid) << c.note;
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(c.params["radiance"][k].get<double>(), ambient[k], 0.03 * ambient[k]) << k;
  }
  EXPECT_NE(c.evidence.find("first reflection"), std::string::npos) << c.evidence;
  Json doc = declared;
  test::WriteCandidate(c, &doc);
  EXPECT_EQ(doc["lights"]["ambient"]["type"], "ambient");
  EXPECT_EQ(doc["lightings"]["L0"].size(), 2u);
}

// Write adds an ambient light of the fitted radiance and puts it in every lighting. Its name is
// "ambient", or, when a light has that name already, the first of "ambient_", "ambient__", ...
// that none has: the declared lights are never overwritten.
TEST(AmbientLightTest, WriteAddsALightToEveryLightingUnderAFreshName) {
  CandidateResult c;
  c.effect = "ambient_light";
  c.params = {{"radiance", {0.3, 0.2, 0.1}}};
  const Json lamp = {{"type", "point"}, {"position", {0, 0, 2}}, {"intensity", {5, 5, 5}}};
  Json doc = {{"lights", {{"lamp", lamp}}},
              {"lightings", {{"L0", {"lamp"}}, {"L1", Json::array()}}}};
  Json expected = doc;
  expected["lights"]["ambient"] = {{"type", "ambient"}, {"radiance", {0.3, 0.2, 0.1}}};
  expected["lightings"]["L0"] = Json::array({"lamp", "ambient"});
  expected["lightings"]["L1"] = Json::array({"ambient"});
  test::WriteCandidate(c, &doc);
  EXPECT_EQ(doc, expected) << doc.dump();

  // A declared "ambient" (another ambient light, here a daylight the capture describes) stays.
  const Json daylight = {{"type", "ambient"}, {"radiance", {1.0, 1.0, 1.0}}};
  Json taken = {{"lights", {{"lamp", lamp}, {"ambient", daylight}}},
                {"lightings", {{"L0", {"lamp", "ambient"}}}}};
  Json expected_taken = taken;
  expected_taken["lights"]["ambient_"] = {{"type", "ambient"}, {"radiance", {0.3, 0.2, 0.1}}};
  expected_taken["lightings"]["L0"] = Json::array({"lamp", "ambient", "ambient_"});
  test::WriteCandidate(c, &taken);
  EXPECT_EQ(taken, expected_taken) << taken.dump();
}

}  // namespace
}  // namespace igi::diagnose
