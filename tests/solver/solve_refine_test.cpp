// Stage 2 of igi-solve (solver/inverse/refine_stage.h, SolverState::RefineRound): the light
// arriving at every observation is rendered by the path tracer from the current model, so the
// albedos light their own next fit. Refitting each region alone (πL/E at that E: "independent")
// then overshoots in a bright closed room: albedos 5 % too high make the rendered room too bright,
// and the next fit comes out several per cent too low. The joint update also renders the
// irradiance's derivatives with respect to every region's albedo scale and solves for all
// albedos at once, so one round from the same start lands on the answer.
//
// Scene: tests/e2e/box_room.h's closed 2 m room (both cameras, the point lamp) with bright
// Lambertian albedos (floor 0.6, ceiling 0.8, walls 0.7/0.65/0.6: about 60 % of each surface's
// irradiance arrives from the other surfaces), photos rendered by the path tracer at 256 paths
// per pixel, all three albedos unknown. Stage 1 is run, its albedos are multiplied by 1.05, and
// one stage-2 round follows.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include "recon/scene.h"
#include "solver/inverse/solve.h"
#include "solver/inverse/solve_internal.h"
#include "solver/render/render.h"
#include "tests/e2e/box_room.h"
#include "tests/solver/box_room_photos.h"
#include "tests/temp_dir.h"
#include "tools/common/image.h"
#include "tools/common/json.h"

