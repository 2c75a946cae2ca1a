#include "solver/render/sampling.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <optional>
#include <vector>

#include "chi_square.h"

namespace igi::render {
namespace {

using test::ChiSquareTest;
using test::IntegrateSphere;
using test::SidakLevel;
using test::SphereHistogram;
using test::TestDirections;

// Family-wise significance of the goodness-of-fit tests in this file. The seeds are fixed, so a
// test passes or fails deterministically; a correct warp fails one with probability <= 1%.
constexpr double kSignificance = 0.01;
constexpr int kNumSamples = 200000;

// ---- chi-square machinery -------------------------------------------------------------------

TEST(ChiSquareTest, IncompleteGammaReproducesTableCriticalValues) {
  // Critical values of χ² tables (e.g. NIST/SEMATECH e-Handbook §1.3.6.7.4), 4-5 digits given.
  struct Case {
    int dof;
    double x;
    double p;
  };
  for (const Case& c : {Case{1, 3.841, 0.05}, Case{10, 23.209, 0.01}, Case{100, 135.807, 0.01},
                        Case{5, 1.145, 0.95}, Case{30, 59.703, 0.001}}) {
    // Relative 1e-3: the table's 4-5 significant digits of x move p by that much.
    EXPECT_NEAR(test::UpperIncompleteGammaQ(0.5 * c.dof, 0.5 * c.x), c.p, 1e-3 * c.p + 1e-5)
        << "dof " << c.dof;
  }
}

TEST(ChiSquareTest, GaussLegendreIsExactForPolynomialsOfDegree2nMinus1) {
  std::vector<double> nodes;
  std::vector<double> weights;
  test::GaussLegendre(8, &nodes, &weights);
  double sum0 = 0.0;
  double sum14 = 0.0;
  double sum15 = 0.0;
  for (int i = 0; i < 8; ++i) {
    EXPECT_GT(nodes[i], -1.0);
    EXPECT_LT(nodes[i], 1.0);
    sum0 += weights[i];
    sum14 += weights[i] * std::pow(nodes[i], 14);
    sum15 += weights[i] * std::pow(nodes[i], 15);
  }
  EXPECT_NEAR(sum0, 2.0, 1e-14);
  EXPECT_NEAR(sum14, 2.0 / 15.0, 1e-14);
  EXPECT_NEAR(sum15, 0.0, 1e-14);
}

TEST(ChiSquareTest, RejectsADrawThatDoesNotMatchThePdf) {
  // Cosine-weighted draws tested against the uniform hemisphere density must fail clearly: the
  // power check that makes the passing tests below mean something.
  SphereHistogram histogram;
  const auto result = TestDirections(
      [](Pcg32& rng) { return std::optional(SampleCosineHemisphere(rng.Uniform2D())); },
      [](const Eigen::Vector3d& d) { return d.z() > 0.0 ? UniformHemispherePdf() : 0.0; },
      histogram, 20000, 1);
  EXPECT_LT(result.p_value, 1e-12);
}

// ---- PCG32 ----------------------------------------------------------------------------------

TEST(Pcg32Test, MatchesTheReferenceImplementation) {
  // pcg32-demo of the reference C library (pcg_basic), seed 42, stream 54; re-derived with an
  // independent Python transcription of pcg32_srandom_r/pcg32_random_r.
  Pcg32 rng(42, 54);
  for (uint32_t expected :
       {0xa15c02b7u, 0x7b47f409u, 0xba1d3330u, 0x83d2f293u, 0xbfa4784bu, 0xcbed606eu}) {
    EXPECT_EQ(rng.NextUInt32(), expected);
  }
}

TEST(Pcg32Test, UniformDoubleIsInUnitIntervalWithMeanOneHalf) {
  Pcg32 rng(3, 4);
  double sum = 0.0;
  constexpr int kN = 100000;
  for (int i = 0; i < kN; ++i) {
    const double u = rng.UniformDouble();
    ASSERT_GE(u, 0.0);
    ASSERT_LT(u, 1.0);
    sum += u;
  }
  // Standard error of the mean of U(0,1): sqrt(1/12/N) = 9.1e-4; 5 sigma.
  EXPECT_NEAR(sum / kN, 0.5, 5 * 9.1e-4);
}

// Runs `p_value_of_seed` for 100 seeds and checks that about 5% of them fall below 0.05, as a
// uniform generator gives: more than 15 happens with probability 7e-5 (binomial(100, 0.05)).
// Stronger than one test at a fixed seed, whose p-value may be small by chance.
void ExpectUniformPValues(const std::function<double(uint64_t)>& p_value_of_seed) {
  int below = 0;
  for (uint64_t seed = 0; seed < 100; ++seed) below += p_value_of_seed(seed) < 0.05 ? 1 : 0;
  EXPECT_LE(below, 15);
}

TEST(Pcg32Test, UniformUInt32IsUnbiased) {
  EXPECT_EQ(Pcg32(1, 1).UniformUInt32(1), 0u);
  for (uint32_t bound : {7u, 1000u}) {
    ExpectUniformPValues([bound](uint64_t seed) {
      Pcg32 rng(seed, 6);
      std::vector<double> observed(bound, 0.0);
      const int n = 50 * static_cast<int>(bound) + 1000;
      for (int i = 0; i < n; ++i) {
        const uint32_t v = rng.UniformUInt32(bound);
        if (v >= bound) return 0.0;
        observed[v] += 1.0;
      }
      const std::vector<double> expected(bound, static_cast<double>(n) / bound);
      return ChiSquareTest(observed, expected).p_value;
    });
  }
}

TEST(Pcg32Test, PixelSampleStreamsAreDeterministicAndIndependent) {
  Pcg32 a = PixelSampleRng(1, 2, 3);
  Pcg32 b = PixelSampleRng(1, 2, 3);
  for (int i = 0; i < 10; ++i) EXPECT_EQ(a.NextUInt32(), b.NextUInt32());
  EXPECT_NE(PixelSampleRng(1, 2, 3).NextUInt32(), PixelSampleRng(2, 2, 3).NextUInt32());
  // The first number over consecutive pixels (or samples) is uniform: no correlation between
  // neighbouring streams.
  for (bool by_pixel : {true, false}) {
    ExpectUniformPValues([by_pixel](uint64_t seed) {
      std::vector<double> observed(16, 0.0);
      constexpr int kN = 1600;
      for (int i = 0; i < kN; ++i) {
        Pcg32 rng = by_pixel ? PixelSampleRng(seed, i, 0) : PixelSampleRng(seed, 0, i);
        observed[rng.NextUInt32() >> 28u] += 1.0;
      }
      return ChiSquareTest(observed, std::vector<double>(16, kN / 16.0)).p_value;
    });
  }
}

// ---- frames ---------------------------------------------------------------------------------

void ExpectOrthonormalRightHanded(const Frame& f) {
  EXPECT_NEAR(f.t.norm(), 1.0, 1e-12);
  EXPECT_NEAR(f.b.norm(), 1.0, 1e-12);
  EXPECT_NEAR(f.t.dot(f.n), 0.0, 1e-12);
  EXPECT_NEAR(f.b.dot(f.n), 0.0, 1e-12);
  EXPECT_NEAR(f.t.dot(f.b), 0.0, 1e-12);
  EXPECT_NEAR((f.n.cross(f.t) - f.b).norm(), 0.0, 1e-12);  // b = n × t (docs/scene-format.md)
  EXPECT_NEAR((f.t.cross(f.b) - f.n).norm(), 0.0, 1e-12);
}

TEST(FrameTest, FromNormalIsOrthonormalEverywhere) {
  Pcg32 rng(11, 0);
  std::vector<Eigen::Vector3d> normals = {Eigen::Vector3d::UnitZ(), -Eigen::Vector3d::UnitZ(),
                                          Eigen::Vector3d::UnitX(), -Eigen::Vector3d::UnitY(),
                                          Eigen::Vector3d(1e-9, 0, -1).normalized()};
  for (int i = 0; i < 100; ++i) normals.push_back(SampleUniformSphere(rng.Uniform2D()));
  for (const auto& n : normals) {
    const Frame frame = Frame::FromNormal(n);
    ExpectOrthonormalRightHanded(frame);
    const Eigen::Vector3d v(0.3, -0.5, 0.7);
    EXPECT_NEAR((frame.ToWorld(frame.ToLocal(v)) - v).norm(), 0.0, 1e-12);
    EXPECT_NEAR((frame.ToLocal(n) - Eigen::Vector3d::UnitZ()).norm(), 0.0, 1e-12);
  }
}

TEST(FrameTest, FromNormalTangentKeepsTheTangentDirection) {
  const Eigen::Vector3d n = Eigen::Vector3d(0.2, -0.3, 0.9).normalized();
  const Eigen::Vector3d tangent(2.0, 0.5, 0.1);  // not unit, not orthogonal to n
  const Frame frame = Frame::FromNormalTangent(n, tangent);
  ExpectOrthonormalRightHanded(frame);
  const Eigen::Vector3d projected = (tangent - n * n.dot(tangent)).normalized();
  EXPECT_NEAR((frame.t - projected).norm(), 0.0, 1e-12);
  EXPECT_NEAR((frame.ToLocal(projected) - Eigen::Vector3d::UnitX()).norm(), 0.0, 1e-12);
  // A tangent along n, or zero, falls back to some valid frame around n.
  ExpectOrthonormalRightHanded(Frame::FromNormalTangent(n, 3.0 * n));
  ExpectOrthonormalRightHanded(Frame::FromNormalTangent(n, Eigen::Vector3d::Zero()));
  EXPECT_NEAR((Frame::FromNormalTangent(n, 3.0 * n).n - n).norm(), 0.0, 1e-15);
}

// ---- warps ----------------------------------------------------------------------------------

struct WarpCase {
  const char* name;
  std::function<std::optional<Eigen::Vector3d>(Pcg32&)> draw;
  std::function<double(const Eigen::Vector3d&)> pdf;
  double theta_max;  // histogram range: the support, so its edge is a bin edge
};

std::vector<WarpCase> DirectionWarps() {
  const Eigen::Vector3d point(0.5, -0.2, 0.1);
  const Eigen::Vector3d center(1.5, 0.8, 1.3);  // distance 1.84: cone half-angle 35°
  const Eigen::Vector3d inside(1.4, 0.9, 1.0);  // within the sphere
  constexpr double kRadius = 1.05;
  // The sphere seen from `point` is tested in a frame whose z axis points at its centre.
  const Frame axis = Frame::FromNormal((center - point).normalized());
  return {
      {"cosine_hemisphere",
       [](Pcg32& r) { return std::optional(SampleCosineHemisphere(r.Uniform2D())); },
       [](const Eigen::Vector3d& d) { return CosineHemispherePdf(d.z()); }, kPi / 2},
      {"uniform_hemisphere",
       [](Pcg32& r) { return std::optional(SampleUniformHemisphere(r.Uniform2D())); },
       [](const Eigen::Vector3d& d) { return d.z() > 0 ? UniformHemispherePdf() : 0.0; }, kPi / 2},
      {"uniform_sphere", [](Pcg32& r) { return std::optional(SampleUniformSphere(r.Uniform2D())); },
       [](const Eigen::Vector3d&) { return UniformSpherePdf(); }, kPi},
      {"cone_narrow", [](Pcg32& r) { return std::optional(SampleUniformCone(r.Uniform2D(), 0.8)); },
       [](const Eigen::Vector3d& d) { return d.z() >= 0.8 ? UniformConePdf(0.8) : 0.0; },
       std::acos(0.8)},
      {"cone_wide", [](Pcg32& r) { return std::optional(SampleUniformCone(r.Uniform2D(), -0.5)); },
       [](const Eigen::Vector3d& d) { return d.z() >= -0.5 ? UniformConePdf(-0.5) : 0.0; },
       std::acos(-0.5)},
      {"sphere_from_outside",
       [=](Pcg32& r) {
         return std::optional(
             axis.ToLocal(SampleSphereFromPoint(point, center, kRadius, r.Uniform2D()).direction));
       },
       [=](const Eigen::Vector3d& d) {
         return SphereFromPointPdf(point, center, kRadius, axis.ToWorld(d));
       },
       std::asin(kRadius / (center - point).norm())},
      {"sphere_from_inside",
       [=](Pcg32& r) {
         return std::optional(
             SampleSphereFromPoint(inside, center, kRadius, r.Uniform2D()).direction);
       },
       [=](const Eigen::Vector3d& d) { return SphereFromPointPdf(inside, center, kRadius, d); },
       kPi},
  };
}

TEST(WarpTest, DirectionsAreUnitAndMatchTheirPdf) {
  const std::vector<WarpCase> warps = DirectionWarps();
  for (size_t i = 0; i < warps.size(); ++i) {
    const WarpCase& warp = warps[i];
    Pcg32 rng(21, i);
    for (int k = 0; k < 1000; ++k) EXPECT_NEAR(warp.draw(rng)->norm(), 1.0, 1e-12) << warp.name;
    // 20 × 40 bins over the support; anything beyond it lands in the last bin (expected 0).
    const SphereHistogram histogram{20, 40, warp.theta_max};
    const auto result = TestDirections(warp.draw, warp.pdf, histogram, kNumSamples, 100 + i);
    EXPECT_GT(result.p_value, SidakLevel(kSignificance, static_cast<int>(warps.size())))
        << warp.name << ": chi2 " << result.statistic << " dof " << result.dof;
  }
}

TEST(WarpTest, DirectionPdfsIntegrateToOne) {
  // Simpson (θ) × trapezoid (φ) on a 400 × 64 grid, over the support only so the integrand is
  // smooth: error < 1e-8 for these trigonometric integrands; tolerance 1e-6.
  auto integrate = [](const std::function<double(const Eigen::Vector3d&)>& pdf, double theta) {
    return IntegrateSphere(pdf, theta, 400, 64);
  };
  EXPECT_NEAR(integrate([](const auto& d) { return CosineHemispherePdf(d.z()); }, kPi / 2), 1.0,
              1e-6);
  EXPECT_NEAR(integrate([](const auto&) { return UniformHemispherePdf(); }, kPi / 2), 1.0, 1e-6);
  EXPECT_NEAR(integrate([](const auto&) { return UniformSpherePdf(); }, kPi), 1.0, 1e-6);
  EXPECT_NEAR(integrate([](const auto&) { return UniformConePdf(0.8); }, std::acos(0.8)), 1.0,
              1e-6);
  // A sphere straight up the z axis from the origin: its cone is θ <= asin(r/d).
  const Eigen::Vector3d center(0, 0, 4);
  EXPECT_NEAR(integrate(
                  [&](const Eigen::Vector3d& d) {
                    return SphereFromPointPdf(Eigen::Vector3d::Zero(), center, 1.0, d);
                  },
                  std::asin(0.25) * (1 - 1e-12)),
              1.0, 1e-6);
  // A tiny, distant sphere keeps its pdf accurate (1 - cosθmax computed without cancellation).
  const double tiny = 1e-5;
  const double pdf = SphereFromPointPdf(Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, 10), tiny,
                                        Eigen::Vector3d::UnitZ());
  const double solid_angle = kPi * tiny * tiny / 100.0;  // small-angle limit, relative 1e-12
  EXPECT_NEAR(pdf * solid_angle, 1.0, 1e-9);
}

TEST(WarpTest, SphereSamplesLandOnTheSphere) {
  const Eigen::Vector3d center(1.5, 0.8, 1.3);
  constexpr double kRadius = 1.05;
  Pcg32 rng(31, 0);
  for (const Eigen::Vector3d& point :
       {Eigen::Vector3d(0.5, -0.2, 0.1), Eigen::Vector3d(1.4, 0.9, 1.0), center}) {
    for (int i = 0; i < 1000; ++i) {
      const SphereSample s = SampleSphereFromPoint(point, center, kRadius, rng.Uniform2D());
      EXPECT_NEAR((point + s.distance * s.direction - center).norm(), kRadius, 1e-9);
      EXPECT_GT(s.distance, 0.0);
      EXPECT_DOUBLE_EQ(s.pdf, SphereFromPointPdf(point, center, kRadius, s.direction));
    }
  }
  // From outside, the near surface: nothing of the sphere lies closer along the direction.
  const Eigen::Vector3d outside(0.5, -0.2, 0.1);
  const SphereSample s = SampleSphereFromPoint(outside, center, kRadius, {0.3, 0.6});
  EXPECT_LT(s.distance, s.direction.dot(center - outside));
  // Directions missing the sphere (away from it) have pdf 0.
  EXPECT_EQ(SphereFromPointPdf(outside, center, kRadius, -(center - outside).normalized()), 0.0);
  EXPECT_EQ(SphereFromPointPdf(outside, center, kRadius, Eigen::Vector3d(1, -1, 0).normalized()),
            0.0);
}

TEST(WarpTest, SinCosPolynomialsMatchLibm) {
  // The warps' own sin/cos replace libm's: they must agree with it to within a few ulp of 1
  // (4e-16: the Taylor remainder is below 5e-17 and each Horner step rounds once), over the
  // reduced range and over whole turns, including the quadrant and octant boundaries.
  constexpr double kTolerance = 4e-16;
  Pcg32 rng(43, 0);
  for (int i = 0; i < 100000; ++i) {
    const double a = (2.0 * rng.UniformDouble() - 1.0) * 0.25 * kPi;
    double s, c;
    SinCosQuarterPi(a, &s, &c);
    ASSERT_NEAR(s, std::sin(a), kTolerance) << a;
    ASSERT_NEAR(c, std::cos(a), kTolerance) << a;
  }
  std::vector<double> turns = {0.0, 0.125, 0.25, 0.375, 0.5, 0.625, 0.75, 0.875, 1.0, 1.3, -0.2};
  for (double edge : {0.0, 0.25, 0.5, 0.75, 1.0}) {
    turns.push_back(edge - 0x1p-32);
    turns.push_back(edge + 0x1p-32);
  }
  for (int i = 0; i < 100000; ++i) turns.push_back(rng.UniformDouble());
  for (double u : turns) {
    double s, c;
    SinCos2Pi(u, &s, &c);
    ASSERT_NEAR(s, std::sin(2.0 * kPi * u), kTolerance * 4) << u;  // 2πu itself rounds
    ASSERT_NEAR(c, std::cos(2.0 * kPi * u), kTolerance * 4) << u;
  }
}

TEST(WarpTest, ConcentricDiskStaysInTheDisk) {
  Pcg32 rng(41, 0);
  for (int i = 0; i < 10000; ++i) {
    EXPECT_LE(SampleUniformDiskConcentric(rng.Uniform2D()).norm(), 1.0 + 1e-15);
  }
  EXPECT_EQ(SampleUniformDiskConcentric({0.5, 0.5}).norm(), 0.0);
}

TEST(WarpTest, TriangleSamplesAreUniform) {
  // Grid of n × n cells over (w1, w2): cells with i + j < n - 1 lie inside the triangle w1 + w2
  // <= 1 (probability 2/n² each), cells with i + j = n - 1 are cut in half by it (1/n²), the
  // rest are empty.
  constexpr int kN = 16;
  std::vector<double> observed(kN * kN, 0.0);
  std::vector<double> expected(kN * kN, 0.0);
  Pcg32 rng(51, 0);
  for (int s = 0; s < kNumSamples; ++s) {
    const Eigen::Vector3d w = SampleUniformTriangle(rng.Uniform2D());
    ASSERT_NEAR(w.sum(), 1.0, 1e-15);
    ASSERT_GE(w.minCoeff(), 0.0);
    const int i = std::min(kN - 1, static_cast<int>(w[1] * kN));
    const int j = std::min(kN - 1, static_cast<int>(w[2] * kN));
    observed[i * kN + j] += 1.0;
  }
  for (int i = 0; i < kN; ++i) {
    for (int j = 0; j < kN; ++j) {
      const double p = i + j < kN - 1 ? 2.0 : (i + j == kN - 1 ? 1.0 : 0.0);
      expected[i * kN + j] = p / (kN * kN) * kNumSamples;
    }
  }
  EXPECT_GT(ChiSquareTest(observed, expected).p_value, kSignificance);
}

TEST(MisTest, HeuristicsWeighStrategies) {
  EXPECT_DOUBLE_EQ(PowerHeuristic(1, 1.0, 1, 1.0), 0.5);
  EXPECT_DOUBLE_EQ(PowerHeuristic(1, 2.0, 1, 1.0), 0.8);  // 4 / (4 + 1)
  EXPECT_DOUBLE_EQ(PowerHeuristic(1, 2.0, 1, 1.0) + PowerHeuristic(1, 1.0, 1, 2.0), 1.0);
  EXPECT_DOUBLE_EQ(PowerHeuristic(2, 1.0, 1, 1.0), 0.8);  // counts multiply the densities
  EXPECT_DOUBLE_EQ(PowerHeuristic(1, INFINITY, 1, 5.0), 1.0);
  EXPECT_DOUBLE_EQ(PowerHeuristic(1, 0.0, 1, 0.0), 0.0);
  EXPECT_DOUBLE_EQ(PowerHeuristic(1, 3.0, 1, 0.0), 1.0);
  EXPECT_DOUBLE_EQ(BalanceHeuristic(1, 3.0, 1, 1.0), 0.75);
}

}  // namespace
}  // namespace igi::render

