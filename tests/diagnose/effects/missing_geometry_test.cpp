// missing_geometry (solver/diagnose/effects/missing_geometry.cpp): the effect's own rules. The
// locator it runs (solver/diagnose/missing_geometry.h) is tested in
// tests/diagnose/missing_geometry_test.cpp. Its Judge: a step that excludes pixels is kept on the
// masks' own held-out share and the refit outside them, not on the residual it removes. Its
// Write: each photo with the object's pixels gets the mask that excludes them.
#include <gtest/gtest.h>

#include "solver/diagnose/candidates.h"
#include "solver/diagnose/effect.h"
#include "solver/diagnose/effects/effects.h"
#include "tests/diagnose/one_light_record.h"

namespace igi::diagnose {
namespace {

// A located object's candidate whose masks hold `gain` of the held-out residual², above the
// level outside them by `z` standard errors.
CandidateResult Located(double gain, double z) {
  CandidateResult c;
  c.effect = "missing_geometry";
  c.valid = true;
  c.held_before = 1.0;
  c.held_after = 1.0 - gain;
  c.z = z;
  return c;
}

// Kept only when the masks' share reaches min_gain, its z reaches min_z, and the refit does not
// make the held-out residual² outside the masks worse by more than min_gain (outcome.gain >=
// -min_gain); the judgement's gain and z are the candidate's own (what the masks hold), not the
// refit's outcome.
TEST(MissingGeometryEffectTest, JudgeNeedsTheMasksShareAndNoLossOutsideThem) {
  const std::unique_ptr<Effect> e = MakeMissingGeometry();
  DiagnoseOptions o;
  o.min_gain = 0.02;
  o.min_z = 2.5;
  const HeldOutScope scope;
  auto judge = [&](double gain, double z, double outside) {
    return e->Judge(Located(gain, z), HeldOutOutcome{outside, 40.0}, scope, o);
  };
  const Judgement kept = judge(0.3, 6.0, -0.01);
  EXPECT_TRUE(kept.kept) << kept.verdict;
  EXPECT_DOUBLE_EQ(kept.gain, Located(0.3, 6.0).Gain());
  EXPECT_DOUBLE_EQ(kept.z, 6.0);
  EXPECT_EQ(kept.verdict.rfind("kept", 0), 0u) << kept.verdict;
  EXPECT_TRUE(judge(0.02, 2.5, -0.02).kept);  // every bound reached exactly
  EXPECT_FALSE(judge(0.3, 6.0, -0.03).kept);  // the refit worse outside
  EXPECT_FALSE(judge(0.015, 6.0, 0.1).kept);  // the masks hold too little
  EXPECT_FALSE(judge(0.3, 2.0, 0.1).kept);    // not significant
  const Judgement rejected = judge(0.3, 6.0, -0.03);
  EXPECT_EQ(rejected.verdict.rfind("rejected", 0), 0u) << rejected.verdict;
}

// Write sets each listed photo's mask (params "mask_files", {"photo": index, "file": path}): a
// declared mask is replaced (the located mask already excludes what it excluded), a photo not
// listed is left as it was.
TEST(MissingGeometryEffectTest, WriteSetsEachListedPhotosMask) {
  CandidateResult c;
  c.effect = "missing_geometry";
  c.params = {{"objects", 1},
              {"mask_files",
               {{{"photo", 0}, {"file", "/out/masks/cam0_L0_mask.png"}},
                {{"photo", 2}, {"file", "/out/masks/cam2_L0_mask.png"}}}}};
  Json doc = {{"photos",
               {{{"file", "/capture/cam0_L0.exr"}, {"camera", "cam0"}},
                {{"file", "/capture/cam1_L0.exr"}, {"camera", "cam1"}},
                {{"file", "/capture/cam2_L0.exr"},
                 {"camera", "cam2"},
                 {"mask", "/capture/cam2_mask.png"}}}}};
  Json expected = doc;
  expected["photos"][0]["mask"] = "/out/masks/cam0_L0_mask.png";
  expected["photos"][2]["mask"] = "/out/masks/cam2_L0_mask.png";
  test::WriteCandidate(c, &doc);
  EXPECT_EQ(doc, expected) << doc.dump();
}

}  // namespace
}  // namespace igi::diagnose
