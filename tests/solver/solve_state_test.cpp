// The solve's data, each a plain structure (solver/inverse/observation_set.h,
// solver/inverse/material_estimate.h, solver/inverse/light_model.h), and the stages that are
// functions of them alone, run on hand-made observations: no photo, no ray.
#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <tuple>
#include <vector>

#include "recon/scene.h"
#include "solver/inverse/fit_inputs.h"
#include "solver/inverse/light_model.h"
#include "solver/inverse/material_estimate.h"
#include "solver/inverse/observation_set.h"
#include "solver/inverse/patches.h"
#include "solver/inverse/region_fit.h"

namespace igi::solver {
namespace {

Observation At(int photo, int x, int y, int region, const Eigen::Vector3f& position) {
  Observation o;
  o.photo = photo, o.x = x, o.y = y, o.region = region;
  o.position = position;
  o.normal = Eigen::Vector3f::UnitZ();
  o.view = Eigen::Vector3f::UnitZ();
  return o;
}

recon::Material Named(const std::string& name, recon::BrdfModel brdf) {
  recon::Material m;
  m.name = name;
  m.brdf = brdf;
  return m;
}

TEST(MaterialEstimateTest, FromSceneMarksTheUnknownsAndGroupsThePatchesByRegion) {
  recon::Scene scene;
  recon::Material walls = Named("walls", recon::BrdfModel::kLambert);
  walls.rho_d = Eigen::Vector3d(0.3, 0.4, 0.5);
  recon::Material floor = Named("floor", recon::BrdfModel::kWard);
  floor.alpha = 0.2;  // ρd and ρs unknown
  scene.materials = {walls, floor, Named("lamp", recon::BrdfModel::kEmitter)};
  PatchSet patches;
  patches.patch_triangle = {0, 1, 2, 3};
  patches.patch_region = {1, 0, 1, 1};

  MaterialEstimate m = MaterialEstimate::FromScene(scene, patches);
  ASSERT_EQ(m.size(), 3u);
  EXPECT_FALSE(m[0].NeedsFit());
  EXPECT_EQ(m[0].params.rho_d, Eigen::Vector3d(0.3, 0.4, 0.5));
  EXPECT_TRUE(m[1].NeedsFit());
  EXPECT_TRUE(m[1].unknown_rho_d && m[1].unknown_rho_s);
  EXPECT_FALSE(m[1].unknown_alpha);
  EXPECT_DOUBLE_EQ(m[1].params.alpha, 0.2);
  EXPECT_FALSE(m[2].reflective);
  EXPECT_EQ(m.region_patches[1], (std::vector<int>{0, 2, 3}));
  EXPECT_EQ(m.patch_slot, (std::vector<int>{0, 0, 1, 2}));
  ASSERT_EQ(m[1].patch_rho_d.size(), 3u);

  // A patch without an albedo of its own has its region's; one fitted per patch has its own.
  EXPECT_EQ(m.PatchAlbedo(patches, 2), m[1].params.rho_d);
  m[1].patch_rho_d[1] = Eigen::Vector3d(0.7, 0.6, 0.5);
  EXPECT_EQ(m.PatchAlbedo(patches, 2), Eigen::Vector3d(0.7, 0.6, 0.5));
  EXPECT_EQ(m.PatchAlbedo(patches, 3), m[1].params.rho_d);
}

TEST(SpecularTermsTest, SumTheWidenedLobeOverTheIncidentSamplesAndAreZeroOffLobes) {
  MaterialEstimate m;
  m.regions.resize(2);
  m[0].params.model = recon::BrdfModel::kLambert;
  m[1].params.model = recon::BrdfModel::kWard;
  m[1].params.alpha = m[1].params.alpha_x = m[1].params.alpha_y = 0.2;
  ObservationSet obs;
  obs.items = {At(0, 0, 0, 0, Eigen::Vector3f::Zero()), At(0, 1, 0, 1, Eigen::Vector3f::Zero())};
  obs[1].lobe_blur2 = 0.01f;
  const double s30 = std::sin(30 * M_PI / 180), c30 = std::cos(30 * M_PI / 180);
  const std::vector<IncidentLocal> samples = {
      {Eigen::Vector3f::UnitZ(), Eigen::Vector3f(1, 2, 3)},
      {Eigen::Vector3f(float(s30), 0, float(c30)), Eigen::Vector3f(0.5f, 0.5f, 0.5f)}};
  const std::vector<std::vector<IncidentLocal>> incident = {samples, samples};

  std::vector<Eigen::Vector3d> t0;
  const std::vector<Eigen::Vector3d> t = SpecularTerms(obs, m, incident, 1, &t0);
  ASSERT_EQ(t0.size(), 2u);
  EXPECT_EQ(t0[1], Eigen::Vector3d::Zero());  // Ward's lobe: all of it scales with ρs
  ASSERT_EQ(t.size(), 2u);
  EXPECT_EQ(t[0], Eigen::Vector3d::Zero());
  // Ward at α widened by the pixel's spread of normals: √(0.2² + 0.01).
  const double a = std::sqrt(0.04 + double(obs[1].lobe_blur2));
  Eigen::Vector3d expected = Eigen::Vector3d::Zero();
  for (const IncidentLocal& s : samples) {
    expected += LobeWeight(recon::BrdfModel::kWard, a, a, m[1].params.ior, Eigen::Vector3d::UnitZ(),
                           s.Wi().cast<double>())
                    .scale *
                s.Value().cast<double>();
  }
  ASSERT_GT(expected.minCoeff(), 0);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(t[1][c], expected[c], 1e-9 * expected[c]);
}

TEST(SmoothIrradianceTest, AveragesTheIndirectOverTheSameRegionsNeighboursAndKeepsTheDirect) {
  ObservationSet obs;
  obs.items = {At(0, 0, 0, 0, {0, 0, 0}), At(1, 0, 0, 0, {0.05f, 0, 0}), At(0, 9, 0, 0, {1, 0, 0}),
               At(0, 0, 9, 1, {0, 0, 0})};
  LightModel light;
  light.lightings.resize(1);
  light.lightings[0].active = true;
  light.lightings[0].obs = {0, 1, 2, 3};
  light.e_direct = {Eigen::Vector3d::Constant(1), Eigen::Vector3d::Constant(2),
                    Eigen::Vector3d::Constant(3), Eigen::Vector3d::Constant(4)};
  light.e_indirect = {Eigen::Vector3d(0.1, 0.2, 0.3), Eigen::Vector3d(0.3, 0.4, 0.5),
                      Eigen::Vector3d::Constant(7), Eigen::Vector3d::Constant(9)};
  light.smoothing_radius.assign(4, 0.1f);

  SmoothIrradiance(obs, 1, &light);
  ASSERT_EQ(light.e.size(), 4u);
  // 0 and 1 are neighbours (another photo of the same lighting counts); 2 is too far; 3 is on
  // another region.
  const Eigen::Vector3d mean01(0.2, 0.3, 0.4);
  EXPECT_TRUE(light.e[0].isApprox(Eigen::Vector3d::Constant(1) + mean01, 1e-12));
  EXPECT_TRUE(light.e[1].isApprox(Eigen::Vector3d::Constant(2) + mean01, 1e-12));
  EXPECT_TRUE(light.e[2].isApprox(Eigen::Vector3d::Constant(10), 1e-12));
  EXPECT_TRUE(light.e[3].isApprox(Eigen::Vector3d::Constant(13), 1e-12));

  // A radius of its own per observation: observation 1's reaches no other.
  light.smoothing_radius = {0.1f, 0.01f, 0.1f, 0.1f};
  SmoothIrradiance(obs, 1, &light);
  EXPECT_TRUE(light.e[1].isApprox(Eigen::Vector3d(2.3, 2.4, 2.5), 1e-12));
  EXPECT_TRUE(light.e[0].isApprox(Eigen::Vector3d::Constant(1) + mean01, 1e-12));
}

// Two patches of one Lambertian region (ρd 0.5) under one lighting: patch 0 seen by the one
// observation, patch 1 unseen and lit directly (E 4); patch 0's gather point has one indirect
// sample toward patch 1, the observation's point two (toward patch 0 and patch 1).
TEST(IrradianceFromPatchesTest, SeenPatchesSendThePhotosRadianceUnseenOnesTheirAlbedoTimesE) {
  recon::Scene scene;
  recon::Material walls = Named("walls", recon::BrdfModel::kLambert);
  walls.rho_d = Eigen::Vector3d::Constant(0.5);
  scene.materials = {walls};
  PatchSet patches;
  patches.patch_triangle = {0, 1};
  patches.patch_region = {0, 0};
  patches.center = {Eigen::Vector3f::Zero(), Eigen::Vector3f::UnitX()};
  patches.normal = {Eigen::Vector3f::UnitZ(), Eigen::Vector3f::UnitZ()};
  const MaterialEstimate materials = MaterialEstimate::FromScene(scene, patches);
  ObservationSet obs;
  obs.items = {At(0, 0, 0, 0, Eigen::Vector3f::Zero())};
  obs[0].patch = 0;
  obs[0].radiance = Eigen::Vector3f::Constant(0.3f);
  LightModel light;
  light.point = {0};
  light.lightings.resize(1);
  LightingState& st = light.lightings[0];
  st.active = true;
  st.obs = {0};
  st.first_patch_point = 1;
  auto indirect = [](int patch, float weight) {
    IndirectSample s;
    s.patch = patch, s.weight = weight;
    return s;
  };
  st.gather.indirect = {indirect(0, 0.5f), indirect(1, 0.25f), indirect(1, 1.0f)};
  st.gather.points.resize(3);
  st.gather.points[0].e_direct = Eigen::Vector3f::Constant(1);
  st.gather.points[0].indirect_begin = 0, st.gather.points[0].indirect_end = 2;
  st.gather.points[1].e_direct = Eigen::Vector3f::Constant(2);
  st.gather.points[1].indirect_begin = 2, st.gather.points[1].indirect_end = 3;
  st.gather.points[2].e_direct = Eigen::Vector3f::Constant(4);
  st.gather.points[2].indirect_begin = st.gather.points[2].indirect_end = 3;
  st.patch_e = {Eigen::Vector3f::Constant(2), Eigen::Vector3f::Constant(4)};
  st.patch_d.assign(2, Eigen::Vector3f::Zero());
  BuildPatchLobes(patches, materials, &st);  // Lambertian: none

  UpdatePatchRadiance(obs, patches, materials, {Eigen::Vector3d::Zero()}, {Eigen::Vector3d::Zero()},
                      1, &st);
  const double d1 = 0.5 * 4 / M_PI;
  EXPECT_NEAR(st.patch_d[0].x(), 0.3, 1e-6);  // the photo's
  EXPECT_NEAR(st.patch_d[1].x(), d1, 1e-6);   // ρd·E/π
  EXPECT_NEAR(st.patch_e[0].x(), 2 + d1, 1e-6);
  EXPECT_NEAR(st.patch_e[1].x(), 4, 1e-6);

  IncidentFromPatches(obs, patches, materials, 1, &light);
  ASSERT_EQ(light.e_indirect.size(), 1u);
  EXPECT_EQ(light.e_direct[0], Eigen::Vector3d::Constant(1));
  EXPECT_NEAR(light.e_indirect[0].x(), 0.5 * 0.3 + 0.25 * d1, 1e-6);
  EXPECT_TRUE(light.incident[0].empty());  // no lobe: no samples kept
}

// Two regions: walls (ρd unknown) and a box whose ρd is given (not fitted); the walls' two
// observations, one a fit sample.
TEST(FitInputsTest, OneInputPerFittedRegionWithASamplePerFitObservation) {
  recon::Scene scene;
  recon::Material walls = Named("walls", recon::BrdfModel::kLambert);
  recon::Material box = Named("box", recon::BrdfModel::kLambert);
  box.rho_d = Eigen::Vector3d::Constant(0.4);
  scene.materials = {walls, box};
  PatchSet patches;
  patches.patch_triangle = {0, 1, 2};
  patches.patch_region = {0, 1, 0};
  patches.area = {0.5f, 0.25f, 1.5f};
  MaterialEstimate materials = MaterialEstimate::FromScene(scene, patches);
  materials[0].observations = 2;
  materials[1].observations = 1;
  ObservationSet obs;
  obs.items = {At(0, 0, 0, 0, Eigen::Vector3f::Zero()), At(0, 1, 0, 1, Eigen::Vector3f::Zero()),
               At(0, 2, 0, 0, Eigen::Vector3f::Zero())};
  obs[0].patch = 2, obs[1].patch = 1, obs[2].patch = 0;
  obs[0].radiance = Eigen::Vector3f(0.1f, 0.2f, 0.3f);
  obs.in_fit = {1, 1, 0};
  LightModel light;
  light.e = {Eigen::Vector3d(1, 2, 3), Eigen::Vector3d::Ones(), Eigen::Vector3d::Ones()};
  light.incident.resize(3);

  std::vector<int> regions;
  SolveOptions options;
  options.specular_colour = SpecularColour::kRgb;
  const std::vector<RegionFitInput> in =
      FitInputs(scene, patches, obs, light, materials, 1, options, &regions);
  ASSERT_EQ(regions, std::vector<int>{0});
  ASSERT_EQ(in.size(), 1u);
  EXPECT_EQ(in[0].name, "walls");
  EXPECT_TRUE(in[0].fit_rho_d);
  EXPECT_EQ(in[0].num_slots, 2);
  EXPECT_EQ(in[0].slot_area, (std::vector<double>{0.5, 1.5}));
  ASSERT_EQ(in[0].samples.size(), 1u);  // the fit sample only
  const FitSample& s = in[0].samples[0];
  EXPECT_EQ(s.observed, Eigen::Vector3f(0.1f, 0.2f, 0.3f).cast<double>());
  EXPECT_EQ(s.irradiance, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(s.slot, 1);  // patch 2 is the walls' second
  EXPECT_FALSE(s.rho_d_held.allFinite());
}

// The fit samples of region 1 (50 observations of photo 2, first) and region 0 (1000 over photos
// 0 and 1, the first 300 near a highlight); region 2 is not fitted.
ObservationSet FitSampleObservations(bool with_photo_2) {
  ObservationSet obs;
  if (with_photo_2) {
    for (int k = 0; k < 50; ++k) obs.items.push_back(At(2, k, 3, 1, Eigen::Vector3f::Zero()));
  }
  for (int k = 0; k < 1000; ++k)
    obs.items.push_back(At(k % 2, k / 2, 7, 0, Eigen::Vector3f::Zero()));
  for (int k = 0; k < 20; ++k) obs.items.push_back(At(0, k, 900, 2, Eigen::Vector3f::Zero()));
  return obs;
}

std::set<std::tuple<int, int, int>> Chosen(const ObservationSet& obs, int region, bool near) {
  std::set<std::tuple<int, int, int>> out;
  for (size_t i = 0; i < obs.size(); ++i) {
    const Observation& o = obs[i];
    const bool is_near = o.region == 0 && o.x < 150;  // the first 300 of region 0
    if (obs.in_fit[i] && o.region == region && is_near == near) out.insert({o.photo, o.x, o.y});
  }
  return out;
}

void Select(ObservationSet* obs) {
  std::vector<char> near(obs->size(), 0);
  for (size_t i = 0; i < obs->size(); ++i) near[i] = (*obs)[i].region == 0 && (*obs)[i].x < 150;
  SelectFitSamples({1, 1, 0}, near, 100, 300, obs);
}

TEST(SelectFitSamplesTest, DrawsToTheCapsByPixelAndKeepsEveryObservationUnderThem) {
  ObservationSet obs = FitSampleObservations(true);
  Select(&obs);
  ASSERT_EQ(obs.in_fit.size(), obs.size());
  const size_t near = Chosen(obs, 0, true).size(), rest = Chosen(obs, 0, false).size();
  // About 100 of the 300 near a highlight, and about 300 − 100 of the other 700 (hashed draws:
  // binomial, σ ≈ 8 and 12).
  EXPECT_NEAR(double(near), 100, 35);
  EXPECT_NEAR(double(rest), 300 - double(near), 45);
  EXPECT_EQ(Chosen(obs, 1, false).size(), 50u);  // under the caps: every one
  EXPECT_TRUE(Chosen(obs, 2, false).empty());    // not fitted

  // The draw is a property of each pixel: without photo 2's observations (every later index
  // moved), region 0's draw is the same.
  ObservationSet without = FitSampleObservations(false);
  Select(&without);
  EXPECT_EQ(Chosen(without, 0, true), Chosen(obs, 0, true));
  EXPECT_EQ(Chosen(without, 0, false), Chosen(obs, 0, false));
}

}  // namespace
}  // namespace igi::solver