// The solver's fit samples are drawn with InHashedSubset: the kept share must be right and even
// over any pattern in the keys (the regular stride it replaced kept one phase of a period-14
// pattern only, which aliased with the demo floor's texture: its faint lobe's ρs −17 %).
TEST(HashedSubsetTest, KeepsTheShareEvenlyOverAPeriodicPattern) {
  constexpr int kKeys = 140000, kPeriod = 14;
  const double p = 4000.0 / kKeys;
  std::array<int, kPeriod> per_phase{};
  int kept = 0;
  for (int i = 0; i < kKeys; ++i) {
    const bool in = igi::render::InHashedSubset(uint64_t(i), p);
    EXPECT_EQ(in, igi::render::InHashedSubset(uint64_t(i), p));  // reproducible
    if (in) ++kept, ++per_phase[i % kPeriod];
  }
  EXPECT_NEAR(kept, 4000, 4 * std::sqrt(4000.0));
  const double expected = 4000.0 / kPeriod;
  for (int phase = 0; phase < kPeriod; ++phase) {
    EXPECT_NEAR(per_phase[phase], expected, 5 * std::sqrt(expected)) << "phase " << phase;
  }
  EXPECT_TRUE(igi::render::InHashedSubset(7, 1.0));
  EXPECT_FALSE(igi::render::InHashedSubset(7, 0.0));
}
