// The driver's side of the effects (solver/diagnose/effect.h): the registry MakeEffects and
// FindEffect, what every effect inherits (the default Judge and PlanTrial, SupportScope),
// EvaluateCandidates, the order a step refits its candidates in (RankForTrials), and the record
// subsample the searches run on (RecordSubset). Each effect's own tests are in
// tests/diagnose/effects/.
#include "solver/diagnose/effect.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <set>
#include <string>
#include <vector>

#include "solver/diagnose/candidates.h"
#include "solver/diagnose/effects/effects.h"
#include "solver/diagnose/residual_fit.h"
#include "tests/diagnose/one_light_record.h"
#include "tests/diagnose/room_records.h"

namespace igi::diagnose {
namespace {

using namespace test::room;

// The effect names of docs/diagnose-effects.md's table, albedo_texture aside.
const std::vector<std::string> kContractEffects = {"indirect_illumination",
                                                   "specular_reflection",
                                                   "specular_lobe_shape",
                                                   "fresnel",
                                                   "anisotropic_reflection",
                                                   "light_emission_profile",
                                                   "light_source_extent",
                                                   "light_intensity",
                                                   "ambient_light",
                                                   "vignetting",
                                                   "camera_response",
                                                   "exposure_scale",
                                                   "pose_error",
                                                   "missing_geometry"};

// The effects igi-diagnose models, one file each under solver/diagnose/effects/.
const std::vector<std::string> kModelled = {"missing_geometry",
                                            "albedo_texture",
                                            "exposure_scale",
                                            "vignetting",
                                            "camera_response",
                                            "ambient_light",
                                            "light_emission_profile",
                                            "light_intensity",
                                            "light_source_extent",
                                            "specular_lobe_shape",
                                            "fresnel",
                                            "anisotropic_reflection",
                                            "pose_error",
                                            "specular_reflection",
                                            "diffuse_shape"};

// MakeEffects makes each modelled effect once, in the driver's order (the effects tried alone
// first: a missing object before any albedo map). Every name is one of the shared table
// (docs/diagnose-effects.md) except the names igi adds (new names are allowed): albedo_texture,
// for the albedo maps its step gives the refit, and diffuse_shape; indirect_illumination is the one name of the table no
// effect models (the renderer's model has the bounces).
TEST(EffectRegistryTest, NamesAreUniqueAndTheContracts) {
  const std::vector<std::unique_ptr<Effect>> effects = MakeEffects();
  std::vector<std::string> names;
  for (const auto& e : effects) names.push_back(e->Name());
  EXPECT_EQ(names, kModelled);
  EXPECT_EQ(std::set<std::string>(names.begin(), names.end()).size(), names.size());
  for (const std::string& name : names) {
    const bool in_contract =
        std::find(kContractEffects.begin(), kContractEffects.end(), name) != kContractEffects.end();
    EXPECT_EQ(in_contract, name != "albedo_texture" && name != "diffuse_shape") << name;
  }
}

// FindEffect returns the effect of each name (the one object of that name among `effects`), and
// null for a name no effect has.
TEST(EffectRegistryTest, FindEffectFindsEachByName) {
  const std::vector<std::unique_ptr<Effect>> effects = MakeEffects();
  for (const auto& e : effects) {
    const Effect* found = FindEffect(effects, e->Name());
    EXPECT_EQ(found, e.get()) << e->Name();
  }
  EXPECT_EQ(FindEffect(effects, "indirect_illumination"), nullptr);
  EXPECT_EQ(FindEffect(effects, "no_such_effect"), nullptr);
  EXPECT_EQ(FindEffect(effects, ""), nullptr);
}

// The default Judge (every effect's but missing_geometry's) keeps a trial whose held-out gain
// reaches min_gain and whose z reaches min_z, both bounds included, and rejects it when either
// falls short. The judgement carries the outcome's gain and z; its verdict says kept or rejected,
// names the blocks the z was counted over when kept, and the parameters not earned when not.
TEST(EffectTest, TheDefaultJudgeKeepsAtMinGainAndMinZ) {
  const std::vector<std::unique_ptr<Effect>> effects = MakeEffects();
  DiagnoseOptions o;
  o.min_gain = 0.02;
  o.min_z = 2.5;
  HeldOutScope scope;
  scope.units = "the 12 held-out blocks where it changes the model";
  CandidateResult c;
  c.num_params = 2;
  for (const auto& e : effects) {
    if (e->Name() == "missing_geometry") continue;  // its own rule (missing_geometry_test.cpp)
    c.effect = e->Name();
    const Judgement at_bounds = e->Judge(c, {0.02, 2.5}, scope, o);
    EXPECT_TRUE(at_bounds.kept) << e->Name();
    EXPECT_DOUBLE_EQ(at_bounds.gain, 0.02);
    EXPECT_DOUBLE_EQ(at_bounds.z, 2.5);
    EXPECT_EQ(at_bounds.verdict.rfind("kept", 0), 0u) << at_bounds.verdict;
    EXPECT_NE(at_bounds.verdict.find(scope.units), std::string::npos) << at_bounds.verdict;
    EXPECT_TRUE(e->Judge(c, {0.3, 12.0}, scope, o).kept) << e->Name();
    const Judgement low_gain = e->Judge(c, {0.019, 12.0}, scope, o);
    EXPECT_FALSE(low_gain.kept) << e->Name();
    EXPECT_EQ(low_gain.verdict.rfind("rejected", 0), 0u) << low_gain.verdict;
    EXPECT_NE(low_gain.verdict.find("2 parameter(s)"), std::string::npos) << low_gain.verdict;
    EXPECT_FALSE(e->Judge(c, {0.3, 2.4}, scope, o).kept) << e->Name();
    EXPECT_FALSE(e->Judge(c, {-0.1, -3.0}, scope, o).kept) << e->Name();
  }
  // An albedo step (one value per texel) does not earn "its albedo per texel".
  c.num_params = -1;
  const Judgement texels = FindEffect(effects, "albedo_texture")->Judge(c, {0.0, 0.0}, scope, o);
  EXPECT_NE(texels.verdict.find("albedo per texel"), std::string::npos) << texels.verdict;
}

// SupportScope: a candidate with fewer than two support blocks is tested over every held-out
// block (no filter); with two or more, over exactly its blocks (photo, block x, block y).
TEST(EffectTest, SupportScopeSelectsExactlyTheSupportBlocks) {
  CandidateResult c;
  EXPECT_FALSE(SupportScope(c).blocks);
  EXPECT_EQ(SupportScope(c).units, "the held-out blocks");
  c.support_blocks = {{0, 1, 2}};
  EXPECT_FALSE(SupportScope(c).blocks);
  c.support_blocks = {{0, 1, 2}, {1, 3, 4}, {0, 1, 3}};
  const HeldOutScope scope = SupportScope(c);
  ASSERT_TRUE(scope.blocks);
  EXPECT_FALSE(scope.pixel_units);
  EXPECT_EQ(scope.units, "the 3 held-out blocks where it changes the model");
  for (size_t photo = 0; photo < 3; ++photo) {
    for (int bx = 0; bx < 6; ++bx) {
      for (int by = 0; by < 6; ++by) {
        const std::array<int, 3> b = {int(photo), bx, by};
        const bool listed = std::find(c.support_blocks.begin(), c.support_blocks.end(), b) !=
                            c.support_blocks.end();
        EXPECT_EQ(scope.blocks(photo, bx, by), listed) << photo << " " << bx << " " << by;
      }
    }
  }
}

// The default PlanTrial refits from the declared document with the candidate written into it
// (Write), the albedo maps and the photos' valid pixels unchanged.
TEST(EffectTest, TheDefaultPlanTrialWritesTheCandidateIntoTheDeclaredDocument) {
  const recon::Scene model = RoomModel();
  const Json declared = {
      {"lights", {{"lamp", {{"type", "point"}, {"intensity", {8.0, 8.0, 8.0}}}}}},
      {"lightings", {{"L0", {"lamp"}}}}};
  const PhotoSet photos;
  const std::vector<Image> sims;
  const std::vector<PixelRecord> records;
  const solver::PixelHoldout holdout;
  const DiagnoseOptions options;
  const MapMode maps{solver::AlbedoMaps::kAuto, {"floor"}};
  const DiagnosisModel m{model,   model,   declared, photos, sims, records,
                         holdout, options, maps,     false,  0.05, {}};
  CandidateResult c;
  c.effect = "light_intensity";
  c.params = {{"light", "lamp"}, {"factor", 0.5}};
  const std::vector<std::unique_ptr<Effect>> effects = MakeEffects();
  const TrialPlan plan = FindEffect(effects, "light_intensity")->PlanTrial(&c, m);
  Json expected = declared;
  expected["lights"]["lamp"]["intensity"] = {4.0, 4.0, 4.0};
  EXPECT_EQ(plan.document, expected) << plan.document.dump();
  EXPECT_EQ(plan.maps.maps, solver::AlbedoMaps::kAuto);
  EXPECT_EQ(plan.maps.only, std::vector<std::string>{"floor"});
  EXPECT_FALSE(plan.photos.has_value());
}

// EvaluateCandidates fits every effect's candidates (AddFits) except those whose key is
// excluded, and returns them in the effects' order; a fit that does not apply to its target (a
// lobe change on a Lambertian region) is left out, one that could not be fitted for a reason
// (vignetting without declared cameras) is kept with its note.
TEST(EvaluateCandidatesTest, FitsTheCandidatesNotExcludedInTheEffectsOrder) {
  const recon::Scene model = RoomModelWithPhotos();
  const Json declared = {{"lights", {{"lamp", {{"type", "point"}}}}}};
  const std::vector<PixelRecord> records = RoomRecords(2.0, 1.0, 3);
  std::vector<std::string> excluded = {"ambient_light",
                                       "light_emission_profile:lamp",
                                       "light_intensity:lamp",
                                       "light_source_extent:lamp",
                                       "specular_reflection:floor",
                                       "specular_reflection:wall",
                                       "diffuse_shape:floor",
                                       "diffuse_shape:wall",
                                       "diffuse_shape"};
  auto keys = [&](const std::vector<std::string>& ex) {
    std::vector<std::string> out;
    for (const CandidateResult& c :
         EvaluateCandidates(MakeEffects(), {model, declared, false}, records, ex)) {
      out.push_back(c.Key());
      if (c.effect == "vignetting") {
        EXPECT_FALSE(c.valid);
        EXPECT_FALSE(c.note.empty());
      }
    }
    return out;
  };
  EXPECT_EQ(keys(excluded),
            (std::vector<std::string>{"exposure_scale", "vignetting", "camera_response"}));
  excluded.push_back("exposure_scale");
  excluded.push_back("camera_response");
  EXPECT_EQ(keys(excluded), (std::vector<std::string>{"vignetting"}));
}

// RecordSubset: one record in `stride` with no pattern, or one region's records.
TEST(RecordSubsetTest, AQuarterOrOneRegion) {
  const recon::Scene model = RoomModel();
  const std::vector<PixelRecord> records = RoomRecords(2.0, 1.0, 3);
  const RecordSubset every(model, records, 0.05, true, 8, 1);
  EXPECT_EQ(every.records().size(), records.size());
  // A quarter, drawn without a pattern: the records alternate floor and wall (every 4th record
  // would be the floor's alone, and the profile's power could not be told from the response).
  const RecordSubset quarter(model, records, 0.05, true, 8, 4);
  EXPECT_NEAR(double(quarter.records().size()), records.size() / 4.0, 0.05 * records.size() / 4);
  int walls_in_quarter = 0;
  for (const PixelRecord& r : quarter.records()) walls_in_quarter += r.region == 1;
  EXPECT_NEAR(walls_in_quarter, quarter.records().size() / 2.0, 0.1 * quarter.records().size());
  const RecordSubset walls(model, records, 0.05, true, 8, 1, 1);  // odd records are the wall's
  EXPECT_EQ(walls.records().size(), records.size() / 2);
  for (const PixelRecord& r : walls.records()) EXPECT_EQ(r.region, 1);
  EXPECT_EQ(SearchStride(records, 1000),
            int(std::count_if(records.begin(), records.end(),
                              [](const PixelRecord& r) { return !r.held_out && !r.outlier; }) /
                1000));
  EXPECT_EQ(SearchStride(records, 1000000), 1);
}

// The order a step refits its candidates in (RankForTrials): the seed-117 baseline's three best
// predictions (two lights' intensities at 74 %, the lamp's profile at 30 %) refit the profile
// second; otherwise best predicted first, and the weak, insignificant or invalid left out.
CandidateResult Predicted(const std::string& effect, double gain, double z,
                          const std::string& light = "") {
  CandidateResult c;
  c.effect = effect;
  c.valid = true;
  c.held_before = 1.0;
  c.held_after = 1.0 - gain;
  c.z = z;
  if (!light.empty()) c.params["light"] = light;
  return c;
}

std::vector<std::string> Order(std::vector<CandidateResult>& cands) {
  std::vector<std::string> out;
  for (const CandidateResult* c : RankForTrials(cands, 0.01, 1.5)) out.push_back(c->Key());
  return out;
}

TEST(RankForTrialsTest, TheBestOfAnotherEffectIsRefittedSecond) {
  std::vector<CandidateResult> cands = {Predicted("ambient_light", 0.12, 3.0),
                                        Predicted("light_intensity", 0.741, 14.0, "lamp"),
                                        Predicted("light_emission_profile", 0.30, 9.0, "lamp"),
                                        Predicted("light_intensity", 0.739, 13.0, "lamp2")};
  EXPECT_EQ(Order(cands),
            (std::vector<std::string>{"light_intensity:lamp", "light_emission_profile:lamp",
                                      "light_intensity:lamp2", "ambient_light"}));
}

TEST(RankForTrialsTest, OtherwiseBestPredictedFirst) {
  std::vector<CandidateResult> cands = {
      Predicted("vignetting", 0.2, 3.0), Predicted("light_intensity", 0.5, 9.0, "lamp"),
      Predicted("light_intensity", 0.1, 2.0, "lamp2"), Predicted("ambient_light", 0.3, 4.0)};
  EXPECT_EQ(Order(cands), (std::vector<std::string>{"light_intensity:lamp", "ambient_light",
                                                    "vignetting", "light_intensity:lamp2"}));
  // All of one effect: nothing to move up.
  std::vector<CandidateResult> same = {Predicted("specular_lobe_shape", 0.2, 3.0),
                                       Predicted("specular_lobe_shape", 0.4, 3.0)};
  same[0].params["region"] = "floor";
  same[1].params["region"] = "glossy_box";
  EXPECT_EQ(Order(same), (std::vector<std::string>{"specular_lobe_shape:glossy_box",
                                                   "specular_lobe_shape:floor"}));
}

TEST(RankForTrialsTest, WeakInsignificantAndInvalidAreLeftOut) {
  std::vector<CandidateResult> cands = {
      Predicted("vignetting", 0.005, 3.0), Predicted("ambient_light", 0.3, 1.0),
      Predicted("camera_response", 0.2, 2.0), Predicted("exposure_scale", 0.4, 5.0)};
  cands[3].valid = false;
  EXPECT_EQ(Order(cands), (std::vector<std::string>{"camera_response"}));
}

// A fit that explains more than the residual holds (predicted gain above 100 %: the camera
// response fitted with an exponent of −0.18 on a capture with a true 0.8) is a fit failure:
// not tried, and said so.
TEST(RankForTrialsTest, AFitThatExplainsMoreThanTheResidualIsAFailure) {
  std::vector<CandidateResult> cands = {Predicted("camera_response", 1.01, 40.0),
                                        Predicted("vignetting", 0.2, 3.0)};
  EXPECT_EQ(Order(cands), (std::vector<std::string>{"vignetting"}));
  EXPECT_FALSE(cands[0].valid);
  EXPECT_NE(cands[0].note.find("fit failure"), std::string::npos) << cands[0].note;
}

}  // namespace
}  // namespace igi::diagnose
