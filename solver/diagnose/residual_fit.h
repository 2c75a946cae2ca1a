#pragma once
// Fitting an effect's amplitudes to the residual (photo − model) of the residual samples, with
// the albedo left free: when the materials are solved, any change of the model is followed by a
// refit of the albedos, so a candidate is only credited with what it explains BEYOND a free
// albedo scale per "cell" (per region for regions of constant albedo, per small surface cell for
// regions with an albedo map), per colour channel. The nuisance is projected out exactly
// (Frisch–Waugh–Lovell): for each cell and channel, every quantity v is replaced by
// v − sim·(Σ v·sim / Σ sim²).
//
// Fits use the fitted (not held-out) samples; the same coefficients are scored on the held-out
// samples (with their own nuisance), and the held-out gain's significance is measured with the
// cells as independent units. Samples flagged as outliers take no part.

#include <Eigen/Core>
#include <algorithm>
#include <memory>
#include <type_traits>
#include <unordered_map>
#include <utility>
#include <vector>

#include "solver/diagnose/pixel_records.h"

namespace igi::diagnose {

struct ResidualFit {
  Eigen::VectorXd coef;                      // empty: singular
  double train_before = 0, train_after = 0;  // squared-error sums after the nuisance
  double held_before = 0, held_after = 0;
  double z = 0;  // held-out gain / its standard error over cells
  // FitBeyond: the fit of the base columns alone ("before"), padded with zeros to k.
  Eigen::VectorXd base_coef;
  double Gain() const { return held_before > 0 ? 1 - held_after / held_before : 0; }
};

class ResidualFitter {
 public:
  // `cell` per record (dense ids 0..num_cells-1); nuisance = the albedo is refitted.
  ResidualFitter(const std::vector<PixelRecord>& records, std::vector<int> cell, int num_cells,
                 bool nuisance, int block_px);

  // basis(record, channel, double* b) writes K values (b is zeroed before each call).
  template <class F>
  ResidualFit Fit(int k, F basis) const {
    return Fit(k, basis, [](const PixelRecord&, int) { return 0.0; });
  }
  // The same with a fixed change of the model, offset(record, channel), of amplitude 1 (the
  // residual fitted is photo − sim − offset; "before" is still photo − sim).
  template <class F, class G>
  ResidualFit Fit(int k, F basis, G offset) const {
    return FitImpl(k, basis, offset, false);
  }

  // Fit for a basis that carries none of the simulation's Monte Carlo noise (a light's direct
  // term, a separately rendered response): the simulation `sim` is the nuisance's regressor and
  // is noisy (variance PixelRecord::sim_var), and the residual photo − sim carries the same noise
  // with the opposite sign, so a plain fit credits any basis shaped like the true sim with
  // "explaining" that noise once the nuisance is projected out (the basis stands in for the noisy
  // sim). Errors in variables: the nuisance's sums are corrected by the variance V (Σ s² − V,
  // Σ s·y + V), which minimises the expected noise-free error Σ (y − a s − c·b)² − (1 + a)² V,
  // and the scores are of that noise-free error (the held-out "before" stays the raw error, the
  // gain's scale, as in the refit's test). Only with the nuisance (solved materials).
  template <class F>
  ResidualFit FitNoiseFreeBasis(int k, F basis) const {
    return FitImpl(
        k, basis, [](const PixelRecord&, int) { return 0.0; }, nuisance_);
  }

  // Fit for a basis computed from the noisy simulation itself, b(s) (a response curve of the
  // model's value): b and the residual y = photo − s both carry the render's noise ε (variance
  // V = PixelRecord::sim_var), so a plain fit reads that noise as part of the curve (the photo's
  // slope on the noisy model value is diluted: a response's exponent comes out low, 0.718 for
  // 0.791 at 10 % render noise in camera_response_test's ResponseTest). To second order in ε, with
  // b' = ∂b/∂s and b'' = ∂²b/∂s², the sums' expectations exceed their noise-free values by
  //   Σ s·b: V (b' + s b''/2),  Σ b·y: V (y b''/2 − b'),  Σ b·bᵀ: V (b' b'ᵀ + (b b''ᵀ + b'' bᵀ)/2);
  // they are subtracted (with the nuisance's correction of FitNoiseFreeBasis), and the held-out
  // gain counts the residual's noise as (1 + a + c·b')² V. derivatives(record, channel, d1, d2)
  // writes b' and b'' (K values each, zeroed before each call).
  template <class F, class D>
  ResidualFit FitNoisyBasis(int k, F basis, D derivatives) const {
    return FitImpl(
        k, basis, [](const PixelRecord&, int) { return 0.0; }, true, 0, derivatives);
  }

