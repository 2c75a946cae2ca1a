#include "calib/response_recovery.h"

#include <Eigen/Sparse>
#include <Eigen/SparseQR>
#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "calib/pixel_sampling.h"
#include "calib/robertson.h"
#include "tools/common/error.h"
#include "tools/common/strings.h"

namespace igi::calib {
namespace {

// Debevec's hat weight on a continuous level z in [0, levels - 1], peak 1, never 0.
double HatWeight(double z, int levels) {
  const double half = 0.5 * levels;
  return (z < half ? z + 1.0 : double(levels) - z) / half;
}

int ResolveLevels(const Bracket& bracket, const ResponseOptions& options) {
  if (options.levels > 0) return options.levels;
  return bracket.bits_per_sample == 8 ? 256 : 1024;
}

void MakeMonotonic(std::vector<double>* g) {
  for (size_t z = 1; z < g->size(); ++z) (*g)[z] = std::max((*g)[z], (*g)[z - 1]);
}

std::string ImagesLabel(const Bracket& bracket) {
  return bracket.names.size() > 1
             ? fmt::format("{} … {}", bracket.names.front(), bracket.names.back())
             : bracket.names.front();
}

// Independent equations: per sample, usable values beyond the first.
int CountEquations(const Bracket& bracket, const std::vector<int64_t>& pixels, int channel,
                   const ResponseOptions& options) {
  int total = 0;
  for (int64_t p : pixels) {
    int usable = 0;
    for (const Image& image : bracket.images) {
      const float v = image.pixels[size_t(p) * image.channels + channel];
      usable += (v > options.black && v < options.saturated) ? 1 : 0;
    }
    total += std::max(usable - 1, 0);
  }
  return total;
}

void CheckEnoughEquations(const Bracket& bracket, int equations, int levels, int channel) {
  const int needed = levels / 2;
  if (equations < needed) {
    throw InputError(DescribeProblem(
        ImagesLabel(bracket), fmt::format("channel {}", channel),
        fmt::format("{} usable equations", equations),
        fmt::format("too few usable pixels: need at least {} equations from sample values "
                    "neither black nor saturated (Debevec–Malik: N(P-1) > levels)",
                    needed)));
  }
}

std::vector<double> SolveDebevecChannel(const Bracket& bracket,
                                        const std::vector<int64_t>& pixels, int channel,
                                        int levels, const ResponseOptions& options,
                                        double* rms) {
  const int n = int(pixels.size());
  const int p = int(bracket.images.size());
  const int unknowns = levels + n;
  std::vector<Eigen::Triplet<double>> triplets;
  std::vector<double> rhs;
  int row = 0;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < p; ++j) {
      const Image& image = bracket.images[size_t(j)];
      const double z = image.pixels[size_t(pixels[size_t(i)]) * image.channels + channel] *
                       double(levels - 1);
      const int k = std::min(int(z), levels - 2);
      const double a = z - k;
      const double w = HatWeight(z, levels);
      triplets.emplace_back(row, k, w * (1.0 - a));
      triplets.emplace_back(row, k + 1, w * a);
      triplets.emplace_back(row, levels + i, -w);
      rhs.push_back(w * std::log(bracket.exposures_s[size_t(j)]));
      ++row;
    }
  }
  // Smoothness: lambda * w(z) * (g(z-1) - 2 g(z) + g(z+1)), scaled so lambda keeps its meaning
  // (curvature per 8-bit level, total weight of the term) whatever the number of levels.
  const double scale = std::pow((levels - 1) / 255.0, 2) * std::sqrt(256.0 / levels);
  for (int z = 1; z < levels - 1; ++z) {
    const double w = options.lambda * HatWeight(z, levels) * scale;
    triplets.emplace_back(row, z - 1, w);
    triplets.emplace_back(row, z, -2.0 * w);
    triplets.emplace_back(row, z + 1, w);
    rhs.push_back(0.0);
    ++row;
  }
  triplets.emplace_back(row, levels / 2, 1.0);  // g(middle) = 0 fixes the free constant
  rhs.push_back(0.0);
  ++row;
  Eigen::SparseMatrix<double> a(row, unknowns);
  a.setFromTriplets(triplets.begin(), triplets.end());
  a.makeCompressed();
  const Eigen::Map<const Eigen::VectorXd> b(rhs.data(), row);
  Eigen::SparseQR<Eigen::SparseMatrix<double>, Eigen::COLAMDOrdering<int>> qr(a);
  if (qr.info() != Eigen::Success) throw Error("Debevec least squares: factorisation failed");
  const Eigen::VectorXd x = qr.solve(b);
  std::vector<double> g(x.data(), x.data() + levels);
  // Residual RMS over the usable data equations, in ln units (unweighted).
  double sum = 0.0;
  int count = 0;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < p; ++j) {
      const Image& image = bracket.images[size_t(j)];
      const float v = image.pixels[size_t(pixels[size_t(i)]) * image.channels + channel];
      if (v <= options.black || v >= options.saturated) continue;
      const double z = v * double(levels - 1);
      const int k = std::min(int(z), levels - 2);
      const double gz = (1.0 - (z - k)) * x[k] + (z - k) * x[k + 1];
      const double r = gz - x[levels + i] - std::log(bracket.exposures_s[size_t(j)]);
      sum += r * r;
      ++count;
    }
  }
  *rms = count > 0 ? std::sqrt(sum / count) : 0.0;
  MakeMonotonic(&g);
  return g;
}

}  // namespace

