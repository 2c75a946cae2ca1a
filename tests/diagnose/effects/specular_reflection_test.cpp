// specular_reflection (solver/diagnose/effects/specular_reflection.cpp) on synthetic records of a
// plate declared Lambertian whose photos hold a Ward lobe: the lobe is found, and one at the
// widest roughness searched is refused. And its Write: the region becomes "ward" with its albedo
// as declared and its lobe left to the refit's solve.
#include <gtest/gtest.h>

#include <string>
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

// specular_reflection: the plate declared Lambertian, its photos with a Ward lobe (ρs 0.08,
// α 0.08). The lobe is found (its grid's α and ρs), and written as a "ward" region whose ρs and α
// the refit solves, the albedo as declared.
TEST(SpecularReflectionTest, TheLobeIsFoundAndLeftToTheSolver) {
  recon::Scene model = PlateScene();
  model.materials[0].brdf = recon::BrdfModel::kLambert;
  model.materials[0].rho_s.reset();
  model.materials[0].alpha.reset();
  std::vector<PixelRecord> records = PlateRecords(false, 3);
  for (PixelRecord& r : records) {
    for (int c = 0; c < 3; ++c)
      r.sim[c] = float(kRhoD[c] / render::kPi * r.lights[0].irradiance[c]);
  }
  const ResidualFitter f(records, std::vector<int>(records.size(), 0), 1, false, 8);
  const Json given = {
      {"materials", {{"plate", {{"brdf", "lambert"}, {"rho_d", {0.1, 0.2, 0.5}}}}}}};
  const CandidateContext cx{model, given, false};
  const CandidateResult c = SpecularReflection(cx, f, 0);
  ASSERT_TRUE(c.valid) << c.note;
  EXPECT_GT(c.Gain(), 0.5);
  // The grid holds the true α; 1 % noise on 6000 records: ρs within 10 %.
  EXPECT_NEAR(c.params["alpha"].get<double>(), 0.08, 1e-9);
  EXPECT_NEAR(c.params["rho_s"].get<double>(), 0.08, 0.008);
  Json doc = given;
  test::WriteCandidate(c, &doc);
  EXPECT_EQ(doc["materials"]["plate"], Json({{"brdf", "ward"}, {"rho_d", {0.1, 0.2, 0.5}}}));
  Json unknown = {{"materials", {{"plate", {{"brdf", "lambert"}}}}}};
  test::WriteCandidate(c, &unknown);
  EXPECT_EQ(unknown["materials"]["plate"], Json({{"brdf", "ward"}}));
}

// A lobe wider than any the candidate searches (true α 0.8 against the grid's widest 0.35) is a
// broad brightening of the region: the widest value fitting best is a bound, not a fit, and the
// candidate refuses it (in the light_emission_profile concealed capture such a "lobe" on wall_y0,
// α 0.35, absorbed what the profile's fitted power left).
TEST(SpecularReflectionTest, ALobeAtTheWidestAlphaSearchedIsRefused) {
  recon::Scene model = PlateScene();
  model.materials[0].brdf = recon::BrdfModel::kLambert;
  model.materials[0].rho_s.reset();
  model.materials[0].alpha.reset();
  std::vector<PixelRecord> records = PlateRecords(false, 4, 0.8);
  for (PixelRecord& r : records) {
    for (int c = 0; c < 3; ++c)
      r.sim[c] = float(kRhoD[c] / render::kPi * r.lights[0].irradiance[c]);
  }
  const ResidualFitter f(records, std::vector<int>(records.size(), 0), 1, false, 8);
  const Json given = {
      {"materials", {{"plate", {{"brdf", "lambert"}, {"rho_d", {0.1, 0.2, 0.5}}}}}}};
  const CandidateResult c = SpecularReflection({model, given, false}, f, 0);
  EXPECT_FALSE(c.valid) << c.evidence;
  EXPECT_NE(c.note.find("widest lobe searched (alpha 0.35"), std::string::npos) << c.note;
}

// Write replaces the region's entry by a fresh "ward" one: a declared albedo map is kept, the
// lobe's ρs and α are left to the refit's solve, and whatever else the entry held (here an index
// the plain lobe has no use for) goes; other regions are left as they were.
TEST(SpecularReflectionTest, WriteKeepsTheAlbedoMapAndLeavesTheLobeToTheSolver) {
  CandidateResult c;
  c.effect = "specular_reflection";
  c.params = {{"region", "plate"}, {"rho_s", 0.06}, {"alpha", 0.12}};
  Json doc = {
      {"materials",
       {{"plate", {{"brdf", "lambert"}, {"rho_d_map", "/capture/plate_albedo.exr"}, {"ior", 1.3}}},
        {"floor", {{"brdf", "lambert"}, {"rho_d", {0.5, 0.5, 0.5}}}}}}};
  Json expected = doc;
  expected["materials"]["plate"] = {{"brdf", "ward"}, {"rho_d_map", "/capture/plate_albedo.exr"}};
  test::WriteCandidate(c, &doc);
  EXPECT_EQ(doc, expected) << doc.dump();
}

}  // namespace
}  // namespace igi::diagnose
