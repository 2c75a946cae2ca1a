// ResidualFitter: an effect's amplitude is recovered from noisy residual samples, also when each
// cell's albedo is wrong by a factor (the nuisance the solver would refit); pure noise earns no
// significant held-out gain; the step gate's block z (BlockGainZ); and the photo model of
// scene.json inverts exactly.
#include "solver/diagnose/residual_fit.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "solver/inverse/photo_model.h"

namespace igi::diagnose {
namespace {

// A record at a random pixel of a 160×120 photo, held out by 16-px blocks.
PixelRecord RandomPixel(int photo, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0, 1);
  PixelRecord r;
  r.photo = photo;
  r.x = int(u(rng) * 160);
  r.y = int(u(rng) * 120);
  r.held_out = solver::PixelHoldout{0.25, 16, 3}.HeldOut(r.photo, r.x, r.y);
  return r;
}

// Records on `cells` cells; the photo is sim·(1 + k·r²)·albedo_error[cell] + noise. Each cell is
// seen around its own image radius (as a surface seen mostly from one place in one photo), and
// with `confounded` its albedo error follows that radius — as when an albedo map has absorbed part
// of the effect.
std::vector<PixelRecord> Records(double k, double albedo_spread, double noise, int cells,
                                 std::vector<int>* cell_of, uint64_t seed,
                                 bool confounded = false) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::normal_distribution<double> n(0, 1);
  std::vector<double> error(cells), center(cells);
  for (int c = 0; c < cells; ++c) {
    center[c] = 0.15 + 0.7 * u(rng);
    error[c] =
        confounded ? 1 + albedo_spread * center[c] * 4 : 1 + albedo_spread * (2 * u(rng) - 1);
  }
  std::vector<PixelRecord> out;
  for (int i = 0; i < 20000; ++i) {
    PixelRecord r = RandomPixel(i % 4, rng);
    const int cell = i % cells;
    r.r2 = float(center[cell] + 0.3 * (u(rng) - 0.5));
    cell_of->push_back(cell);
    for (int c = 0; c < 3; ++c) {
      r.sim[c] = float(0.5 + u(rng));
      r.recorded[c] = float(r.sim[c] * (1 + k * r.r2) * error[cell] + noise * n(rng));
    }
    out.push_back(r);
  }
  return out;
}

auto kR2 = [](const PixelRecord& r, int c, double* b) { b[0] = r.sim[c] * r.r2; };

TEST(ResidualFitTest, RecoversAnAmplitudeWithoutNuisance) {
  std::vector<int> cells;
  const auto records = Records(-0.3, 0.0, 0.05, 50, &cells, 1);
  const ResidualFitter f(records, cells, 50, false, 16);
  const ResidualFit fit = f.Fit(1, kR2);
  ASSERT_EQ(fit.coef.size(), 1);
  // 60 000 samples of noise 0.05 against a basis of spread ~0.3: σ(k) ≈ 0.001.
  EXPECT_NEAR(fit.coef[0], -0.3, 0.005);
  EXPECT_GT(fit.Gain(), 0.5);
  EXPECT_GT(fit.z, 10);
}

TEST(ResidualFitTest, ProjectsOutAFreeAlbedoPerCell) {
  std::vector<int> cells;
  // Albedo errors that grow with the radius (+3 % .. +17 %) bias a plain fit.
  const auto records = Records(-0.3, 0.05, 0.05, 50, &cells, 2, true);
  const ResidualFitter plain(records, cells, 50, false, 16);
  const ResidualFitter nuisance(records, cells, 50, true, 16);
  const ResidualFit a = plain.Fit(1, kR2), b = nuisance.Fit(1, kR2);
  // Within-cell variation of r² (±0.15) still identifies k: σ(k) ≈ 0.005; the cell factor
  // (0.9..1.1) multiplies the effect too, so allow 0.03.
  EXPECT_NEAR(b.coef[0], -0.3, 0.03);
  EXPECT_GT(std::abs(a.coef[0] + 0.3), 0.1) << a.coef[0];  // the plain fit is confounded
  EXPECT_GT(b.z, 5);
}

