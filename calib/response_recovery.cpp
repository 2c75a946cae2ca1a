#include "calib/response_recovery.h"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>

#include "calib/pixel_sampling.h"
#include "calib/robertson.h"
#include "tools/common/enum_names.h"
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

// Makes g non-decreasing outward from the middle level (where the gauge holds g at 0, inside the
// data): a running maximum above it, a running minimum below it. Levels without data hold only the
// smoothness term's extrapolation, which can swing far; a running maximum from level 0 would carry
// such a swing at the dark end across the whole curve, anchored in the middle it only flattens the
// empty end.
void MakeMonotonic(std::vector<double>* g) {
  const size_t middle = g->size() / 2;
  for (size_t z = middle + 1; z < g->size(); ++z) (*g)[z] = std::max((*g)[z], (*g)[z - 1]);
  for (size_t z = middle; z-- > 0;) (*g)[z] = std::min((*g)[z], (*g)[z + 1]);
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

// One data equation w * (g(z) - ln E_i - ln t_j) = 0 with g(z) interpolated between levels
// k and k + 1 (fraction a).
struct Equation {
  int k;
  double a;
  double w;
  double ln_t;
};

// Adds one sample's equations to the normal equations with its ln E eliminated. A row is
// w (a^T g - e - ln t); in (g, e): H_gg += w^2 a a^T, H_ge = -w^2 a, H_ee = w^2,
// b_g += w^2 ln t a, b_e = -w^2 ln t; then S = H_gg - H_ge H_ee^-1 H_eg and
// b = b_g - H_ge H_ee^-1 b_e, where H_ge has at most 2P non-zero entries.
void AddSample(const std::vector<Equation>& sample, Eigen::MatrixXd* h, Eigen::VectorXd* rhs) {
  std::vector<std::pair<int, double>> cross;  // (level, H_ge entry)
  const auto add_cross = [&](int k, double value) {
    for (auto& [level, entry] : cross) {
      if (level == k) {
        entry += value;
        return;
      }
    }
    cross.emplace_back(k, value);
  };
  double h_ee = 0.0, b_e = 0.0;
  for (const Equation& eq : sample) {
    const double w2 = eq.w * eq.w;
    const double c0 = 1.0 - eq.a, c1 = eq.a;
    (*h)(eq.k, eq.k) += w2 * c0 * c0;
    (*h)(eq.k, eq.k + 1) += w2 * c0 * c1;
    (*h)(eq.k + 1, eq.k) += w2 * c0 * c1;
    (*h)(eq.k + 1, eq.k + 1) += w2 * c1 * c1;
    (*rhs)(eq.k) += w2 * eq.ln_t * c0;
    (*rhs)(eq.k + 1) += w2 * eq.ln_t * c1;
    add_cross(eq.k, -w2 * c0);
    add_cross(eq.k + 1, -w2 * c1);
    h_ee += w2;
    b_e -= w2 * eq.ln_t;
  }
  for (const auto& [r, cr] : cross) {
    for (const auto& [c, cc] : cross) (*h)(r, c) -= cr * cc / h_ee;
    (*rhs)(r) -= cr * b_e / h_ee;
  }
}

// Smoothness: lambda * w(z) * (g(z-1) - 2 g(z) + g(z+1)), scaled so lambda keeps its meaning
// (curvature per 8-bit level, total weight of the term) whatever the number of levels.
void AddSmoothness(double lambda, int levels, Eigen::MatrixXd* h) {
  const double scale = std::pow((levels - 1) / 255.0, 2) * std::sqrt(256.0 / levels);
  for (int z = 1; z < levels - 1; ++z) {
    const double w = lambda * HatWeight(z, levels) * scale;
    const int idx[3] = {z - 1, z, z + 1};
    const double coef[3] = {w, -2.0 * w, w};
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) (*h)(idx[r], idx[c]) += coef[r] * coef[c];
    }
  }
}

// Residual RMS over the data equations, in ln units (unweighted), with each ln E_i at its
// weighted optimum.
double ResidualRms(const std::vector<std::vector<Equation>>& equations,
                   const std::vector<double>& g) {
  double sum = 0.0;
  int count = 0;
  const auto g_at = [&](const Equation& eq) {
    return (1.0 - eq.a) * g[size_t(eq.k)] + eq.a * g[size_t(eq.k) + 1];
  };
  for (const auto& sample : equations) {
    if (sample.empty()) continue;
    double num = 0.0, den = 0.0;
    for (const Equation& eq : sample) {
      num += eq.w * eq.w * (g_at(eq) - eq.ln_t);
      den += eq.w * eq.w;
    }
    const double ln_e = num / den;
    for (const Equation& eq : sample) {
      const double r = g_at(eq) - ln_e - eq.ln_t;
      sum += r * r;
      ++count;
    }
  }
  return count > 0 ? std::sqrt(sum / count) : 0.0;
}

