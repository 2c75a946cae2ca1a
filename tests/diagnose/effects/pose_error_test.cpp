// pose_error (solver/diagnose/effects/pose_error.cpp): its Write. A candidate whose pose was
// iterated on re-renders (PlanTrial) carries the pose found, qvec and tvec, which Write sets; a
// candidate of one fitted step carries the step, rotation_vector and translation_m, which Write
// composes with the camera's declared pose (ComposePoseStep). The fit itself is tested on
// rendered captures (tests/diagnose/concealed_geometry_test.cpp).
#include "solver/diagnose/effects/pose_error.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "solver/diagnose/candidates.h"
#include "solver/render/sampling.h"
#include "tests/diagnose/one_light_record.h"

namespace igi::diagnose {
namespace {

// Two cameras of a scene document, cam0 and cam1, with their poses and intrinsics.
Json TwoCameras() {
  return {{"cameras",
           {{"cam0",
             {{"model", "PINHOLE"},
              {"width", 160},
              {"height", 120},
              {"params", {138.0, 138.0, 80.0, 60.0}},
              {"qvec", {0.5, 0.5, -0.5, 0.5}},
              {"tvec", {0.1, -0.2, 3.0}}}},
            {"cam1",
             {{"model", "PINHOLE"},
              {"width", 160},
              {"height", 120},
              {"params", {138.0, 138.0, 80.0, 60.0}},
              {"qvec", {1.0, 0.0, 0.0, 0.0}},
              {"tvec", {0.0, 0.0, 2.0}}}}}}};
}

// The pose found is written as it is: the camera's qvec and tvec become the params', its other
// keys and the other camera are left as they were.
TEST(PoseErrorTest, WriteSetsThePoseFound) {
  CandidateResult c;
  c.effect = "pose_error";
  c.params = {{"camera", "cam0"},
              {"iterations", 4},
              {"rotation_deg", 2.5},
              {"center_shift_m", 0.13},
              {"qvec", {0.8, 0.2, -0.3, 0.1}},
              {"tvec", {0.15, -0.1, 2.9}}};
  Json doc = TwoCameras();
  Json expected = doc;
  expected["cameras"]["cam0"]["qvec"] = {0.8, 0.2, -0.3, 0.1};
  expected["cameras"]["cam0"]["tvec"] = {0.15, -0.1, 2.9};
  test::WriteCandidate(c, &doc);
  EXPECT_EQ(doc, expected) << doc.dump();
}

// Without a pose found, the fitted step is composed with the declared pose: the document is the
// one ComposePoseStep makes of the step, R ← exp(ω) R and t ← exp(ω) t + δ (checked against that
// formula too); the other camera is left as it was.
TEST(PoseErrorTest, WriteComposesTheFittedStepWithTheDeclaredPose) {
  const Eigen::Vector3d omega(0.01, -0.02, 0.005), delta(0.001, 0.0, -0.002);
  CandidateResult c;
  c.effect = "pose_error";
  c.params = {{"camera", "cam0"},
              {"rotation_deg", omega.norm() * 180 / render::kPi},
              {"rotation_vector", {omega.x(), omega.y(), omega.z()}},
              {"translation_m", {delta.x(), delta.y(), delta.z()}}};
  const Json declared = TwoCameras();
  Json doc = declared;
  test::WriteCandidate(c, &doc);
  recon::SceneDocument expected(declared);
  ComposePoseStep("cam0", omega, delta, &expected);
  EXPECT_EQ(doc, expected.json()) << doc.dump();
  EXPECT_NE(doc["cameras"]["cam0"], declared["cameras"]["cam0"]);
  EXPECT_EQ(doc["cameras"]["cam1"], declared["cameras"]["cam1"]);
  const Rigid3d before = recon::SceneDocument(declared).CameraPose("cam0");
  const Rigid3d after = recon::SceneDocument(doc).CameraPose("cam0");
  const Eigen::Quaterniond step(Eigen::AngleAxisd(omega.norm(), omega.normalized()));
  EXPECT_LT(after.rotation.angularDistance(step * before.rotation), 1e-12);
  EXPECT_LT((after.translation - (step * before.translation + delta)).norm(), 1e-12);
}

}  // namespace
}  // namespace igi::diagnose
