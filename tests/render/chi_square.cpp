#include "chi_square.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace igi::test {
namespace {

// Simpson weight of node i of a composite rule with n (even) intervals.
double SimpsonWeight(int i, int n) {
  if (i == 0 || i == n) return 1.0;
  return (i % 2 == 1) ? 4.0 : 2.0;
}

Eigen::Vector3d Direction(double theta, double phi) {
  return {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
}

// Σ_k x^k/((a+1)…(a+k)), the series of the lower function: P(a,x) = x^a e^-x/Γ(a+1) · Σ.
double LowerSeries(double a, double x) {
  double term = 1.0;
  double sum = 1.0;
  for (int k = 1; k < 10000; ++k) {
    term *= x / (a + k);
    sum += term;
    if (term < sum * 1e-16) break;
  }
  return sum;
}

// Continued fraction of Γ(a,x) e^x x^-a = 1/(x+1-a- 1(1-a)/(x+3-a- 2(2-a)/(x+5-a- …))),
// evaluated with Lentz's method.
double UpperFraction(double a, double x) {
  constexpr double kTiny = 1e-300;
  double b = x + 1.0 - a;
  double c = 1.0 / kTiny;
  double d = 1.0 / b;
  double value = d;
  for (int k = 1; k < 10000; ++k) {
    const double an = -k * (k - a);
    b += 2.0;
    d = an * d + b;
    d = 1.0 / (std::abs(d) < kTiny ? kTiny : d);
    c = b + an / c;
    if (std::abs(c) < kTiny) c = kTiny;
    const double delta = c * d;
    value *= delta;
    if (std::abs(delta - 1.0) < 1e-16) break;
  }
  return value;
}

}  // namespace

void GaussLegendre(int n, std::vector<double>* nodes, std::vector<double>* weights) {
  nodes->assign(n, 0.0);
  weights->assign(n, 0.0);
  for (int i = 0; i < n; ++i) {
    // Newton's method on P_n from the Chebyshev-like first guess; P_n and P_n' by recurrence.
    double x = std::cos(render::kPi * (i + 0.75) / (n + 0.5));
    double derivative = 1.0;
    for (int iteration = 0; iteration < 100; ++iteration) {
      double p0 = 1.0;
      double p1 = x;
      for (int k = 2; k <= n; ++k) {
        const double p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      derivative = n * (x * p1 - p0) / (x * x - 1.0);
      const double step = p1 / derivative;
      x -= step;
      if (std::abs(step) < 1e-15) break;
    }
    (*nodes)[i] = x;
    (*weights)[i] = 2.0 / ((1.0 - x * x) * derivative * derivative);
  }
}

double UpperIncompleteGammaQ(double a, double x) {
  if (x <= 0.0) return 1.0;
  const double log_prefactor = a * std::log(x) - x - std::lgamma(a);
  if (x < a + 1.0) {
    return 1.0 - std::exp(log_prefactor - std::log(a)) * LowerSeries(a, x);
  }
  return std::exp(log_prefactor) * UpperFraction(a, x);
}

ChiSquareResult ChiSquareTest(const std::vector<double>& observed,
                              const std::vector<double>& expected, double min_expected) {
  ChiSquareResult result;
  double pooled_observed = 0.0;
  double pooled_expected = 0.0;
  int bins = 0;
  for (size_t i = 0; i < observed.size(); ++i) {
    if (expected[i] < min_expected) {
      pooled_observed += observed[i];
      pooled_expected += expected[i];
      continue;
    }
    const double diff = observed[i] - expected[i];
    result.statistic += diff * diff / expected[i];
    ++bins;
  }
  if (pooled_expected >= min_expected) {
    const double diff = pooled_observed - pooled_expected;
    result.statistic += diff * diff / pooled_expected;
    ++bins;
  } else if (pooled_observed > min_expected + 6.0 * std::sqrt(min_expected) + 6.0) {
    // Far more draws than a Poisson count of mean < min_expected gives (P < 1e-8): the draws
    // land where the density says (almost) none can.
    result.statistic = std::numeric_limits<double>::infinity();
  }
  result.dof = std::max(1, bins - 1);
  result.p_value = std::isinf(result.statistic)
                       ? 0.0
                       : UpperIncompleteGammaQ(0.5 * result.dof, 0.5 * result.statistic);
  return result;
}

int SphereHistogram::Bin(const std::optional<Eigen::Vector3d>& direction) const {
  const int other = n_theta * n_phi;
  if (!direction) return other;
  const Eigen::Vector3d& d = *direction;
  const double theta = std::acos(std::clamp(d.z(), -1.0, 1.0));
  if (theta >= theta_max) return other;
  double phi = std::atan2(d.y(), d.x());
  if (phi < 0.0) phi += 2.0 * render::kPi;
  const int i = std::min(n_theta - 1, static_cast<int>(theta / theta_max * n_theta));
  const int j = std::min(n_phi - 1, static_cast<int>(phi / (2.0 * render::kPi) * n_phi));
  return i * n_phi + j;
}

std::vector<double> SphereHistogram::Probabilities(
    const std::function<double(const Eigen::Vector3d&)>& pdf, int order) const {
  std::vector<double> nodes;
  std::vector<double> weights;
  GaussLegendre(order, &nodes, &weights);
  std::vector<double> probabilities(NumBins(), 0.0);
  const double d_theta = theta_max / n_theta;
  const double d_phi = 2.0 * render::kPi / n_phi;
  double total = 0.0;
  for (int i = 0; i < n_theta; ++i) {
    for (int j = 0; j < n_phi; ++j) {
      double sum = 0.0;
      for (int a = 0; a < order; ++a) {
        const double theta = (i + 0.5 + 0.5 * nodes[a]) * d_theta;
        const double wa = weights[a] * std::sin(theta);
        for (int b = 0; b < order; ++b) {
          const double phi = (j + 0.5 + 0.5 * nodes[b]) * d_phi;
          sum += wa * weights[b] * pdf(Direction(theta, phi));
        }
      }
      const double p = sum * 0.25 * d_theta * d_phi;
      probabilities[i * n_phi + j] = p;
      total += p;
    }
  }
  probabilities.back() = std::max(0.0, 1.0 - total);
  return probabilities;
}

ChiSquareResult TestDirections(
    const std::function<std::optional<Eigen::Vector3d>(render::Pcg32&)>& draw,
    const std::function<double(const Eigen::Vector3d&)>& pdf, const SphereHistogram& histogram,
    int num_samples, uint64_t seed) {
  render::Pcg32 rng(seed, 7);
  std::vector<double> observed(histogram.NumBins(), 0.0);
  for (int s = 0; s < num_samples; ++s) observed[histogram.Bin(draw(rng))] += 1.0;
  std::vector<double> expected = histogram.Probabilities(pdf);
  for (double& e : expected) e *= num_samples;
  return ChiSquareTest(observed, expected);
}

double SidakLevel(double overall, int num_tests) {
  return 1.0 - std::pow(1.0 - overall, 1.0 / num_tests);
}

double IntegrateSphere(const std::function<double(const Eigen::Vector3d&)>& fn, double theta_max,
                       int n_theta, int n_phi) {
  const double h_theta = theta_max / n_theta;
  const double h_phi = 2.0 * render::kPi / n_phi;
  double sum = 0.0;
  for (int a = 0; a <= n_theta; ++a) {
    const double theta = a * h_theta;
    const double wa = SimpsonWeight(a, n_theta) * std::sin(theta);
    if (wa == 0.0) continue;
    // φ is periodic: the trapezoid rule (equal weights) is spectrally accurate.
    double row = 0.0;
    for (int b = 0; b < n_phi; ++b) row += fn(Direction(theta, b * h_phi));
    sum += wa * row;
  }
  return sum * h_theta / 3.0 * h_phi;
}

}  // namespace igi::test