// Debevec–Malik's weighted least squares by normal equations, with the per-sample unknowns
// ln E_i eliminated exactly (Schur complement): what remains is a dense levels x levels symmetric
// system in g. The data part is kept in two halves (samples alternately) so that automatic
// lambda can compare the curves the halves give; the full data term is their sum.
struct ChannelSystem {
  Eigen::MatrixXd h[2];
  Eigen::VectorXd rhs[2];
  Eigen::MatrixXd smooth;  // smoothness term for lambda = 1
  std::vector<std::vector<Equation>> equations;
};

ChannelSystem BuildChannelSystem(const Bracket& bracket, const std::vector<int64_t>& pixels,
                                 int channel, int levels, const ResponseOptions& options) {
  ChannelSystem s;
  for (int half = 0; half < 2; ++half) {
    s.h[half] = Eigen::MatrixXd::Zero(levels, levels);
    s.rhs[half] = Eigen::VectorXd::Zero(levels);
  }
  s.equations.resize(pixels.size());
  for (size_t i = 0; i < pixels.size(); ++i) {
    for (size_t j = 0; j < bracket.images.size(); ++j) {
      const Image& image = bracket.images[j];
      const double v = image.pixels[size_t(pixels[i]) * image.channels + channel];
      if (v <= options.black || v >= options.saturated) continue;
      const double z = v * double(levels - 1);
      const int k = std::min(int(z), levels - 2);
      s.equations[i].push_back({k, z - k, HatWeight(z, levels), std::log(bracket.exposures_s[j])});
    }
    if (!s.equations[i].empty()) AddSample(s.equations[i], &s.h[i % 2], &s.rhs[i % 2]);
  }
  s.smooth = Eigen::MatrixXd::Zero(levels, levels);
  AddSmoothness(1.0, levels, &s.smooth);
  return s;
}

// g minimising data + lambda^2 smoothness, g(middle) = 0 fixing the free constant (the
// smoothness rows and that gauge keep the matrix positive definite: Cholesky).
std::vector<double> SolveCurve(const Eigen::MatrixXd& data, const Eigen::VectorXd& rhs,
                               const Eigen::MatrixXd& smooth, double lambda) {
  const int levels = int(data.rows());
  Eigen::MatrixXd h = data + (lambda * lambda) * smooth;
  h(levels / 2, levels / 2) += 1.0;
  const Eigen::LLT<Eigen::MatrixXd> llt(h);
  if (llt.info() != Eigen::Success) throw Error("Debevec least squares: factorisation failed");
  const Eigen::VectorXd g = llt.solve(rhs);
  return std::vector<double>(g.data(), g.data() + levels);
}

// Split-half noise of the curve: RMS over the levels with data (inside black..saturated) of the
// difference between the two halves' curves, offset removed, halved. Each half has half the
// data, so its noise is sqrt(2) that of the full curve, and the difference of two independent
// halves sqrt(2) more: half the difference estimates the full curve's noise, ripples included
// (constant-ratio ripples are noise the data barely constrain, and they differ between halves).
double SplitHalfNoise(const ChannelSystem& s, double lambda, const ResponseOptions& options) {
  const int levels = int(s.smooth.rows());
  const std::vector<double> a = SolveCurve(s.h[0], s.rhs[0], s.smooth, lambda);
  const std::vector<double> b = SolveCurve(s.h[1], s.rhs[1], s.smooth, lambda);
  const Eigen::VectorXd coverage = (s.h[0] + s.h[1]).diagonal();  // data weight per level
  double weight = 0.0, mean = 0.0, sum = 0.0;
  for (int z = 0; z < levels; ++z) {
    const double v = double(z) / (levels - 1);
    if (v <= options.black || v >= options.saturated) continue;
    weight += coverage(z);
    mean += coverage(z) * (a[size_t(z)] - b[size_t(z)]);
  }
  if (!(weight > 0.0)) return 0.0;
  mean /= weight;
  for (int z = 0; z < levels; ++z) {
    const double v = double(z) / (levels - 1);
    if (v <= options.black || v >= options.saturated) continue;
    const double d = a[size_t(z)] - b[size_t(z)] - mean;
    sum += coverage(z) * d * d;
  }
  return 0.5 * std::sqrt(sum / weight);
}