  // A fit credited only with what it explains beyond its first `k_base` columns: "before" (the
  // scores and the significance's blocks) is the fit of those columns alone, "after" the fit of
  // all k. For an effect whose model contains another's (per-photo scales contain a scale per
  // lighting, which is the lights' intensity): what the other explains is not its.
  template <class F>
  ResidualFit FitBeyond(int k, int k_base, F basis) const {
    return FitImpl(
        k, basis, [](const PixelRecord&, int) { return 0.0; }, false, k_base);
  }

  const std::vector<PixelRecord>& records() const { return records_; }
  bool nuisance() const { return nuisance_; }

 private:
  // No basis derivatives: the basis carries none of the simulation's noise.
  struct NoDerivatives {
    bool operator()(const PixelRecord&, int, double*, double*) const { return false; }
  };
  template <class F, class G, class D = NoDerivatives>
  ResidualFit FitImpl(int k, F basis, G offset, bool noise_free, int k_base = 0,
                      D derivatives = D()) const;
  ResidualFit Solve(int k, const std::vector<double>& stats, bool noise_free, int k_base = 0) const;
  // Σ s y / Σ s² of the held-out set per (cell, channel), before and after the fit (with the
  // variance correction when noise_free).
  double NuisanceCoef(const std::vector<double>& stats, int k, size_t cell, int c,
                      const Eigen::VectorXd& coef, bool noise_free) const;
  static double Z(const std::vector<double>& gains);
  static int Stride(int k) { return 6 + 2 * k + k * k; }

  const std::vector<PixelRecord>& records_;
  std::vector<int> cell_;
  int num_cells_;
  bool nuisance_;
  int block_px_;
};

// The significance (a normal z) of a held-out gain summed over blocks, from each block's
// (gain g_b, error before e_b), over the n blocks the change touched; two ways, Bonferroni-combined
// (the z whose one-sided p-value is twice the smaller one's):
// - each block alike: the mean of g_b / e_b over its standard error (an effect spread over many
//   blocks, e.g. a lens fall-off, whose blocks differ in brightness);
// - each block by its error: R = Σ g_b / Σ e_b (the form of the reported gain) over the ratio
//   estimator's standard error, sqrt(n/(n−1) Σ (g_b − R e_b)²) / Σ e_b: an effect seen in a few
//   blocks (a highlight) counts by what it explains there, not diluted by the blocks whose change
//   is only the path tracer's noise.
// With no effect both are z's of noise, and the combination's false-alarm rate is at most the
// nominal rate of one test at the same threshold. When neither z is positive, the larger is
// returned as it is.
double BlockGainZ(const std::vector<std::pair<double, double>>& blocks);

// Two tests of one hypothesis, Bonferroni-combined: the z whose one-sided p-value is twice the
// smaller one's (the larger z as it is when neither is positive).
double EitherZ(double z1, double z2);

// Wilcoxon's signed-rank statistic of `values` (zeros dropped) as a normal z: whether they are
// mostly positive, robust to the heavy tails of per-block gains on edges.
double SignedRankZ(std::vector<double> values);

// Cells for `model`'s records: per region, or per (region, voxel of `cell_m`) where the region
// has an albedo map.
std::vector<int> RecordCells(const recon::Scene& model, const std::vector<PixelRecord>& records,
                             double cell_m, int* num_cells);

// A subset of the records with its own fitter (cells by the same rule, the same nuisance and
// blocks): the searches over a candidate's nonlinear parameters (an axis, a radius, a lobe's
// roughnesses) run on it, and only the parameters they find are fitted and scored on every
// record. One record in `stride`, drawn by a hash of its index (deterministic), of region
// `region` only when it is >= 0.
class RecordSubset {
 public:
  RecordSubset(const recon::Scene& model, const std::vector<PixelRecord>& records, double cell_m,
               bool nuisance, int block_px, int stride, int region = -1);
  // Every record as given (a candidate's own copy whose outlier marks it changed: records taken
  // out of its fit or back into it), with its fitter; stride 1.
  RecordSubset(const recon::Scene& model, std::vector<PixelRecord> records, double cell_m,
               bool nuisance, int block_px);
  RecordSubset(const RecordSubset&) = delete;
  RecordSubset& operator=(const RecordSubset&) = delete;

