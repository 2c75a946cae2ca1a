// The fit stage and the paper stage's smoothing alone (solver/inverse/fit_stage.h,
// solver/inverse/paper_stage.h), on data built by hand: observations of a 1 m Lambertian square
// under a known irradiance. No photo is read and nothing is gathered or rendered.
#include "solver/inverse/fit_stage.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "solver/inverse/paper_stage.h"
#include "tests/solver/stage_fixture.h"

namespace igi::solver {
namespace {

constexpr double kIrradiance = 3.0;

// The stage's inputs (tests/solver/stage_fixture.h): `n` observations of the square, radiance
// albedo·E/π with 5 % Gaussian noise, every one a fit sample; the light model's irradiance E
// everywhere.
struct FitFixture : test::SquareStage {
  SolveSummary summary;

  FitFixture(double albedo, int n, unsigned seed)
      : SquareStage("fit_stage", n, kIrradiance, seed,
                    [albedo, gauss = std::normal_distribution<double>(0.0, 0.05)](
                        double, double, std::mt19937& rng) mutable {
                      return albedo * kIrradiance / render::kPi * (1 + gauss(rng));
                    }) {}

  StageData Data() const { return StageData{scene, options, obs, patches, 1.0, 0.1, 0.02}; }
};

TEST(FitStage, TheFitTakesEachRegionsAlbedoFromTheLightModel) {
  FitFixture f(0.4, 4000, 1);
  ASSERT_TRUE(f.materials[0].unknown_rho_d);
  const double change = FitRegions(f.Data(), f.light, 1, 1, &f.materials, &f.summary);
  const Eigen::Vector3d rho = f.materials[0].params.rho_d;
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(rho[c], 0.4, 0.004) << c;
  EXPECT_TRUE(f.materials[0].last_fit.fitted);
  // The iteration's record: its stage, its values, the change from the starting value.
  ASSERT_EQ(f.summary.history.size(), 1u);
  EXPECT_EQ(f.summary.history[0].stage, 1);
  EXPECT_NEAR(f.summary.history[0].params["floor"]["rho_d"][0].get<double>(), rho[0], 1e-12);
  EXPECT_EQ(f.summary.history[0].max_change, change);
  // A second fit from the same light changes nothing.
  EXPECT_LT(FitRegions(f.Data(), f.light, 1, 2, &f.materials, &f.summary), 1e-9);
}

TEST(FitStage, TheFitFollowsTheIrradianceItIsGiven) {
  // The same photos under a model that says 10 % more light: the albedo 10 % less.
  FitFixture f(0.4, 4000, 2);
  for (Eigen::Vector3d& e : f.light.e) e *= 1.1;
  FitRegions(f.Data(), f.light, 1, 1, &f.materials, &f.summary);
  EXPECT_NEAR(f.materials[0].params.rho_d[1], 0.4 / 1.1, 0.004);
}

// The joint update of one region whose own refit asks for ρd × 1.2 while its light grows with
// its albedo (feedback g: ΣE × (1 + g·Δ) for ρd × (1 + Δ)): the fixed point (1 + Δ)(1 + gΔ) = 1.2,
// Δ = (−(1 + g) + √((1 + g)² + 0.8g)) / 2g. Without feedback it is the refit itself.
TEST(FitStage, TheJointUpdateIsTheFixedPointOfTheLinearisedLight) {
  FitFixture f(0.4, 400, 3);
  f.options.refine_update = RefineUpdate::kJointAlbedo;
  f.materials[0].params.rho_d = Eigen::Vector3d::Constant(0.5);
  RegionFitResult fit;
  fit.fitted = true;
  fit.rho_d = Eigen::Vector3d::Constant(0.6);
  const double sum_e = kIrradiance * 400;
  for (double g : {0.0, 0.5, 2.0}) {
    f.light.joint_sums.Resize(1);
    const size_t entry = size_t(render::Renderer::kLnRhoD);  // region 0's row, region 0's ln ρd
    f.light.joint_sums.d_e[entry] = Eigen::Vector3d(g, g, 0.5 * g) * sum_e;
    const JointUpdate ju = JointParams(f.Data(), f.materials, f.light, {0}, {fit});
    ASSERT_EQ(ju.rho_d.size(), 1u);
    for (int c = 0; c < 3; ++c) {
      const double gc = c < 2 ? g : 0.5 * g;
      const double delta =
          gc == 0 ? 0.2 : (-(1 + gc) + std::sqrt((1 + gc) * (1 + gc) + 0.8 * gc)) / (2 * gc);
      EXPECT_NEAR(ju.rho_d[0][c], 0.5 * (1 + delta), 1e-9) << "g " << gc << ", channel " << c;
      EXPECT_NEAR(ju.feedback[0][c], gc, 1e-12);
    }
    EXPECT_TRUE(std::isnan(ju.rho_s[0][0]));  // joint_albedo: ρs is the region's own refit
  }
}

TEST(PaperStage, WithoutADrawOrAdaptiveSmoothingEveryRadiusIsTheScenesOver96) {
  FitFixture f(0.4, 200, 4);
  f.options.smoothing_accuracy = 0;
  const std::vector<float> radii = SmoothingRadii(f.Data(), f.light, f.materials.size());
  ASSERT_EQ(radii.size(), 200u);
  for (float r : radii) ASSERT_FLOAT_EQ(r, float(1.0 / 96));
  f.options.smoothing_radius_m = 0.05;
  for (float r : SmoothingRadii(f.Data(), f.light, f.materials.size())) ASSERT_FLOAT_EQ(r, 0.05f);
}

}  // namespace
}  // namespace igi::solver