// Automatic lambda: the smallest of kAutoLambdas whose split-half noise is at most
// max(kAutoLambdaNoise, 1.25 x the least noise over kAutoLambdas): the least smoothing bias
// among the curves that are reproducible (to the target, or as well as this data allows).
double ChooseLambda(const ChannelSystem& s, const ResponseOptions& options) {
  std::vector<double> noise;
  for (double lambda : kAutoLambdas) {
    noise.push_back(SplitHalfNoise(s, lambda, options));
    spdlog::debug("debevec: lambda {} split-half noise {:.5f}", lambda, noise.back());
  }
  const double bound =
      std::max(kAutoLambdaNoise, kAutoLambdaSlack * *std::min_element(noise.begin(), noise.end()));
  for (size_t i = 0; i < noise.size(); ++i) {
    if (noise[i] <= bound) return kAutoLambdas[i];
  }
  return kAutoLambdas.back();
}

std::vector<double> SolveDebevecChannel(const Bracket& bracket, const std::vector<int64_t>& pixels,
                                        int channel, int levels, const ResponseOptions& options,
                                        double* lambda, double* rms) {
  const ChannelSystem s = BuildChannelSystem(bracket, pixels, channel, levels, options);
  *lambda = options.lambda == kLambdaAuto ? ChooseLambda(s, options) : options.lambda;
  std::vector<double> g = SolveCurve(s.h[0] + s.h[1], s.rhs[0] + s.rhs[1], s.smooth, *lambda);
  *rms = ResidualRms(s.equations, g);
  MakeMonotonic(&g);
  return g;
}

}  // namespace

double DetectBlackFloor(const Bracket& bracket, int channel) {
  const auto shortest = std::min_element(bracket.exposures_s.begin(), bracket.exposures_s.end());
  const Image& image = bracket.images[size_t(shortest - bracket.exposures_s.begin())];
  constexpr int kBins = 256;
  constexpr int kPileWidth = 4;  // levels from the pile's mode to its top, at most
  std::array<int64_t, kBins> histogram{};
  const int64_t pixels = int64_t(image.width) * image.height;
  for (int64_t p = 0; p < pixels; ++p) {
    const float v = image.pixels[size_t(p) * image.channels + channel];
    ++histogram[size_t(std::clamp(int(std::lround(v * (kBins - 1))), 0, kBins - 1))];
  }
  const int first = int(std::floor(kMinBlack * (kBins - 1))) + 1;
  const int last = int(0.25 * (kBins - 1));
  int mode = first;
  for (int b = first; b <= last; ++b) {
    if (histogram[size_t(b)] > histogram[size_t(mode)]) mode = b;
  }
  int64_t pile = 0;
  for (int b = std::max(0, mode - 2); b <= std::min(kBins - 1, mode + 2); ++b) {
    pile += histogram[size_t(b)];
  }
  if (pile * 10 <= pixels) return 0.0;
  int top = mode;
  while (top + 1 < kBins && histogram[size_t(top + 1)] * 10 >= histogram[size_t(mode)]) ++top;
  // A broad mode is dark scene content, not a floor; so is a mode at the window's lower edge
  // (the tail of values falling from true black).
  if (top - mode > kPileWidth || mode - 3 < first ||
      histogram[size_t(mode - 3)] * 10 >= histogram[size_t(mode)]) {
    return 0.0;
  }
  return double(top + 1) / (kBins - 1);
}

double ParseLambda(const std::string& text) {
  const std::string trimmed(Trim(text));
  if (ToLower(trimmed) == "auto") return kLambdaAuto;
  const std::optional<double> value = ParseDouble(trimmed);
  if (!value || !(*value >= 0.0) || !std::isfinite(*value)) {
    throw InputError(DescribeProblem("--lambda", "", text, "must be auto or a number >= 0"));
  }
  return *value;
}

double ParseBlack(const std::string& text) {
  const std::string trimmed(Trim(text));
  if (ToLower(trimmed) == "auto") return kBlackAuto;
  const std::optional<double> value = ParseDouble(trimmed);
  if (!value || !(*value >= 0.0 && *value < 1.0)) {
    throw InputError(DescribeProblem("--black", "", text, "must be auto or a number in [0, 1)"));
  }
  return *value;
}

