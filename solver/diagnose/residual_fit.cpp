#include "solver/diagnose/residual_fit.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <unordered_map>

namespace igi::diagnose {

ResidualFitter::ResidualFitter(const std::vector<PixelRecord>& records, std::vector<int> cell,
                               int num_cells, bool nuisance, int block_px)
    : records_(records),
      cell_(std::move(cell)),
      num_cells_(num_cells),
      nuisance_(nuisance),
      block_px_(std::max(1, block_px)) {
  // Without the nuisance the cells play no part in a fit: one cell holds every record's sums
  // (with maps' voxel cells, thousands of per-cell sums would be zeroed, filled and read back
  // at every fit of a search).
  if (!nuisance_) {
    std::fill(cell_.begin(), cell_.end(), 0);
    num_cells_ = std::min(num_cells_, 1);
  }
}

namespace {

// Σ s² less the variance (errors in variables), kept at least half of Σ s² (a variance estimate
// as large as the signal is noise of its own).
double CorrectedSs(const double* st, int stride, bool noise_free) {
  return noise_free ? std::max(0.5 * st[0], st[0] - st[stride - 3]) : st[0];
}

}  // namespace

double ResidualFitter::NuisanceCoef(const std::vector<double>& stats, int k, size_t cell, int c,
                                    const Eigen::VectorXd& coef, bool noise_free) const {
  if (!nuisance_) return 0;
  const int stride = Stride(k);
  const double* st = &stats[((cell * 3 + c) * 2 + 1) * stride];
  if (!(st[0] > 0)) return 0;
  const double ss = CorrectedSs(st, stride, noise_free), v = noise_free ? st[0] - ss : 0.0;
  // Before the fit: the plain residual y0; after: y − coef·b.
  if (coef.size() == 0) return (st[stride - 2] + v) / ss;
  double sy = st[1] + v;
  for (int a = 0; a < coef.size(); ++a) sy -= coef[a] * st[3 + a];
  return sy / ss;
}

double ResidualFitter::Z(const std::vector<double>& gains) {
  const double n = double(gains.size());
  if (n < 2) return 0;
  double mean = 0, sq = 0;
  for (double x : gains) mean += x;
  mean /= n;
  for (double x : gains) sq += (x - mean) * (x - mean);
  const double se = std::sqrt(sq / (n - 1) / n);
  return se > 0 ? mean / se : 0;
}

namespace {

// The projected quantities of one (cell, channel, set) block (reused from block to block: no
// allocation per block).
struct Projected {
  explicit Projected(int k) : bb(k, k), by(k), tmp(k) {}
  Eigen::MatrixXd bb;  // Σ b bᵀ − (Σ s b)(Σ s b)ᵀ / Σ s²
  Eigen::VectorXd by;  // Σ b y − (Σ s b)(Σ s y) / Σ s²
  Eigen::VectorXd tmp;
  double yy = 0;   // Σ y² − (Σ s y)² / Σ s²
  double yy0 = 0;  // the same for y0 (no offset)
};

// With noise_free, the noise-free error: the nuisance's sums corrected by the variance V
// (ResidualFitter::FitNoiseFreeBasis); Σ y² − V − (Σ s·y + V)² / (Σ s² − V) is the least
// Σ (y − a s)² − (1 + a)² V.
void Project(const double* st, int k, bool nuisance, bool noise_free, Projected* out) {
  Projected& p = *out;
  p.bb = Eigen::Map<const Eigen::MatrixXd>(st + 3 + 2 * k, k, k);
  p.by = Eigen::Map<const Eigen::VectorXd>(st + 3 + k, k);
  p.yy = st[2];
  const int stride = 6 + 2 * k + k * k;
  p.yy0 = st[stride - 1];
  if (nuisance && st[0] > 0) {
    const double ss = CorrectedSs(st, stride, noise_free), v = noise_free ? st[0] - ss : 0.0;
    const double sy = st[1] + v, sy0 = st[stride - 2] + v;
    const Eigen::Map<const Eigen::VectorXd> sb(st + 3, k);
    p.bb.noalias() -= sb * sb.transpose() / ss;
    p.by.noalias() -= sb * (sy / ss);
    p.yy -= v + sy * sy / ss;
    p.yy0 -= v + sy0 * sy0 / ss;
  }
}

}  // namespace

ResidualFit ResidualFitter::Solve(int k, const std::vector<double>& stats, bool noise_free,
                                  int k_base) const {
  const int stride = Stride(k);
  ResidualFit fit;
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(k, k);
  Eigen::VectorXd g = Eigen::VectorXd::Zero(k);
  Projected p(k), raw(k);
  double train_offset = 0;  // projected Σ y² (with the offset) before the fit
  for (int cell = 0; cell < num_cells_; ++cell) {
    for (int c = 0; c < 3; ++c) {
      Project(&stats[((size_t(cell) * 3 + c) * 2 + 0) * stride], k, nuisance_, noise_free, &p);
      a += p.bb;
      g += p.by;
      fit.train_before += p.yy0;
      train_offset += p.yy;
    }
  }
  const double ridge = 1e-9 * std::max(1e-300, a.diagonal().cwiseAbs().maxCoeff());
  a.diagonal().array() += ridge;
  Eigen::LDLT<Eigen::MatrixXd> ldlt(a);
  if (ldlt.info() != Eigen::Success || !(a.diagonal().maxCoeff() > 0)) return fit;
  fit.coef = ldlt.solve(g);
  if (!fit.coef.allFinite()) {
    fit.coef.resize(0);
    return fit;
  }
  fit.train_after = train_offset - 2 * fit.coef.dot(g) + fit.coef.dot(a * fit.coef);
  // FitBeyond (no offset, not noise-free): "before" is the base columns' own fit.
  if (k_base > 0 && k_base < k) {
    Eigen::LDLT<Eigen::MatrixXd> base(a.topLeftCorner(k_base, k_base));
    fit.base_coef = Eigen::VectorXd::Zero(k);
    if (base.info() == Eigen::Success) fit.base_coef.head(k_base) = base.solve(g.head(k_base));
    if (!fit.base_coef.allFinite()) fit.base_coef.setZero();
    fit.train_before =
        train_offset - 2 * fit.base_coef.dot(g) + fit.base_coef.dot(a * fit.base_coef);
  }
  const bool beyond = fit.base_coef.size() == k;
  // Held out: the same coefficients, the set's own nuisance.
  double held_raw = 0;
  for (int cell = 0; cell < num_cells_; ++cell) {
    for (int c = 0; c < 3; ++c) {
      const double* st = &stats[((size_t(cell) * 3 + c) * 2 + 1) * stride];
      Project(st, k, nuisance_, noise_free, &p);
      p.tmp.noalias() = p.bb * fit.coef;
      fit.held_before +=
          beyond ? p.yy - (2 * fit.base_coef.dot(p.by) - fit.base_coef.dot(p.bb * fit.base_coef))
                 : p.yy0;
      fit.held_after += p.yy - (2 * fit.coef.dot(p.by) - fit.coef.dot(p.tmp));
      if (noise_free) {
        Project(st, k, nuisance_, false, &raw);
        held_raw += raw.yy0;
      }
    }
  }
  // The noise-free fall of the error on the raw error's scale (the refit's test: the fall of
  // the squared error less the fall of the renders' variance, over the raw error before).
  if (noise_free) {
    fit.held_after = held_raw - (fit.held_before - fit.held_after);
    fit.held_before = held_raw;
  }
  return fit;
}

namespace {

// One-sided p-value of a normal z, and back (bisection: p underflows only beyond z ≈ 37).
double UpperTail(double z) { return 0.5 * std::erfc(z / std::sqrt(2.0)); }
double UpperQuantile(double p) {
  double lo = -40, hi = 40;
  for (int k = 0; k < 100; ++k) {
    const double mid = 0.5 * (lo + hi);
    (UpperTail(mid) > p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace

double BlockGainZ(const std::vector<std::pair<double, double>>& blocks) {
  const double n = double(blocks.size());
  if (n < 2) return 0;
  double mean = 0, sum_g = 0, sum_e = 0;
  for (const auto& [g, e] : blocks) mean += g / e, sum_g += g, sum_e += e;
  mean /= n;
  const double ratio = sum_g / sum_e;
  double sq_rel = 0, sq_ratio = 0;
  for (const auto& [g, e] : blocks) {
    sq_rel += (g / e - mean) * (g / e - mean);
    sq_ratio += (g - ratio * e) * (g - ratio * e);
  }
  const double se_rel = std::sqrt(sq_rel / (n - 1) / n);
  const double se_ratio = std::sqrt(sq_ratio * n / (n - 1)) / sum_e;
  const double z_rel = se_rel > 0 ? mean / se_rel : 0;
  const double z_ratio = se_ratio > 0 ? ratio / se_ratio : 0;
  return EitherZ(z_rel, z_ratio);
}

double EitherZ(double z1, double z2) {
  const double best = std::max(z1, z2);
  const double p = UpperTail(best);
  return best > 0 && p > 0 ? UpperQuantile(2 * p) : best;
}

std::vector<int> RecordCells(const recon::Scene& model, const std::vector<PixelRecord>& records,
                             double cell_m, int* num_cells) {
  std::unordered_map<int64_t, int> ids;
  std::vector<int> cell(records.size());
  for (size_t i = 0; i < records.size(); ++i) {
    const PixelRecord& r = records[i];
    int64_t key = int64_t(r.region) << 48;
    if (model.materials[r.region].rho_d_map) {
      const Eigen::Vector3f q = r.position / float(cell_m);
      key += ((int64_t(std::floor(q.x())) & 0xFFFF) << 32) +
             ((int64_t(std::floor(q.y())) & 0xFFFF) << 16) + (int64_t(std::floor(q.z())) & 0xFFFF) +
             1;
    }
    auto [it, added] = ids.emplace(key, int(ids.size()));
    cell[i] = it->second;
  }
  *num_cells = int(ids.size());
  return cell;
}

RecordSubset::RecordSubset(const recon::Scene& model, const std::vector<PixelRecord>& records,
                           double cell_m, bool nuisance, int block_px, int stride, int region)
    : stride_(std::max(1, stride)) {
  for (size_t i = 0; i < records.size(); ++i) {
    // A hash of the index, not every stride-th record: records come in patterns (photo by photo,
    // rows of pixels, regions interleaved) that a regular stride could alias.
    uint64_t h = (uint64_t(i) + 0x9e3779b97f4a7c15ull) * 0xbf58476d1ce4e5b9ull;
    h ^= h >> 31;
    h *= 0x94d049bb133111ebull;
    h ^= h >> 29;
    if (h % uint64_t(stride_) != 0) continue;
    if (region < 0 || records[i].region == region) records_.push_back(records[i]);
  }
  int num_cells = 0;
  std::vector<int> cells = RecordCells(model, records_, cell_m, &num_cells);
  fitter_ =
      std::make_unique<ResidualFitter>(records_, std::move(cells), num_cells, nuisance, block_px);
}

RecordSubset::RecordSubset(const recon::Scene& model, std::vector<PixelRecord> records,
                           double cell_m, bool nuisance, int block_px)
    : records_(std::move(records)), stride_(1) {
  int num_cells = 0;
  std::vector<int> cells = RecordCells(model, records_, cell_m, &num_cells);
  fitter_ =
      std::make_unique<ResidualFitter>(records_, std::move(cells), num_cells, nuisance, block_px);
}

int SearchStride(const std::vector<PixelRecord>& records, int target) {
  int64_t fitted = 0;
  for (const PixelRecord& r : records) fitted += !r.held_out && !r.outlier;
  return int(std::max<int64_t>(1, fitted / std::max(1, target)));
}

ResidualFit FitChange(const ResidualFitter& f, const Change& ch) {
  const PixelRecord* base = f.records().data();
  return f.Fit(
      1, [&](const PixelRecord& r, int c, double* b) { b[0] = ch.basis[size_t(&r - base)][c]; },
      [&](const PixelRecord& r, int c) {
        return ch.offset.empty() ? 0.0 : double(ch.offset[size_t(&r - base)][c]);
      });
}

double SignedRankZ(std::vector<double> values) {
  values.erase(std::remove(values.begin(), values.end(), 0.0), values.end());
  const double n = double(values.size());
  if (n < 2) return 0;
  std::sort(values.begin(), values.end(),
            [](double a, double b) { return std::abs(a) < std::abs(b); });
  double w = 0;
  for (size_t k = 0; k < values.size(); ++k) w += values[k] > 0 ? double(k + 1) : -double(k + 1);
  return w / std::sqrt(n * (n + 1) * (2 * n + 1) / 6);
}

}  // namespace igi::diagnose