void ResponseOptions::Validate() const {
  ProblemList problems;
  if (method != "debevec" && method != "robertson") {
    problems.Add("--method", "", method, "must be debevec or robertson");
  }
  if (!(lambda >= 0.0) || !std::isfinite(lambda)) {
    problems.Add("--lambda", "", fmt::format("{}", lambda), "must be >= 0");
  }
  if (levels != 0 && (levels < 16 || levels > 65536)) {
    problems.Add("--levels", "", fmt::format("{}", levels), "must be 0 (auto) or 16..65536");
  }
  if (samples < 0) problems.Add("--samples", "", fmt::format("{}", samples), "must be >= 0");
  if (!(black >= 0.0 && black < saturated && saturated <= 1.0)) {
    problems.Add("--black/--saturated", "", fmt::format("{}/{}", black, saturated),
                 "need 0 <= black < saturated <= 1");
  }
  if (max_iterations < 1) {
    problems.Add("--max-iterations", "", fmt::format("{}", max_iterations), "must be >= 1");
  }
  problems.ThrowIfAny();
}


ResponseSummary RecoverResponse(const Bracket& bracket, const ResponseOptions& options) {
  options.Validate();
  const int levels = ResolveLevels(bracket, options);
  if (options.method == "robertson") return RecoverRobertson(bracket, options, levels);
  const int p = int(bracket.images.size());
  SamplingOptions sampling;
  sampling.samples = options.samples > 0
                         ? options.samples
                         : std::min(4000, std::max(100, 3 * levels / std::max(p - 1, 1)));
  sampling.black = options.black;
  sampling.saturated = options.saturated;
  const std::vector<int64_t> pixels = SelectSamplePixels(bracket, sampling);
  ResponseSummary summary;
  summary.samples = int(pixels.size());
  summary.equations = 1 << 30;
  summary.curve.method = "debevec";
  summary.curve.levels = levels;
  summary.curve.channels = DefaultChannelNames(bracket.channels());
  for (int c = 0; c < bracket.channels(); ++c) {
    const int equations = CountEquations(bracket, pixels, c, options);
    CheckEnoughEquations(bracket, equations, levels, c);
    summary.equations = std::min(summary.equations, equations);
    double rms = 0.0;
    summary.curve.g.push_back(SolveDebevecChannel(bracket, pixels, c, levels, options, &rms));
    summary.rms_residual.push_back(rms);
  }
  spdlog::info("debevec: {} samples, {} equations, lambda {}, rms {:.4f}", summary.samples,
               summary.equations, options.lambda, summary.rms_residual.front());
  return summary;
}

}  // namespace igi::calib
