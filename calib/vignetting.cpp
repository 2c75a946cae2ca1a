#include "calib/vignetting.h"

#include <ceres/ceres.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "tools/common/error.h"

namespace igi::calib {
namespace {

// The non-radial terms of a photo's illumination (vignetting.h): u, v, u² − v², uv, u³, u²v,
// uv², v³. Their coefficients and ln L's constant are the photo's parameters.
constexpr int kIlluminationTerms = 8;
constexpr int kPhotoParams = kIlluminationTerms + 1;

template <typename T>
T LnFactor(const T* k, double r2) {
  // V is kept above a small positive floor so that a trial step of the solver that turns V
  // negative somewhere gives a large residual instead of a NaN.
  const T v = T(1.0) + k[0] * r2 + k[1] * (r2 * r2);
  return log(v > T(1e-6) ? v : T(1e-6));
}

struct FlatFieldResidual {
  double u, v, r2, ln_value;

  template <typename T>
  bool operator()(const T* photo, const T* k, T* residual) const {
    const double terms[kIlluminationTerms] = {u,         v,         u * u - v * v, u * v,
                                              u * u * u, u * u * v, u * v * v,     v * v * v};
    T ln_l = photo[0];
    for (int j = 0; j < kIlluminationTerms; ++j) ln_l += photo[1 + j] * terms[j];
    residual[0] = T(ln_value) - ln_l - LnFactor(k, r2);
    return true;
  }
};

struct OverlapResidual {
  double r2_a, r2_b, ln_a, ln_b;

  template <typename T>
  bool operator()(const T* s_a, const T* s_b, const T* k, T* residual) const {
    residual[0] = (T(ln_a) - s_a[0] - LnFactor(k, r2_a)) - (T(ln_b) - s_b[0] - LnFactor(k, r2_b));
    return true;
  }
};

void Solve(ceres::Problem* problem) {
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = 200;
  options.function_tolerance = 1e-12;
  options.parameter_tolerance = 1e-12;
  options.num_threads = 1;
  ceres::Solver::Summary summary;
  ceres::Solve(options, problem, &summary);
}

// RMS of the residuals without the loss function.
double RmsResidual(ceres::Problem* problem) {
  ceres::Problem::EvaluateOptions options;
  std::vector<ceres::ResidualBlockId> blocks;
  problem->GetResidualBlocks(&blocks);
  options.residual_blocks = blocks;
  options.apply_loss_function = false;
  std::vector<double> residuals;
  problem->Evaluate(options, nullptr, &residuals, nullptr, nullptr);
  double sum = 0;
  for (double r : residuals) sum += r * r;
  return residuals.empty() ? 0.0 : std::sqrt(sum / double(residuals.size()));
}

}  // namespace

double VignettingRadius2(double x, double y, double cx, double cy, int width, int height) {
  const double half_diag2 = 0.25 * (double(width) * width + double(height) * height);
  return ((x - cx) * (x - cx) + (y - cy) * (y - cy)) / half_diag2;
}

int FlatFieldBlockSize(int width, int height) { return std::max(1, std::max(width, height) / 48); }

FlatFieldReducer::FlatFieldReducer(std::string name, int width, int height, int block_px)
    : name_(std::move(name)),
      width_(width),
      height_(height),
      block_px_(block_px),
      cols_(width / block_px),
      rows_(height / block_px),
      sum_(size_t(cols_) * rows_, 0.0),
      count_(size_t(cols_) * rows_, 0) {}

void FlatFieldReducer::AddRow(int y, const float* luminance, const uint8_t* usable) {
  const int row = y / block_px_;
  for (int x = 0; x < width_; ++x) {
    const bool ok = usable[x] != 0 && std::isfinite(luminance[x]) && luminance[x] > 0;
    if (!ok) {
      if (unusable_++ == 0) {
        first_bad_x_ = x;
        first_bad_y_ = y;
        first_bad_value_ = luminance[x];
      }
      continue;
    }
    const int col = x / block_px_;
    if (row >= rows_ || col >= cols_) continue;
    sum_[size_t(row) * cols_ + col] += luminance[x];
    ++count_[size_t(row) * cols_ + col];
  }
}

FlatField FlatFieldReducer::Finish() {
  const int64_t pixels = int64_t(width_) * height_;
  if (double(unusable_) > kMaxUnusableShare * double(pixels)) {
    throw InputError(DescribeProblem(
        name_, fmt::format("pixel ({}, {})", first_bad_x_, first_bad_y_),
        fmt::format("{:g}", first_bad_value_),
        fmt::format("clipped, black or not a number, as are {} of its {} pixels (at most {:g} % "
                    "may be): a flat field must be exposed within the sensor's range everywhere",
                    unusable_, pixels, 100 * kMaxUnusableShare)));
  }
  FlatField field{name_, width_, height_, {}, unusable_};
  for (int row = 0; row < rows_; ++row) {
    for (int col = 0; col < cols_; ++col) {
      const size_t i = size_t(row) * cols_ + col;
      if (count_[i] == 0) continue;
      field.blocks.push_back(
          {(col + 0.5) * block_px_, (row + 0.5) * block_px_, sum_[i] / double(count_[i])});
    }
  }
  if (field.blocks.empty()) {
    throw InputError(DescribeProblem(name_, "", fmt::format("{}x{}", width_, height_),
                                     "no usable block of pixels"));
  }
  std::vector<double> values;
  for (const FlatFieldBlock& b : field.blocks) values.push_back(b.value);
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  const double median = values[values.size() / 2];
  for (const FlatFieldBlock& b : field.blocks) {
    if (b.value < kDarkShareOfMedian * median) {
      throw InputError(DescribeProblem(
          name_, fmt::format("pixel ({:.0f}, {:.0f})", b.x, b.y), fmt::format("{:g}", b.value),
          fmt::format("dark: below {:g} % of the photo's median {:g}; a flat field must fill the "
                      "frame with a lit target",
                      100 * kDarkShareOfMedian, median)));
    }
  }
  return field;
}

VignettingFit FitFlatFields(const std::vector<FlatField>& fields, double cx, double cy) {
  if (fields.empty()) {
    throw InputError(DescribeProblem("flat fields", "", "0", "need at least one photo"));
  }
  const int width = fields[0].width, height = fields[0].height;
  const double half_diag = 0.5 * std::hypot(double(width), double(height));
  ceres::Problem::Options problem_options;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  // Dust on the lens or a spot on the target moves a block's ln value by far more than the
  // smooth model; beyond 5 % the residual counts linearly.
  ceres::HuberLoss loss(0.05);
  std::vector<std::vector<double>> photos(fields.size(), std::vector<double>(kPhotoParams, 0.0));
  double k[2] = {0, 0};
  double max_r2 = 0;
  VignettingFit fit;
  for (size_t i = 0; i < fields.size(); ++i) {
    const FlatField& f = fields[i];
    if (f.width != width || f.height != height) {
      throw InputError(DescribeProblem(f.name, "", fmt::format("{}x{}", f.width, f.height),
                                       fmt::format("must be {}x{} as {} is: flat fields of one "
                                                   "camera",
                                                   width, height, fields[0].name)));
    }
    std::vector<double> ln;
    for (const FlatFieldBlock& b : f.blocks) ln.push_back(std::log(b.value));
    std::nth_element(ln.begin(), ln.begin() + ln.size() / 2, ln.end());
    photos[i][0] = ln[ln.size() / 2];
    for (const FlatFieldBlock& b : f.blocks) {
      const double u = (b.x - cx) / half_diag, v = (b.y - cy) / half_diag;
      const double r2 = u * u + v * v;
      max_r2 = std::max(max_r2, r2);
      problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<FlatFieldResidual, 1, kPhotoParams, 2>(
              new FlatFieldResidual{u, v, r2, std::log(b.value)}),
          &loss, photos[i].data(), k);
      ++fit.samples;
    }
  }
  if (max_r2 < 0.25) {
    throw InputError(DescribeProblem("flat fields", "blocks", fmt::format("r² ≤ {:.3f}", max_r2),
                                     "must reach half the half diagonal to measure a fall-off"));
  }
  Solve(&problem);
  fit.vignetting = {k[0], k[1]};
  fit.rms_ln = RmsResidual(&problem);
  fit.photos = int(fields.size());
  return fit;
}

