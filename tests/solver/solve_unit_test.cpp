// Unit tests of the solver's building blocks: patches (solver/patches.h) and the region fit
// (solver/region_fit.h) on samples generated from the model with known parameters.
#include <gtest/gtest.h>

#include <cmath>

#include "solver/brdf.h"
#include "solver/patches.h"
#include "solver/region_fit.h"
#include "solver/sampling.h"

namespace igi {
namespace {

TriangleMesh OneTriangle() {
  TriangleMesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  m.normals = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}};
  m.triangles = {{0, 1, 2}};
  m.triangle_region = {0};
  m.region_names = {"r"};
  return m;
}

TEST(Patches, SplitTrianglesIntoCongruentCellsThatPartitionThem) {
  const TriangleMesh mesh = OneTriangle();
  const PatchSet set = BuildPatches(mesh, 0.3);  // longest edge √2 → k = 5
  ASSERT_EQ(set.triangle_k[0], 5);
  ASSERT_EQ(set.size(), 25);
  double area = 0;
  for (int p = 0; p < set.size(); ++p) {
    area += set.area[p];
    // Each centre lies in its own patch.
    EXPECT_EQ(set.PatchOf(0, set.center_bary[p].x(), set.center_bary[p].y()), p);
  }
  EXPECT_NEAR(area, 0.5, 1e-6);
  // Random points: the patch found contains the point (its centre is within one cell).
  Pcg32 rng(3, 4);
  std::vector<int> hits(25, 0);
  for (int i = 0; i < 20000; ++i) {
    double b1 = rng.UniformDouble(), b2 = rng.UniformDouble();
    if (b1 + b2 > 1) b1 = 1 - b1, b2 = 1 - b2;
    const int p = set.PatchOf(0, b1, b2);
    ASSERT_GE(p, 0);
    ASSERT_LT(p, 25);
    EXPECT_LT(std::abs(set.center_bary[p].x() - b1) + std::abs(set.center_bary[p].y() - b2),
              2.0 / 5 + 1e-9);
    ++hits[p];
  }
  // Equal areas: each cell gets 1/25 of uniform points (binomial sd ≈ 28 of 800).
  for (int h : hits) EXPECT_NEAR(h, 800, 150);
}

// Samples of one region: each sees a small light near the mirror direction of some views, plus
// a few random incident directions, with L generated from the model.
RegionFitInput MakeSamples(BrdfModel model, const std::vector<Eigen::Vector3d>& slot_rho_d,
                           double rho_s, double alpha, double noise, uint64_t seed,
                           double alpha_y = 0) {
  if (alpha_y <= 0) alpha_y = alpha;
  RegionFitInput in;
  in.name = "test";
  in.model = model;
  in.num_slots = static_cast<int>(slot_rho_d.size());
  in.slot_area.assign(in.num_slots, 1.0);
  BrdfParams truth;
  truth.model = model;
  truth.rho_s.setConstant(rho_s);
  truth.alpha = alpha;
  Pcg32 rng(seed, 7);
  const Eigen::Vector3d light = Eigen::Vector3d(0.3, 0.1, 1).normalized();
  for (int i = 0; i < 3000; ++i) {
    FitSample s;
    s.slot = i % in.num_slots;
    // Views spread so that some fall inside the lobe around the light's mirror direction.
    const Eigen::Vector3d mirror(-light.x(), -light.y(), light.z());
    const Eigen::Vector3d jitter = (0.6 * SampleUniformHemisphere(rng.Uniform2D())).eval();
    Eigen::Vector3d wo = (mirror + Eigen::Vector3d(jitter.x(), jitter.y(), 0)).normalized();
    if (wo.z() < 0.05) wo = Eigen::Vector3d(wo.x(), wo.y(), 0.05).normalized();
    s.wo = wo.cast<float>();
    s.incident_begin = static_cast<int>(in.incident.size());
    Eigen::Vector3d e = Eigen::Vector3d::Zero(), spec = Eigen::Vector3d::Zero();
    auto add = [&](const Eigen::Vector3d& wi, const Eigen::Vector3d& value) {
      in.incident.push_back({wi.cast<float>(), value.cast<float>()});
      e += value;
      spec += SpecularWeight(model, alpha, alpha_y, 1.5, wo, wi) * value;
    };
    for (int k = 0; k < 4; ++k) {  // an extended light: four directions close together
      const Eigen::Vector3d wi =
          (light + 0.01 * Eigen::Vector3d(k % 2 - 0.5, k / 2 - 0.5, 0)).normalized();
      add(wi, Eigen::Vector3d(2.0, 1.8, 1.6) * wi.z());
    }
    for (int k = 0; k < 8; ++k) {  // dim light from the rest of the hemisphere
      const Eigen::Vector3d wi = SampleCosineHemisphere(rng.Uniform2D());
      add(wi, Eigen::Vector3d(0.1, 0.1, 0.12));
    }
    s.incident_end = static_cast<int>(in.incident.size());
    s.irradiance = e;
    const Eigen::Vector3d l =
        slot_rho_d[s.slot].cwiseProduct(e) / kPi + truth.rho_s.cwiseProduct(spec);
    // Shot-like noise: standard deviation noise·√(L·0.3), i.e. `noise` relative at L = 0.3.
    for (int c = 0; c < 3; ++c) {
      s.observed[c] = l[c] + noise * std::sqrt(l[c] * 0.3) * (2 * rng.UniformDouble() - 1) * std::sqrt(3.0);
    }
    in.samples.push_back(s);
  }
  return in;
}