  const ResidualFitter& fitter() const { return *fitter_; }
  const std::vector<PixelRecord>& records() const { return records_; }
  int stride() const { return stride_; }

 private:
  std::vector<PixelRecord> records_;
  int stride_;
  std::unique_ptr<ResidualFitter> fitter_;
};

// The stride that leaves about `target` fitted (not held-out, not outlier) records, at least 1.
int SearchStride(const std::vector<PixelRecord>& records, int target);

// The records' change of model for one parameter set, per record and channel (zero where a
// candidate does not touch the record).
struct Change {
  std::vector<Eigen::Vector3f> basis;   // amplitude-1 value of the new term
  std::vector<Eigen::Vector3f> offset;  // fixed change (the old term removed), or empty
};

// `ch` fitted on f's records with one free amplitude against its fixed offset.
ResidualFit FitChange(const ResidualFitter& f, const Change& ch);

// ------------------------------------------------------------------ implementation
// Per (cell, channel, set) the statistics are laid out as (y = photo − sim − offset, y0 = photo −
// sim): [0] Σ s², [1] Σ s·y, [2] Σ y², [3..3+k) Σ s·b, [3+k..3+2k) Σ b·y, then k×k Σ b·bᵀ,
// then Σ var(s), Σ s·y0 and Σ y0².
// With derivatives (FitNoisyBasis), the sums are corrected for the basis's own noise as they are
// accumulated; derivatives returns false for a basis without noise.
template <class F, class G, class D>
ResidualFit ResidualFitter::FitImpl(int k, F basis, G offset, bool noise_free, int k_base,
                                    D derivatives) const {
  const int stride = Stride(k);
  std::vector<double> stats(size_t(num_cells_) * 3 * 2 * stride, 0.0);
  std::vector<double> b(k), d1(k), d2(k);
  // Σ c·b' of the record's channel (zero for a basis without noise).
  // A basis without noise (every fit but FitNoisyBasis's) skips the derivatives' work.
  constexpr bool kNoisy = !std::is_same_v<D, NoDerivatives>;
  auto slope = [&](const PixelRecord& r, int c, const Eigen::VectorXd& coef) {
    if constexpr (!kNoisy) return 0.0;
    std::fill(d1.begin(), d1.end(), 0.0);
    std::fill(d2.begin(), d2.end(), 0.0);
    if (coef.size() == 0 || !derivatives(r, c, d1.data(), d2.data())) return 0.0;
    double v = 0;
    for (int a = 0; a < coef.size(); ++a) v += coef[a] * d1[a];
    return v;
  };
  // A basis is mostly zeros (one column per region, of which a record has one): only its
  // nonzero entries are accumulated (the sums are the same: adding a zero product changes none).
  std::vector<int> nz(k);
  for (size_t i = 0; i < records_.size(); ++i) {
    const PixelRecord& r = records_[i];
    if (r.outlier) continue;
    for (int c = 0; c < 3; ++c) {
      std::fill(b.begin(), b.end(), 0.0);
      basis(r, c, b.data());
      const double s = r.sim[c], y0 = double(r.recorded[c]) - s, y = y0 - offset(r, c);
      double* st = &stats[((size_t(cell_[i]) * 3 + c) * 2 + (r.held_out ? 1 : 0)) * stride];
      st[0] += s * s, st[1] += s * y, st[2] += y * y;
      st[stride - 3] += r.sim_var[c];
      st[stride - 2] += s * y0, st[stride - 1] += y0 * y0;
      int n = 0;
      for (int a = 0; a < k; ++a) {
        if (b[a] != 0) nz[n++] = a;
      }
      for (int ia = 0; ia < n; ++ia) {
        const int a = nz[ia];
        st[3 + a] += s * b[a];
        st[3 + k + a] += b[a] * y;
        double* row = st + 3 + 2 * k + a * k;
        for (int ie = 0; ie < n; ++ie) row[nz[ie]] += b[a] * b[nz[ie]];
      }
      if constexpr (!kNoisy) continue;
      std::fill(d1.begin(), d1.end(), 0.0);
      std::fill(d2.begin(), d2.end(), 0.0);
      const double v = r.sim_var[c];
      if (v > 0 && derivatives(r, c, d1.data(), d2.data())) {
        for (int a = 0; a < k; ++a) {
          st[3 + a] -= v * (d1[a] + 0.5 * s * d2[a]);
          st[3 + k + a] -= v * (0.5 * y * d2[a] - d1[a]);
          double* row = st + 3 + 2 * k + a * k;
          for (int e = 0; e < k; ++e) {
            row[e] -= v * (d1[a] * d1[e] + 0.5 * (b[a] * d2[e] + d2[a] * b[e]));
          }
        }
      }
    }
  }
  ResidualFit fit = Solve(k, stats, noise_free, k_base);
  if (fit.coef.size() == 0) return fit;
  const Eigen::VectorXd& before_coef = fit.base_coef;  // empty: the plain residual
  // Held-out gain per block (photo, block_px square) for its standard error.
  // Relative gain per block (gain / the block's error before), so that a few bright blocks
  // cannot carry the significance on their own.
  // Only blocks where the candidate changes the model count (its support): a highlight's change
  // is not diluted by the blocks it never touches.
  std::unordered_map<int64_t, std::pair<double, double>> gains;
  for (size_t i = 0; i < records_.size(); ++i) {
    const PixelRecord& r = records_[i];
    if (r.outlier || !r.held_out) continue;
    double g = 0, e = 0;
    bool support = false;
    for (int c = 0; c < 3; ++c) {
      std::fill(b.begin(), b.end(), 0.0);
      basis(r, c, b.data());
      const double s = r.sim[c], y0 = double(r.recorded[c]) - s, y = y0 - offset(r, c);
      support |= y != y0 || std::any_of(b.begin(), b.end(), [](double v) { return v != 0; });
      double cb = 0, cb0 = 0;
      for (int a = 0; a < k; ++a) cb += fit.coef[a] * b[a];
      for (int a = 0; a < before_coef.size(); ++a) cb0 += before_coef[a] * b[a];
      const double a0 = NuisanceCoef(stats, k, size_t(cell_[i]), c, before_coef, noise_free);
      const double a1 = NuisanceCoef(stats, k, size_t(cell_[i]), c, fit.coef, noise_free);
      const double r0 = y0 - cb0 - a0 * s;
      g += r0 * r0 - (y - cb - a1 * s) * (y - cb - a1 * s);
      // The render's noise in the residual, (1 + a + c·b')² var: its change is not the
      // candidate's gain.
      if (noise_free) {
        const double n0 = 1 + a0 + slope(r, c, before_coef), n1 = 1 + a1 + slope(r, c, fit.coef);
        g -= (n0 * n0 - n1 * n1) * double(r.sim_var[c]);
      }
      e += r0 * r0;
    }
    if (!support) continue;
    auto& acc =
        gains[(int64_t(r.photo) << 40) + (int64_t(r.y / block_px_) << 20) + r.x / block_px_];
    acc.first += g;
    acc.second += e;
  }
  std::vector<double> list;
  std::vector<std::pair<double, double>> blocks;
  for (const auto& [key, ge] : gains) {
    if (ge.second > 0) list.push_back(ge.first / ge.second), blocks.push_back(ge);
  }
  // The candidate's z only decides which candidates are refitted (the step gate, on the refit,
  // guards against false alarms): the larger of the mean relative gain's z and the step gate's
  // BlockGainZ, so that an effect seen in a few blocks (a highlight on one wall: large gains in
  // its few blocks, the path tracer's noise in the many others its basis touches) is refitted.
  fit.z = std::max(Z(list), BlockGainZ(blocks));
  return fit;
}

}  // namespace igi::diagnose