TEST(ResidualFitTest, NoiseAloneEarnsNothing) {
  std::vector<int> cells;
  const auto records = Records(0.0, 0.1, 0.05, 50, &cells, 3);
  const ResidualFitter f(records, cells, 50, true, 16);
  const ResidualFit fit = f.Fit(2, [](const PixelRecord& r, int c, double* b) {
    b[0] = r.sim[c] * r.r2;
    b[1] = r.sim[c] * r.r2 * r.r2;
  });
  ASSERT_EQ(fit.coef.size(), 2);
  EXPECT_LT(fit.Gain(), 0.01);
  EXPECT_LT(fit.z, 3);
}

// BlockGainZ (igi-diagnose's step gate): blocks of error e ~ 1..10 whose change is noise
// (gain ~ N(0, 0.3 e)) rarely reach 2.5 (one-sided rate 0.6 % per test; 400 draws expect ≤ 2.5,
// ≤ 8 allowed for the tails of a t statistic); an effect explained in 4 bright blocks among 300
// noise blocks (a highlight) reaches it although the per-block-alike mean alone stays under 2;
// an effect spread thinly over every block reaches it too.
std::vector<std::pair<double, double>> NoiseBlocks(std::mt19937_64* rng, int n) {
  std::uniform_real_distribution<double> u(1, 10);
  std::normal_distribution<double> g(0, 1);
  std::vector<std::pair<double, double>> blocks;
  for (int b = 0; b < n; ++b) {
    const double e = u(*rng);
    blocks.emplace_back(0.3 * e * g(*rng), e);
  }
  return blocks;
}

TEST(BlockGainZTest, NoiseRarelyPasses) {
  std::mt19937_64 rng(7);
  int passed = 0;
  for (int draw = 0; draw < 400; ++draw) passed += BlockGainZ(NoiseBlocks(&rng, 300)) >= 2.5;
  EXPECT_LE(passed, 8);
}

TEST(BlockGainZTest, AFewWellExplainedBlocksPass) {
  std::mt19937_64 rng(8);
  std::vector<std::pair<double, double>> blocks = NoiseBlocks(&rng, 300);
  double mean_relative = 0;
  for (const double e : {4600.0, 1800.0, 1200.0, 140.0}) blocks.emplace_back(0.95 * e, e);
  for (const auto& [g, e] : blocks) mean_relative += g / e / double(blocks.size());
  EXPECT_LT(mean_relative, 0.05);  // the per-block-alike mean barely moves
  EXPECT_GT(BlockGainZ(blocks), 4);
}

TEST(BlockGainZTest, AThinEffectEverywherePasses) {
  std::mt19937_64 rng(9);
  std::vector<std::pair<double, double>> blocks = NoiseBlocks(&rng, 300);
  for (auto& [g, e] : blocks) g += 0.15 * e;  // 15 % of every block: about 8.7 standard errors
  EXPECT_GT(BlockGainZ(blocks), 4);
}

TEST(PhotoModelTest, LinearRadianceInvertsTheForwardModel) {
  recon::Camera cam;
  cam.width = 40;
  cam.height = 30;
  cam.params = {30, 30, 20, 15};
  cam.vignetting_k1 = -0.25;
  cam.vignetting_k2 = -0.05;
  recon::Photo photo;
  photo.exposure_scale = 1.3;
  photo.response_exponent = 0.8;
  photo.response_reference = 0.5;
  Image radiance(40, 30, 3);
  for (size_t i = 0; i < radiance.pixels.size(); ++i) radiance.pixels[i] = 0.01f * (i % 97 + 1);
  // Forward: the render carries vignetting, then scale and response.
  Image recorded = radiance;
  for (int y = 0; y < 30; ++y) {
    for (int x = 0; x < 40; ++x) {
      const double v = cam.VignettingFactor(Eigen::Vector2d(x + 0.5, y + 0.5));
      for (int c = 0; c < 3; ++c) recorded.at(x, y, c) *= float(v);
    }
  }
  solver::ApplyExposureAndResponse(photo, &recorded);
  const double v00 = cam.VignettingFactor(Eigen::Vector2d(0.5, 0.5));
  EXPECT_NEAR(recorded.at(0, 0, 0), 0.5 * std::pow(0.01 * 1.3 * v00 / 0.5, 0.8), 1e-6);
  const Image back = solver::LinearRadianceOfPhoto(photo, cam, recorded);
  for (size_t i = 0; i < back.pixels.size(); ++i) {
    ASSERT_NEAR(back.pixels[i], radiance.pixels[i], 1e-5 * radiance.pixels[i] + 1e-7);
  }
}