VignettingFit FitOverlap(const std::vector<OverlapPair>& pairs, int photos, bool free_exposures) {
  constexpr size_t kMinPairs = 100;
  if (pairs.size() < kMinPairs) {
    throw InputError(DescribeProblem(
        "overlap", "pairs", fmt::format("{}", pairs.size()),
        fmt::format("need at least {} surface points seen by two photos of one lighting",
                    kMinPairs)));
  }
  // The radii must differ between the two views of a point, and over a range: the spread of
  // r2_a − r2_b is what separates V from the photos' exposures.
  double spread = 0;
  for (const OverlapPair& p : pairs) spread += (p.r2_a - p.r2_b) * (p.r2_a - p.r2_b);
  spread = std::sqrt(spread / double(pairs.size()));
  if (spread < 0.05) {
    throw InputError(DescribeProblem(
        "overlap", "pairs", fmt::format("RMS r² difference {:.3f}", spread),
        "must be ≥ 0.05: the photos see the same points at nearly the same image radius"));
  }
  ceres::Problem::Options problem_options;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  // Glossy surfaces, occlusion edges and misregistration give pairs that are not the same
  // radiance; a Cauchy loss with a 10 % scale keeps them from pulling the fit.
  ceres::CauchyLoss loss(0.1);
  VignettingFit fit;
  fit.exposures_ln.assign(size_t(photos), 0.0);
  double k[2] = {0, 0};
  std::vector<bool> used(size_t(photos), false);
  for (const OverlapPair& p : pairs) {
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<OverlapResidual, 1, 1, 1, 2>(
                                 new OverlapResidual{p.r2_a, p.r2_b, p.ln_a, p.ln_b}),
                             &loss, &fit.exposures_ln[size_t(p.photo_a)],
                             &fit.exposures_ln[size_t(p.photo_b)], k);
    used[size_t(p.photo_a)] = used[size_t(p.photo_b)] = true;
  }
  if (free_exposures) {
    // One exposure is the reference: the first photo in a pair.
    const auto first = std::find(used.begin(), used.end(), true);
    problem.SetParameterBlockConstant(&fit.exposures_ln[size_t(first - used.begin())]);
  } else {
    for (int i = 0; i < photos; ++i) {
      if (used[size_t(i)]) problem.SetParameterBlockConstant(&fit.exposures_ln[size_t(i)]);
    }
  }
  Solve(&problem);
  fit.vignetting = {k[0], k[1]};
  fit.rms_ln = RmsResidual(&problem);
  fit.samples = int(pairs.size());
  fit.photos = int(std::count(used.begin(), used.end(), true));
  return fit;
}

}  // namespace igi::calib
