#pragma once
// Test helpers: Pearson's chi-square goodness-of-fit test of sampled directions against a density
// on a (θ, φ) histogram of the sphere, as pbrt's and Mitsuba's sampling tests do.

#include <Eigen/Core>
#include <functional>
#include <optional>
#include <vector>

#include "solver/render/sampling.h"

namespace igi::test {

// Nodes in (-1, 1) and weights of the n-point Gauss-Legendre rule.
void GaussLegendre(int n, std::vector<double>* nodes, std::vector<double>* weights);

// Regularised upper incomplete gamma function Q(a, x) = Γ(a, x)/Γ(a), a > 0, x >= 0.
double UpperIncompleteGammaQ(double a, double x);

struct ChiSquareResult {
  double statistic = 0.0;
  int dof = 0;
  double p_value = 1.0;
};
// Pearson's test of `observed` counts against `expected` counts (same total): bins expected to
// hold fewer than `min_expected` are pooled into one bin, which is kept if it reaches it.
// p_value = P(χ²_dof >= statistic); dof = bins kept - 1.
ChiSquareResult ChiSquareTest(const std::vector<double>& observed,
                              const std::vector<double>& expected, double min_expected = 5.0);

// Bins over θ in [0, theta_max] (from +z) and φ in [0, 2π); one last bin catches every direction
// beyond theta_max and every failed draw.
struct SphereHistogram {
  int n_theta = 20;
  int n_phi = 40;
  double theta_max = render::kPi;

  int NumBins() const { return n_theta * n_phi + 1; }
  int Bin(const std::optional<Eigen::Vector3d>& direction) const;
  // Probability of each bin under `pdf` (per steradian): Gauss-Legendre of `order`² nodes per
  // bin, all strictly inside it, so a density that jumps on a bin edge is integrated exactly as
  // well as a smooth one; the last bin gets 1 minus the rest.
  std::vector<double> Probabilities(const std::function<double(const Eigen::Vector3d&)>& pdf,
                                    int order = 8) const;
};

// Draws `num_samples` directions (nullopt = failed draw) and tests them against `pdf`.
ChiSquareResult TestDirections(
    const std::function<std::optional<Eigen::Vector3d>(render::Pcg32&)>& draw,
    const std::function<double(const Eigen::Vector3d&)>& pdf, const SphereHistogram& histogram,
    int num_samples, uint64_t seed);

// Per-test significance level that keeps the family-wise level at `overall` over `num_tests`
// independent tests (Šidák correction).
double SidakLevel(double overall, int num_tests);

// ∫ fn(ω) dω over θ in [0, theta_max], φ in [0, 2π) with composite Simpson on an
// n_theta (even) × n_phi grid in θ and the trapezoid rule in (periodic) φ.
double IntegrateSphere(const std::function<double(const Eigen::Vector3d&)>& fn, double theta_max,
                       int n_theta, int n_phi);

}  // namespace igi::test