TEST(PhotoModelTest, HoldoutIsReproducibleAndHoldsTheFraction) {
  const solver::PixelHoldout h{0.25, 16, 7};
  int held = 0, total = 0;
  for (int p = 0; p < 4; ++p) {
    for (int y = 0; y < 480; y += 16) {
      for (int x = 0; x < 640; x += 16) {
        held += h.HeldOut(p, x, y);
        ++total;
        ASSERT_EQ(h.HeldOut(p, x, y), h.HeldOut(p, x + 15, y + 15));  // whole blocks
      }
    }
  }
  EXPECT_NEAR(double(held) / total, 0.25, 0.03);  // 4800 blocks: σ = 0.006
  EXPECT_FALSE(solver::PixelHoldout{}.HeldOut(0, 3, 3));
}

// A basis free of the render's noise (an ambient light's separately rendered response) against a
// noisy simulation, with the albedos refitted: the photo is the true radiance t (plus a little
// photo noise, and `effect` times the basis), the simulation t·(1 + 15 % noise) with its variance
// known, and the basis smooth and shaped like t. The plain fit trades the noisy sim for the
// noise-free basis and predicts a gain that is the render's noise alone; the noise-free fit
// predicts none, and finds a true effect's amplitude where the plain fit's is biased.
struct NoisySimRecords {
  std::vector<PixelRecord> records;
  std::vector<int> cells;
  std::vector<float> basis;
};

NoisySimRecords NoisySim(double effect, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::normal_distribution<double> n(0, 1);
  NoisySimRecords out;
  for (int i = 0; i < 40000; ++i) {
    PixelRecord r = RandomPixel(i % 4, rng);
    const int cell = i % 20;
    const double t = 0.5 + u(rng);  // the true radiance (before the effect)
    const float b = float(0.3 * t * (0.8 + 0.4 * std::sin(0.01 * i)));  // shaped like t
    for (int c = 0; c < 3; ++c) {
      r.sim[c] = float(t * (1 + 0.15 * n(rng)));
      r.sim_var[c] = float(t * t * 0.15 * 0.15);
      r.recorded[c] = float(t + effect * b + 0.01 * n(rng));
    }
    out.cells.push_back(cell);
    out.basis.push_back(b);
    out.records.push_back(r);
  }
  return out;
}

TEST(ResidualFitTest, ANoiseFreeBasisIsNotCreditedWithTheRendersNoise) {
  const NoisySimRecords none = NoisySim(0.0, 5);
  const ResidualFitter f(none.records, none.cells, 20, true, 16);
  const PixelRecord* first = none.records.data();
  auto basis = [&](const PixelRecord& r, int, double* b) { b[0] = none.basis[&r - first]; };
  const ResidualFit plain = f.Fit(1, basis);
  const ResidualFit corrected = f.FitNoiseFreeBasis(1, basis);
  ASSERT_EQ(plain.coef.size(), 1);
  ASSERT_EQ(corrected.coef.size(), 1);
  std::printf("no effect: plain gain %.3f (coef %.3f), noise-free gain %.4f (coef %.4f)\n",
              plain.Gain(), plain.coef[0], corrected.Gain(), corrected.coef[0]);
  EXPECT_GT(plain.Gain(), 0.05);  // the trap the correction removes
  EXPECT_LT(std::abs(corrected.Gain()), 0.01);
  EXPECT_LT(std::abs(corrected.coef[0]), 0.05);
  EXPECT_LT(corrected.z, 1.5);

  const NoisySimRecords some = NoisySim(0.2, 6);
  const ResidualFitter g(some.records, some.cells, 20, true, 16);
  const PixelRecord* base = some.records.data();
  const ResidualFit found = g.FitNoiseFreeBasis(
      1, [&](const PixelRecord& r, int, double* b) { b[0] = some.basis[&r - base]; });
  ASSERT_EQ(found.coef.size(), 1);
  std::printf("effect 0.2: noise-free coef %.4f, gain %.3f, z %.1f\n", found.coef[0], found.Gain(),
              found.z);
  EXPECT_NEAR(found.coef[0], 0.2, 0.03);
}

}  // namespace
}  // namespace igi::diagnose