namespace igi::solver {
namespace {
namespace fs = std::filesystem;
namespace room = test::box_room;

// The bright room's truth; with `glossy_floor` the floor is ward_gmd (ρd 0.3, ρs 0.3, α 0.2).
Json BrightMaterials(bool glossy_floor = false) {
  Json m = {{"floor", {{"brdf", "lambert"}, {"rho_d", {0.6, 0.6, 0.6}}}},
            {"ceiling", {{"brdf", "lambert"}, {"rho_d", {0.8, 0.8, 0.8}}}},
            {"walls", {{"brdf", "lambert"}, {"rho_d", {0.7, 0.65, 0.6}}}}};
  if (glossy_floor) {
    m["floor"] = {{"brdf", "ward_gmd"},
                  {"rho_d", {0.3, 0.3, 0.3}},
                  {"rho_s", {0.3, 0.3, 0.3}},
                  {"alpha", 0.2}};
  }
  return m;
}

// The same with every parameter left to solve.
Json Unknowns(Json m) {
  for (auto& [name, material] : m.items()) {
    for (const char* key : {"rho_d", "rho_s", "alpha"}) material.erase(key);
  }
  return m;
}

class SolveRefine : public ::testing::TestWithParam<bool> {
 protected:
  // GetParam(): the floor is glossy.
  void SetUp() override {
    dir_ = test::UniqueTempDir("solve_refine");
    room::WriteRoomFolder(dir_);
    ASSERT_TRUE(fs::exists(dir_ / "geometry" / "room.obj"));
    Json photos = Json::array();
    for (const char* cam : {"cam0", "cam1"}) {
      photos.push_back(room::PhotoEntry(std::string("photos/") + cam + ".exr", cam, "L0"));
    }
    WriteJsonFile(dir_ / "truth.json", room::SceneDoc(BrightMaterials(GetParam()), Json::array()));
    WriteJsonFile(dir_ / "scene.json",
                  room::SceneDoc(Unknowns(BrightMaterials(GetParam())), photos));
    room::RenderTruthPhotos(dir_, {"cam0", "cam1"}, 256, 9);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // Stage 1, then every solved albedo times `start_scale` and every solved ρs times
  // `rho_s_scale`, then one stage-2 round with `update`: the largest relative error of any
  // Lambertian region's albedo channel (signed), before (after the scaling) and after the round;
  // and in `rho_s_after` the floor's ρs error after it (if glossy).
  std::pair<double, double> OneRound(const std::string& update, double start_scale,
                                     double rho_s_scale = 1, double* rho_s_after = nullptr,
                                     int threads = 2) const {
    const recon::Scene scene = recon::LoadScene(dir_ / "scene.json");
    SolveOptions o;
    o.pixel_stride = 1;
    o.refine_rays = 64;
    o.refine_update = RefineUpdateFromName(update).value();
    o.num_threads = threads;
    o.show_progress = false;
    SolverState s(scene, o);
    s.Prepare();
    s.GatherAll();
    s.RunStage1();
    for (MaterialState& m : s.materials) {
      if (!m.unknown_rho_d) continue;
      m.params.rho_d *= start_scale;
      for (Eigen::Vector3d& p : m.patch_rho_d) p *= start_scale;  // NaN stays NaN
      if (m.unknown_rho_s) m.params.rho_s *= rho_s_scale;
    }
    UpdateSpecularTerms(s.Stage(), s.materials, &s.light);
    const Json truth = BrightMaterials(GetParam());
    auto worst = [&]() {
      double w = 0;
      for (size_t r = 0; r < s.materials.size(); ++r) {
        if (s.materials[r].params.model != recon::BrdfModel::kLambert) continue;
        for (int c = 0; c < 3; ++c) {
          const double want = truth.at(scene.materials[r].name).at("rho_d")[c].get<double>();
          const double e = s.materials[r].params.rho_d[c] / want - 1;
          if (std::abs(e) > std::abs(w)) w = e;
        }
      }
      return w;
    };
    const double before = worst();
    s.RefineRound(1, dir_ / ("maps_" + update));
    const double after = worst();
    for (size_t r = 0; r < s.materials.size(); ++r) {
      const render::BrdfParams& v = s.materials[r].params;
      std::printf("  %s %-8s rho_d %.4f %.4f %.4f", update.c_str(), scene.materials[r].name.c_str(),
                  v.rho_d[0], v.rho_d[1], v.rho_d[2]);
      if (s.materials[r].unknown_rho_s) {
        std::printf("  rho_s %.4f  alpha %.4f", v.rho_s.mean(), v.alpha);
        if (rho_s_after != nullptr) *rho_s_after = v.rho_s.mean() / 0.3 - 1;
      }
      std::printf("\n");
    }
    EXPECT_EQ(s.summary.history.back().albedo_update, RefineUpdateFromName(update));
    return {before, after};
  }

  fs::path dir_;
};

using SolveRefineLambert = SolveRefine;
using SolveRefineGlossy = SolveRefine;

TEST_P(SolveRefineLambert, JointRoundLandsOnTheAlbedosWhereTheIndependentOneOvershoots) {
  const auto [joint_before, joint_after] = OneRound("joint", 1.05);
  const auto [indep_before, indep_after] = OneRound("independent", 1.05);
  std::printf(
      "worst albedo error: start %+.2f %%, joint round %+.2f %%, independent round %+.2f %%\n",
      100 * joint_before, 100 * joint_after, 100 * indep_after);
  EXPECT_GT(joint_before, 0.04);  // the start really is off
  // 1 %: the accuracy target for region means. The round's own noise (64 rendered directions per
  // observation, every pixel, 256-path photos) is a few tenths of a per cent.
  EXPECT_LT(std::abs(joint_after), 0.01);
  // The scene must show the feedback, or the check above guards nothing: the independent
  // round from the same start swings past the answer by more than it started off.
  EXPECT_LT(indep_after, -0.05);
}

INSTANTIATE_TEST_SUITE_P(Room, SolveRefineLambert, ::testing::Values(false));

// The floor glossy (ward_gmd, ρs 0.3, α 0.2): the walls and ceiling receive its reflected light,
// lobe included. Stage 1's ρs is raised by 40 % before the round: that model's rendered light
// is too bright where the floor's lobe sends it, and the refits of the walls and ceiling, seeing
// that light, come out low while the floor's own refit of ρs comes back down. The joint update
// knows from the renderer's derivatives with respect to the floor's ρs (and α) how much of the
// others' light goes with it, so their albedos land on the truth (within 0.1 %); the
// albedo-only joint update ("joint_albedo") treats the light of the floor's lobe
// as fixed and leaves them 1.3–1.8 % low. The floor's own ρd and ρs are not checked to 1 %: in
// this 64 × 48 room its wide lobe trades ρs against ρd by ±4 % from one round to another
// (stage 1's floor: ρd −1.3 %); its ρs is checked to have come back from +40 %.
TEST_P(SolveRefineGlossy, JointRoundFollowsTheGlossyFloorsReflectedLight) {
  double rho_s_joint = 0, rho_s_albedo_only = 0;
  const auto [joint_before, joint_after] = OneRound("joint", 1.0, 1.4, &rho_s_joint);
  const auto [albedo_before, albedo_after] = OneRound("joint_albedo", 1.0, 1.4, &rho_s_albedo_only);
  std::printf(
      "worst wall/ceiling albedo error: start %+.2f %%, joint round %+.2f %%, albedo-only joint "
      "round %+.2f %%; floor rho_s %+.2f %% / %+.2f %%\n",
      100 * joint_before, 100 * joint_after, 100 * albedo_after, 100 * rho_s_joint,
      100 * rho_s_albedo_only);
  EXPECT_LT(std::abs(joint_after), 0.005);
  EXPECT_LT(albedo_after, -0.01);  // the scene shows the lobe's share of the feedback
  EXPECT_LT(std::abs(rho_s_joint), 0.08);
  // The derivatives are summed per chunk of observations fixed by their count, not by the
  // threads: one thread gives the same round to the last bit.
  double rho_s_one_thread = 0;
  const auto [one_before, one_after] = OneRound("joint", 1.0, 1.4, &rho_s_one_thread, 1);
  EXPECT_EQ(one_after, joint_after);
  EXPECT_EQ(rho_s_one_thread, rho_s_joint);
}
INSTANTIATE_TEST_SUITE_P(Room, SolveRefineGlossy, ::testing::Values(true));

}  // namespace
}  // namespace igi::solver
