#include "calib/robertson.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>

#include "tools/common/error.h"

namespace igi::calib {
namespace {

// Robertson's certainty weight: a Gaussian bump over the level range, 0 where unusable.
std::vector<double> Weights(int levels, const ResponseOptions& options) {
  std::vector<double> w(static_cast<size_t>(levels));
  const double mid = 0.5 * (levels - 1);
  for (int z = 0; z < levels; ++z) {
    const double v = double(z) / (levels - 1);
    const double d = (z - mid) / mid;
    w[size_t(z)] = (v <= options.black || v >= options.saturated) ? 0.0 : std::exp(-4.0 * d * d);
  }
  return w;
}

// Levels of a regular subsample of pixels: [pixel][image].
std::vector<std::vector<int>> SubsampleLevels(const Bracket& bracket, int channel, int levels,
                                              int max_pixels) {
  const int64_t total = int64_t(bracket.width()) * bracket.height();
  const int stride = std::max(1, int(std::ceil(std::sqrt(double(total) / max_pixels))));
  std::vector<std::vector<int>> out;
  for (int y = stride / 2; y < bracket.height(); y += stride) {
    for (int x = stride / 2; x < bracket.width(); x += stride) {
      std::vector<int> z;
      for (const Image& image : bracket.images) {
        z.push_back(int(std::lround(image.at(x, y, channel) * (levels - 1))));
      }
      out.push_back(std::move(z));
    }
  }
  return out;
}

// Whittaker smoother: argmin_g sum_k c_k (y_k - g_k)^2 + mu sum_k (g_{k-1} - 2 g_k + g_{k+1})^2.
// Removes the sawtooth that a bracket with one constant exposure ratio leaves undetermined
// (any ln I periodic in ln exposure with that ratio fits the data equally well).
std::vector<double> Smooth(const std::vector<double>& y, const std::vector<double>& c, double mu) {
  const int n = int(y.size());
  std::vector<Eigen::Triplet<double>> triplets;
  Eigen::VectorXd rhs(n);
  for (int k = 0; k < n; ++k) {
    triplets.emplace_back(k, k, c[size_t(k)] + 1e-9);
    rhs(k) = c[size_t(k)] * y[size_t(k)];
  }
  for (int k = 1; k < n - 1; ++k) {
    const int idx[3] = {k - 1, k, k + 1};
    const double coef[3] = {1.0, -2.0, 1.0};
    for (int r = 0; r < 3; ++r) {
      for (int q = 0; q < 3; ++q) triplets.emplace_back(idx[r], idx[q], mu * coef[r] * coef[q]);
    }
  }
  Eigen::SparseMatrix<double> a(n, n);
  a.setFromTriplets(triplets.begin(), triplets.end());
  const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(a);
  const Eigen::VectorXd g = solver.solve(rhs);
  return std::vector<double>(g.data(), g.data() + n);
}

}  // namespace

namespace {

// One Robertson iteration: radiances given I, then I given the radiances (the mean of E_i t_j
// over the samples at each level), optionally smoothed, normalised to I(middle) = 1. Returns the
// RMS change of ln I; `count` gets the samples per level.
double Iterate(const std::vector<std::vector<int>>& z, const std::vector<double>& t,
               const std::vector<double>& w, const ResponseOptions& options,
               std::vector<double>* inv, std::vector<int>* count) {
  const size_t levels = inv->size();
  std::vector<double> radiance(z.size());
  for (size_t i = 0; i < z.size(); ++i) {
    double num = 0.0, den = 0.0;
    for (size_t j = 0; j < t.size(); ++j) {
      const double wz = w[size_t(z[i][j])];
      num += wz * t[j] * (*inv)[size_t(z[i][j])];
      den += wz * t[j] * t[j];
    }
    radiance[i] = den > 0.0 ? num / den : -1.0;
  }
  std::vector<double> sum(levels, 0.0);
  std::fill(count->begin(), count->end(), 0);
  for (size_t i = 0; i < z.size(); ++i) {
    if (radiance[i] < 0.0) continue;
    for (size_t j = 0; j < t.size(); ++j) {
      sum[size_t(z[i][j])] += radiance[i] * t[j];
      ++(*count)[size_t(z[i][j])];
    }
  }
  std::vector<double> next = *inv;
  for (size_t k = 0; k < levels; ++k) {
    if ((*count)[k] > 0) next[k] = sum[k] / (*count)[k];
  }
  if (options.robertson_smoothing > 0.0) {
    // Smooth ln I with weights from the counts and certainties of the levels.
    std::vector<double> y(levels), cw(levels);
    double total = 0.0;
    for (size_t k = 0; k < levels; ++k) {
      y[k] = std::log(std::max(next[k], 1e-12));
      cw[k] = (*count)[k] * w[k];  // unusable levels: no data
      total += cw[k];
    }
    for (double& ck : cw) ck *= double(levels) / std::max(total, 1e-12);
    const double scale = std::pow((double(levels) - 1) / 255.0, 4);
    const double mu = options.robertson_smoothing * options.robertson_smoothing * scale;
    const std::vector<double> smooth = Smooth(y, cw, mu);
    for (size_t k = 0; k < levels; ++k) next[k] = std::exp(smooth[k]);
  }
  const double mid = next[levels / 2];
  double sq = 0.0;
  for (size_t k = 0; k < levels; ++k) {
    next[k] /= mid;
    const double d = std::log(std::max(next[k], 1e-12)) - std::log(std::max((*inv)[k], 1e-12));
    sq += d * d;
  }
  *inv = std::move(next);
  return std::sqrt(sq / double(levels));
}

}  // namespace

ResponseSummary RecoverRobertson(const Bracket& bracket, const ResponseOptions& options,
                                 int levels) {
  const std::vector<double> w = Weights(levels, options);
  ResponseSummary summary;
  summary.curve.method = ResponseRecoveryMethodName(ResponseRecoveryMethod::kRobertson);
  summary.curve.levels = levels;
  summary.curve.channels = DefaultChannelNames(bracket.channels());
  for (int c = 0; c < bracket.channels(); ++c) {
    const auto z = SubsampleLevels(bracket, c, levels, options.max_robertson_pixels);
    summary.samples = int(z.size());
    std::vector<double> inv(static_cast<size_t>(levels));  // I(z), linear start
    for (int k = 0; k < levels; ++k) inv[size_t(k)] = (k + 0.5) / (0.5 * levels);
    std::vector<int> count(static_cast<size_t>(levels));
    int iteration = 0;
    double change = 1e30;
    for (; iteration < options.max_iterations && change > options.tolerance; ++iteration) {
      change = Iterate(z, bracket.exposures_s, w, options, &inv, &count);
    }
    summary.iterations = std::max(summary.iterations, iteration);
    summary.converged = summary.converged && change <= options.tolerance;
    int used = 0;
    for (int k = 0; k < levels; ++k) used += (count[size_t(k)] > 0 && w[size_t(k)] > 0) ? 1 : 0;
    if (used < levels / 4) {
      throw InputError(DescribeProblem(
          bracket.names.front(), fmt::format("channel {}", c),
          fmt::format("{} of {} levels observed", used, levels),
          "too few usable pixels: Robertson needs values neither black nor saturated over at "
          "least a quarter of the levels"));
    }
    std::vector<double> g(static_cast<size_t>(levels));
    for (int k = 0; k < levels; ++k) g[size_t(k)] = std::log(std::max(inv[size_t(k)], 1e-12));
    for (size_t k = 1; k < g.size(); ++k) g[k] = std::max(g[k], g[k - 1]);
    summary.curve.g.push_back(std::move(g));
  }
  summary.equations = summary.samples * int(bracket.exposures_s.size());
  spdlog::info("robertson: {} pixels, {} iterations{}", summary.samples, summary.iterations,
               summary.converged ? "" : " (not converged)");
  return summary;
}

}  // namespace igi::calib