TEST(RegionFit, RecoversWardParametersExactlyFromNoiseFreeSamples) {
  for (BrdfModel model : {BrdfModel::kWard, BrdfModel::kWardGmd}) {
    const Eigen::Vector3d rho_d(0.3, 0.5, 0.2);
    const RegionFitInput in = MakeSamples(model, {rho_d}, 0.06, 0.08, 0.0, 1);
    const RegionFitResult r = FitRegion(in, {});
    ASSERT_TRUE(r.fitted);
    EXPECT_EQ(r.albedo_model, "constant");
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(r.rho_d[c], rho_d[c], 1e-4 * rho_d[c]);
    EXPECT_NEAR(r.rho_s.mean(), 0.06, 1e-4 * 0.06);
    EXPECT_NEAR(r.alpha, 0.08, 1e-4 * 0.08);
    EXPECT_LT(r.relative_rms, 1e-5);
  }
}

TEST(RegionFit, RecoversAnisotropicRoughnessAlongTheTangentAndAcrossIt) {
  // ward_aniso with its tangent known (the local frame's x): αx and αy both recovered.
  const Eigen::Vector3d rho_d(0.3, 0.3, 0.3);
  const RegionFitInput in = MakeSamples(BrdfModel::kWardAniso, {rho_d}, 0.08, 0.05, 0.0, 6, 0.2);
  const RegionFitResult r = FitRegion(in, {});
  EXPECT_NEAR(r.alpha_x, 0.05, 0.01 * 0.05);
  EXPECT_NEAR(r.alpha_y, 0.2, 0.01 * 0.2);
  EXPECT_NEAR(r.rho_s.mean(), 0.08, 0.01 * 0.08);
}

TEST(RegionFit, NoisySamplesStayWithinTheirStatedUncertainty) {
  // Shot-like noise (2 % at L = 0.3): the estimates must fall within 4 sigma of the truth,
  // and sigma must be small enough to be useful (under 5 % of the value).
  const Eigen::Vector3d rho_d(0.3, 0.5, 0.2);
  const RegionFitInput in = MakeSamples(BrdfModel::kWard, {rho_d}, 0.06, 0.08, 0.02, 2);
  const RegionFitResult r = FitRegion(in, {});
  ASSERT_TRUE(std::isfinite(r.sigma_rho_s));
  ASSERT_TRUE(std::isfinite(r.sigma_alpha));
  EXPECT_LT(std::abs(r.rho_s.mean() - 0.06), 4 * r.sigma_rho_s);
  EXPECT_LT(std::abs(r.alpha - 0.08), 4 * r.sigma_alpha);
  EXPECT_LT(r.sigma_rho_s, 0.05 * 0.06);
  EXPECT_LT(r.sigma_alpha, 0.05 * 0.08);
  for (int c = 0; c < 3; ++c) EXPECT_LT(std::abs(r.rho_d[c] - rho_d[c]), 4 * r.sigma_rho_d[c] + 1e-4);
}

TEST(RegionFit, VaryingAlbedoIsFittedPerPatchAndKeepsTheLobe) {
  // 12 patches whose albedo differs by up to ±40 %: the constant model cannot explain them, the
  // per-patch model must be chosen, and ρs and α must still come out right (noise-free: 1 %).
  std::vector<Eigen::Vector3d> slots;
  for (int k = 0; k < 12; ++k) slots.push_back(Eigen::Vector3d(0.3, 0.4, 0.2) * (0.6 + 0.07 * k));
  const RegionFitInput in = MakeSamples(BrdfModel::kWard, slots, 0.05, 0.12, 0.0, 3);
  const RegionFitResult r = FitRegion(in, {});
  EXPECT_EQ(r.albedo_model, "per_patch");
  EXPECT_TRUE(r.albedo_varies);
  EXPECT_NEAR(r.rho_s.mean(), 0.05, 0.01 * 0.05);
  EXPECT_NEAR(r.alpha, 0.12, 0.01 * 0.12);
  for (int k = 0; k < 12; ++k) {
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(r.slot_rho_d[k][c], slots[k][c], 0.01 * slots[k][c]);
  }
}

TEST(RegionFit, LambertRegionsGetTheirAlbedoAndKnownValuesAreHeld) {
  RegionFitInput in = MakeSamples(BrdfModel::kLambert, {Eigen::Vector3d(0.7, 0.6, 0.5)}, 0, 0.1, 0, 4);
  RegionFitResult r = FitRegion(in, {});
  EXPECT_NEAR(r.rho_d[0], 0.7, 1e-6);
  EXPECT_NEAR(r.rho_d[2], 0.5, 1e-6);
  // Ward with ρs known: only α and ρd are fitted, ρs stays.
  in = MakeSamples(BrdfModel::kWard, {Eigen::Vector3d(0.2, 0.2, 0.2)}, 0.04, 0.1, 0, 5);
  in.rho_s_grey = 0.04;
  r = FitRegion(in, {});
  EXPECT_DOUBLE_EQ(r.rho_s.mean(), 0.04);
  EXPECT_NEAR(r.alpha, 0.1, 1e-3);
  // No sample: nothing fitted, and it says so.
  RegionFitInput empty;
  empty.model = BrdfModel::kWard;
  r = FitRegion(empty, {});
  EXPECT_FALSE(r.fitted);
  EXPECT_FALSE(r.message.empty());
}

}  // namespace
}  // namespace igi