constexpr EnumNames<ResponseRecoveryMethod, 2> kResponseRecoveryMethodNames{
    {{ResponseRecoveryMethod::kDebevec, "debevec"},
     {ResponseRecoveryMethod::kRobertson, "robertson"}}};

std::string_view ResponseRecoveryMethodName(ResponseRecoveryMethod method) {
  return kResponseRecoveryMethodNames.Name(method);
}
std::optional<ResponseRecoveryMethod> ResponseRecoveryMethodFromName(std::string_view name) {
  return kResponseRecoveryMethodNames.FromName(name);
}

void ResponseOptions::Validate() const {
  ProblemList problems;
  if (!ResponseRecoveryMethodFromName(ResponseRecoveryMethodName(method))) {
    problems.Add("--method", "", std::to_string(int(method)), "must be debevec or robertson");
  }
  if (lambda != kLambdaAuto && (!(lambda >= 0.0) || !std::isfinite(lambda))) {
    problems.Add("--lambda", "", fmt::format("{}", lambda), "must be auto or >= 0");
  }
  if (levels != 0 && (levels < 16 || levels > 65536)) {
    problems.Add("--levels", "", fmt::format("{}", levels), "must be 0 (auto) or 16..65536");
  }
  if (samples < 0) problems.Add("--samples", "", fmt::format("{}", samples), "must be >= 0");
  if (!((black == kBlackAuto || black >= 0.0) && black < saturated && saturated <= 1.0)) {
    problems.Add("--black/--saturated", "", fmt::format("{}/{}", black, saturated),
                 "need black auto or 0 <= black < saturated <= 1");
  }
  if (!(robertson_smoothing >= 0.0)) {
    problems.Add("--robertson-smoothing", "", fmt::format("{}", robertson_smoothing),
                 "must be >= 0");
  }
  if (max_iterations < 1) {
    problems.Add("--max-iterations", "", fmt::format("{}", max_iterations), "must be >= 1");
  }
  problems.ThrowIfAny();
}

ResponseSummary RecoverResponse(const Bracket& bracket, const ResponseOptions& options) {
  options.Validate();
  const int levels = ResolveLevels(bracket, options);
  // Each channel's black level; the pixel sampling and Robertson's fit take the highest.
  std::vector<double> black;
  for (int c = 0; c < bracket.channels(); ++c) {
    black.push_back(options.black == kBlackAuto ? std::max(kMinBlack, DetectBlackFloor(bracket, c))
                                                : options.black);
  }
  ResponseOptions resolved = options;
  resolved.black = 0.0;
  for (double b : black) resolved.black = std::max(resolved.black, b);
  if (options.method == ResponseRecoveryMethod::kRobertson) {
    ResponseSummary summary = RecoverRobertson(bracket, resolved, levels);
    summary.black.assign(black.size(), resolved.black);
    return summary;
  }
  const int p = int(bracket.images.size());
  SamplingOptions sampling;
  sampling.samples = options.samples > 0
                         ? options.samples
                         : std::min(4000, std::max(1000, 3 * levels / std::max(p - 1, 1)));
  sampling.black = resolved.black;
  sampling.saturated = options.saturated;
  const std::vector<int64_t> pixels = SelectSamplePixels(bracket, sampling);
  ResponseSummary summary;
  summary.samples = int(pixels.size());
  summary.equations = 1 << 30;
  summary.curve.method = ResponseRecoveryMethodName(ResponseRecoveryMethod::kDebevec);
  summary.curve.levels = levels;
  summary.curve.channels = DefaultChannelNames(bracket.channels());
  summary.black = black;
  for (int c = 0; c < bracket.channels(); ++c) {
    ResponseOptions channel_options = options;
    channel_options.black = black[size_t(c)];
    const int equations = CountEquations(bracket, pixels, c, channel_options);
    CheckEnoughEquations(bracket, equations, levels, c);
    summary.equations = std::min(summary.equations, equations);
    double rms = 0.0, lambda = 0.0;
    summary.curve.g.push_back(
        SolveDebevecChannel(bracket, pixels, c, levels, channel_options, &lambda, &rms));
    summary.rms_residual.push_back(rms);
    summary.lambda.push_back(lambda);
  }
  spdlog::info("debevec: {} samples, {} equations, lambda {}{}, black {:.3f}, rms {:.4f}",
               summary.samples, summary.equations, fmt::join(summary.lambda, "/"),
               options.lambda == kLambdaAuto ? " (auto)" : "", fmt::join(black, "/"),
               summary.rms_residual.front());
  return summary;
}

}  // namespace igi::calib
