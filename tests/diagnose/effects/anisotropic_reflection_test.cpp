// anisotropic_reflection (solver/diagnose/effects/anisotropic_reflection.cpp) on synthetic records
// of a Ward plate with known truth: a stretched lobe's tangent and roughnesses are recovered; a
// lobe that is merely wider, or stretched beyond the widest roughness searched, is refused; the
// model's Fresnel suffix is kept. And its Write: the region's model becomes its *_aniso form.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "solver/diagnose/candidates.h"
#include "solver/diagnose/effects/effects.h"
#include "solver/diagnose/residual_fit.h"
#include "solver/render/sampling.h"
#include "tests/diagnose/one_light_record.h"
#include "tests/diagnose/ward_plate.h"

namespace igi::diagnose {
namespace {

using namespace test::ward_plate;

TEST(AnisotropicReflectionTest, RecoversTheTangentAndRoughnesses) {
  const recon::Scene model = PlateScene();
  const Json declared = PlateDocument();
  const std::vector<PixelRecord> records = PlateRecords(true, 1);
  const ResidualFitter f(records, std::vector<int>(records.size(), 0), 1, false, 8);
  const CandidateContext cx{model, declared, false};
  const CandidateResult c = AnisotropicReflection(cx, f, 0);
  ASSERT_TRUE(c.valid) << c.note;
  EXPECT_EQ(c.effect, "anisotropic_reflection");
  EXPECT_GT(c.Gain(), 0.5);
  EXPECT_GT(c.z, 5);
  const std::vector<double> t = c.params["tangent"].get<std::vector<double>>();
  double ax = c.params["alpha_x"], ay = c.params["alpha_y"];
  // The narrow direction's angle in the plate's plane, modulo 180°.
  double angle = std::atan2(t[1], t[0]) * 180 / render::kPi;
  if (ax > ay) std::swap(ax, ay), angle += 90;
  angle = std::fmod(angle + 360, 180);
  // 6000 records at 1 % noise pin the lobe well; the grid refinement stops at 1.25° and at
  // factors of 1.2^0.12: allow 4° and 15 %.
  EXPECT_NEAR(angle, 25, 4);
  EXPECT_NEAR(ax, 0.03, 0.15 * 0.03);
  EXPECT_NEAR(ay, 0.15, 0.15 * 0.15);
  EXPECT_NEAR(c.params["rho_s_factor"].get<double>(), 1.0, 0.1);
  Json doc = declared;
  test::WriteCandidate(c, &doc);
  const Json& m = doc["materials"]["plate"];
  EXPECT_EQ(m["brdf"], "ward_aniso");
  EXPECT_FALSE(m.contains("alpha"));
  EXPECT_TRUE(m.contains("alpha_x") && m.contains("alpha_y") && m.contains("tangent"));
}

// The same for anisotropic_reflection: a lobe stretched to α 0.8 across its tangent (the grid
// goes to 0.3) is refused, where 0.03 / 0.15 is found (RecoversTheTangentAndRoughnesses).
TEST(AnisotropicReflectionTest, ALobeReachingTheWidestAlphaIsRefused) {
  const recon::Scene model = PlateScene();
  const Json declared = PlateDocument();
  const std::vector<PixelRecord> records = PlateRecords(true, 5, 0.03, 0.8);
  const ResidualFitter f(records, std::vector<int>(records.size(), 0), 1, false, 8);
  const CandidateResult c = AnisotropicReflection({model, declared, false}, f, 0);
  EXPECT_FALSE(c.valid) << c.evidence;
  EXPECT_NE(c.note.find("widest roughness searched"), std::string::npos) << c.note;
}

TEST(AnisotropicReflectionTest, AWiderIsotropicLobeIsNotNamedAnisotropic) {
  const recon::Scene model = PlateScene();
  const Json declared = PlateDocument();
  const std::vector<PixelRecord> records = PlateRecords(false, 2);
  const ResidualFitter f(records, std::vector<int>(records.size(), 0), 1, false, 8);
  const CandidateContext cx{model, declared, false};
  const CandidateResult c = AnisotropicReflection(cx, f, 0);
  EXPECT_FALSE(c.valid) << c.evidence;
  EXPECT_NE(c.note.find("isotropic"), std::string::npos) << c.note;
}

TEST(AnisotropicReflectionTest, KeepsTheFresnelSuffix) {
  recon::Scene model = PlateScene();
  model.materials[0].brdf = recon::BrdfModel::kWardGmdFresnel;
  Json declared = PlateDocument();
  declared["materials"]["plate"]["brdf"] = "ward_gmd_fresnel";
  // Records of the plain ward model still differ from this model's lobe by a stretch; what
  // matters here is the name written.
  const std::vector<PixelRecord> records = PlateRecords(true, 3);
  const ResidualFitter f(records, std::vector<int>(records.size(), 0), 1, false, 8);
  const CandidateResult c = AnisotropicReflection({model, declared, false}, f, 0);
  ASSERT_TRUE(c.valid) << c.note;
  EXPECT_EQ(c.params["to"], "ward_gmd_aniso_fresnel");
}

// The candidate's params as AnisotropicReflection makes them, for region "plate".
CandidateResult AnisotropicCandidate(const std::string& to, double rho_s_factor) {
  CandidateResult c;
  c.effect = "anisotropic_reflection";
  c.params = {{"region", "plate"},           {"from", "ward"},  {"to", to},
              {"tangent", {0.6, 0.8, 0.0}},  {"alpha_x", 0.03}, {"alpha_y", 0.15},
              {"rho_s_factor", rho_s_factor}};
  return c;
}

// Write, where the declared region has α and ρs (materials given): the model becomes the params'
// *_aniso one with their tangent, α gives way to the fitted α_x and α_y, and ρs is scaled by the
// fitted factor; ρd and the other regions are left as they were.
TEST(AnisotropicReflectionTest, WriteReplacesAlphaAndScalesRhoSWhereDeclared) {
  const double k = 0.5;
  Json doc = {
      {"materials",
       {{"plate", {{"brdf", "ward"}, {"rho_d", {0.1, 0.2, 0.5}}, {"rho_s", 0.08}, {"alpha", 0.05}}},
        {"floor", {{"brdf", "lambert"}, {"rho_d", {0.5, 0.5, 0.5}}}}}}};
  Json expected = doc;
  expected["materials"]["plate"] = {{"brdf", "ward_aniso"}, {"rho_d", {0.1, 0.2, 0.5}},
                                    {"rho_s", 0.08 * k},    {"tangent", {0.6, 0.8, 0.0}},
                                    {"alpha_x", 0.03},      {"alpha_y", 0.15}};
  test::WriteCandidate(AnisotropicCandidate("ward_aniso", k), &doc);
  EXPECT_EQ(doc, expected) << doc.dump();
}

// Write, where the declared region has no α (igi-solve fits the roughnesses, given the tangent):
// no α_x or α_y is written; an RGB ρs is scaled channel by channel, and the index of a Fresnel
// model stays.
TEST(AnisotropicReflectionTest, WriteLeavesUnknownRoughnessesToTheSolver) {
  const double k = 1.25;
  Json doc = {
      {"materials",
       {{"plate", {{"brdf", "ward_fresnel"}, {"rho_s", {0.04, 0.08, 0.16}}, {"ior", 1.4}}}}}};
  Json expected = doc;
  expected["materials"]["plate"] = {{"brdf", "ward_aniso_fresnel"},
                                    {"rho_s", {0.04 * k, 0.08 * k, 0.16 * k}},
                                    {"ior", 1.4},
                                    {"tangent", {0.6, 0.8, 0.0}}};
  test::WriteCandidate(AnisotropicCandidate("ward_aniso_fresnel", k), &doc);
  EXPECT_EQ(doc, expected) << doc.dump();
}

}  // namespace
}  // namespace igi::diagnose
