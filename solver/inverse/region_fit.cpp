#include "solver/inverse/region_fit.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <type_traits>
#include <utility>

#include "solver/inverse/numeric.h"
#include "solver/render/brdf.h"
#include "tools/common/enum_names.h"
#include "tools/common/progress.h"

namespace igi::solver {

render::LobeWeights LobeWeight(recon::BrdfModel model, double alpha_x, double alpha_y, double ior,
                               const Eigen::Vector3d& wo, const Eigen::Vector3d& wi) {
  return render::SpecularWeights<double>(model, alpha_x, alpha_y, ior, wo, wi);
}

namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

// Ends a Ceres solve at its next iteration once cancellation is requested (Ctrl-C in the Python
// package), so that a long fit does not run to the end before the job stops.
class CancelCallback : public ceres::IterationCallback {
 public:
  ceres::CallbackReturnType operator()(const ceres::IterationSummary&) override {
    return CancelRequested() ? ceres::SOLVER_ABORT : ceres::SOLVER_CONTINUE;
  }
};

struct Prepared {
  std::vector<Eigen::Vector3d> w;  // residual weights per sample and channel
  std::vector<Eigen::Vector3d> a;  // E/π
};

Prepared Prepare(const RegionFitInput& in) {
  // Shot-noise weights (variance ∝ level) from a proxy of each sample's level (the region's mean
  // reflectance ratio times its irradiance), not from the observed value: weights that follow
  // the photos' noise would bias the fit low. With variance ∝ E the albedo estimate is a ratio
  // of sums, Σ L / Σ E/π, which noise in the gathered E does not bias the way a mean of ratios
  // would.
  Prepared p;
  Eigen::Vector3d sum_l = Eigen::Vector3d::Zero(), sum_e = sum_l;
  for (const FitSample& s : in.samples) {
    sum_l += s.observed.cwiseMax(0.0);
    sum_e += s.irradiance / render::kPi;
  }
  const size_t n = std::max<size_t>(1, in.samples.size());
  const Eigen::Vector3d mean = sum_l / n;
  for (const FitSample& s : in.samples) {
    Eigen::Vector3d w;
    for (int c = 0; c < 3; ++c) {
      const double ratio = sum_e[c] > 0 ? sum_l[c] / sum_e[c] : 0.0;
      w[c] = 1.0 /
             std::sqrt((ratio * s.irradiance[c] / render::kPi + 0.1 * mean[c]) * mean[c] + 1e-24);
    }
    p.w.push_back(w);
    p.a.push_back(s.irradiance / render::kPi);
  }
  return p;
}

// The scalar value of a double or a Ceres Jet (LobeTable::Term's cut-off test).
inline double ScalarPart(double x) { return x; }
template <typename J, int N>
double ScalarPart(const ceres::Jet<J, N>& x) {
  return x.a;
}

// The lobe of every sample at one α: ρs_c·t_c + o_c, with o the part that ρs does not scale (the
// microfacet models' grazing Fresnel, LobeWeights in solver/render/brdf.h; zero for Ward's lobes).
//
// The incident lists are Monte Carlo estimates, so t is noisy, and a least-squares slope on a
// noisy column is biased toward zero (regression dilution): ρs low, ρd high, most on a faint
// broad lobe whose true t varies little from sample to sample. `half` is t with the Monte Carlo
// rays of each incident list (FitSample::incident_rays_from) halved: its exact samples, and its
// even-indexed rays twice; the odd rays give 2t − half, an independent estimate of the same t,
// and Σ half·(2t − half) estimates Σ t² without the rays' noise (SolveLinear). Where a table
// does not split its rows (the microfacet lobes), or a list has no rays, half is t.
struct LobeTerms {
  std::vector<Eigen::Vector3d> t, o, half;
  Eigen::Vector3d Lobe(size_t i, const Eigen::Vector3d& rho_s) const {
    return rho_s.cwiseProduct(t[i]) + o[i];
  }
};

// The specular terms of every sample from a per-incident-sample table of the α-independent
// factors, computed once per region fit (the α search evaluates them at dozens of α).
// Ward's lobes: S·W·v = exp(−(qx/αx² + qy/αy²))·g·v / (αx·αy) (SpecularFactorParts,
// solver/render/brdf.h; Fresnel folded into g). Each sample's entries (a row) are sorted by
// qx + qy, so a sum stops at the first entry whose exponent is beyond kMaxExponent (exp(−60):
// nothing).
// The microfacet lobes (solver/render/microfacet.h): S = D·G2/(4 cosθo cosθi) with
// D = d(Q)/(π αx αy cos⁴θh), Q = qx/αx² + qy/αy², d = 1/(1 + Q)² (GGX) or exp(−Q) (Beckmann), and
// G2 = 1/(1 + Λ(wo) + Λ(wi)), Λ a function of a² = αx²·lx + αy²·ly with (lx, ly) the squared
// tangents of the direction along x and y; the entry keeps qx, qy, wi's (lx, ly) and g·v split
// into Schlick's (1 − m) part (t) and m part (o). Rows stop where d has fallen below 1e-9 of its
// peak (GGX: Q > 3·10⁴, which leaves out 3·10⁻⁵ of its normals; Beckmann as Ward's).
// Used by the α search (double) and by Ceres' polish (Jets), so both see the same lobe.
class LobeTable {
 public:
  // Built once per region fit from all its samples; any subset of them (the held-albedo
  // variant's) finds its rows by incident range (Rows).
  explicit LobeTable(const RegionFitInput& in)
      : model_(in.model),
        shape_(recon::Lobe(in.model)),
        microfacet_(recon::IsMicrofacet(in.model)) {
    if (!recon::HasSpecularLobe(in.model)) return;
    std::vector<std::pair<const IncidentLocal*, int>> order;  // (incident, sample)
    order.reserve(in.samples.size());
    for (size_t i = 0; i < in.samples.size(); ++i) {
      order.emplace_back(in.samples[i].incident, int(i));
    }
    std::sort(order.begin(), order.end());
    starts_.reserve(order.size());
    begin_.reserve(order.size() + 1);
    // At most one entry per incident sample: reserved once (grown by doubling, the arrays held
    // up to twice the region's incident light).
    for (std::vector<float>* v : {&qx_, &qy_, &qs_, &gr_, &gg_, &gb_, &half_})
      v->reserve(in.incident.size());
    if (microfacet_) {
      for (std::vector<float>* v : {&lx_, &ly_, &ls_, &orr_, &og_, &ob_})
        v->reserve(in.incident.size());
    }
    struct Entry {
      float qx, qy, lx, ly;
      Eigen::Vector3f gv, ov;
      float half;  // its weight in LobeTerms::half
    };
    std::vector<Entry> row;
    for (const auto& [start, i] : order) {
      const FitSample& s = in.samples[i];
      starts_.push_back(start);
      begin_.push_back(static_cast<int>(qx_.size()));
      blur2_.push_back(std::max(0.0, s.lobe_blur2));
      const Eigen::Vector3d wo = s.wo.cast<double>();
      if (microfacet_) {
        const double z2 = std::max(wo.z() * wo.z(), 1e-300);
        wo_l_.push_back({wo.x() * wo.x() / z2, wo.y() * wo.y() / z2});
      }
      row.clear();
      for (int64_t k = 0; k < s.incident_count; ++k) {
        const IncidentLocal& inc = s.incident[k];
        const Eigen::Vector3d wi = inc.Wi().cast<double>();
        const Eigen::Vector3d v = inc.Value().cast<double>();
        Entry e{};
        // An exact sample counts in both halves, a ray in one: even-indexed rays (from the
        // first) twice.
        e.half = k < s.incident_rays_from              ? 1.0f
                 : (k - s.incident_rays_from) % 2 == 0 ? 2.0f
                                                       : 0.0f;
        if (microfacet_) {
          if (!(wo.z() > 0.0) || !(wi.z() > 0.0)) continue;
          const Eigen::Vector3d h = wo + wi;
          const double hz2 = h.z() * h.z(), h2 = h.squaredNorm();
          e.qx = float(h.x() * h.x() / hz2), e.qy = float(h.y() * h.y() / hz2);
          e.lx = float(wi.x() * wi.x() / (wi.z() * wi.z()));
          e.ly = float(wi.y() * wi.y() / (wi.z() * wi.z()));
          // 1/(π cos⁴θh · 4 cosθo cosθi), cos⁴θh = hz⁴/|h|⁴.
          const double g = h2 * h2 / (render::kPi * hz2 * hz2 * 4.0 * wo.z() * wi.z());
          const double m = render::microfacet::SchlickWeight<double>(wo, wi);
          e.gv = (g * (1.0 - m) * v).cast<float>();
          e.ov = (g * m * v).cast<float>();
          if (!(g > 0.0) || !e.gv.allFinite() || !e.ov.allFinite()) continue;
        } else {
          double qx = 0, qy = 0, g = 0;
          if (!render::SpecularFactorParts(in.model, wo, wi, &qx, &qy, &g)) continue;
          if (recon::HasFresnel(in.model)) g *= render::FresnelWeight<double>(in.ior, wo, wi);
          const Eigen::Vector3d gv = g * v;
          if (!(g > 0.0) || !gv.allFinite()) continue;
          e.qx = float(qx), e.qy = float(qy), e.gv = gv.cast<float>();
        }
        row.push_back(e);
      }
      std::sort(row.begin(), row.end(),
                [](const Entry& a, const Entry& b) { return a.qx + a.qy < b.qx + b.qy; });
      for (const Entry& e : row) {
        qx_.push_back(e.qx), qy_.push_back(e.qy), qs_.push_back(e.qx + e.qy);
        gr_.push_back(e.gv[0]), gg_.push_back(e.gv[1]), gb_.push_back(e.gv[2]);
        half_.push_back(e.half);
        if (microfacet_) {
          lx_.push_back(e.lx), ly_.push_back(e.ly), ls_.push_back(e.lx + e.ly);
          orr_.push_back(e.ov[0]), og_.push_back(e.ov[1]), ob_.push_back(e.ov[2]);
        }
      }
    }
    begin_.push_back(static_cast<int>(qx_.size()));
  }

  // The row of each sample of `in` (the table's input or a subset of its samples); −1: none.
  std::vector<int> Rows(const RegionFitInput& in) const {
    std::vector<int> rows(in.samples.size(), -1);
    for (size_t i = 0; i < in.samples.size(); ++i) {
      const auto it = std::lower_bound(starts_.begin(), starts_.end(), in.samples[i].incident);
      if (it != starts_.end() && *it == in.samples[i].incident) {
        rows[i] = int(it - starts_.begin());
      }
    }
    return rows;
  }

  // One row's terms at (αx, αy) (Ceres' polish: T a double or a Jet): the part per unit ρs (t)
  // and the part ρs does not scale (o, zero for Ward's lobes); without the held-out albedo's
  // share (Terms adds it).
  template <typename T>
  std::pair<Eigen::Matrix<T, 3, 1>, Eigen::Matrix<T, 3, 1>> Term(int row, const T& ax,
                                                                 const T& ay) const {
    using std::exp;
    using std::sqrt;
    Eigen::Matrix<T, 3, 1> sum = Eigen::Matrix<T, 3, 1>::Zero(), off = sum;
    if (row < 0) return {sum, off};
    const T ax2 = ax * ax + T(blur2_[row]), ay2 = ay * ay + T(blur2_[row]);
    if (shape_ == recon::LobeShape::kGgx && !recon::IsAnisotropic(model_)) {
      // One roughness: the sums and their derivatives in a² in double precision, then onto a².
      Eigen::Vector3d t, o, dt, do_;
      IsotropicGgxRowDerivative(row, ScalarPart(ax2), &t, &o, &dt, &do_);
      for (int c = 0; c < 3; ++c) {
        sum[c] = Linearised(t[c], dt[c], ax2);
        off[c] = Linearised(o[c], do_[c], ax2);
      }
      return {sum, off};
    }
    if (microfacet_) {
      MicrofacetRow<T>(row, ax2, ay2, &sum, &off);
      return {sum, off};
    }
    const T ix = T(1.0) / ax2, iy = T(1.0) / ay2;
    const double ix0 = ScalarPart(ix), iy0 = ScalarPart(iy), imin = std::min(ix0, iy0);
    for (int k = begin_[row]; k < begin_[row + 1]; ++k) {
      if (imin * double(qs_[k]) >= kMaxExponent) break;
      if (double(qx_[k]) * ix0 + double(qy_[k]) * iy0 >= kMaxExponent) continue;
      const T f = exp(-(T(double(qx_[k])) * ix + T(double(qy_[k])) * iy));
      sum[0] += f * double(gr_[k]), sum[1] += f * double(gg_[k]), sum[2] += f * double(gb_[k]);
    }
    return {sum / sqrt(ax2 * ay2), off};
  }

  // The terms for every sample of `in` (its rows from Rows(in)), t less the held-out albedo's
  // own lobe where `in` fits with it (RegionFitInput::use_held_albedo). The α search's inner
  // loop: for Ward's lobes the exponentials of a row up to its cut-off in one vectorised pass,
  // then their weighted sums.
  LobeTerms Terms(const RegionFitInput& in, const std::vector<int>& rows, double ax,
                  double ay) const {
    LobeTerms out;
    out.t.assign(in.samples.size(), Eigen::Vector3d::Zero());
    out.o.assign(in.samples.size(), Eigen::Vector3d::Zero());
    out.half = out.t;
    if (!recon::HasSpecularLobe(model_)) return out;
    std::vector<float> f;
    for (size_t i = 0; i < in.samples.size(); ++i) {
      const FitSample& s = in.samples[i];
      Eigen::Vector3d sum = Eigen::Vector3d::Zero(), half = Eigen::Vector3d::Constant(kNan);
      if (rows[i] >= 0 && shape_ == recon::LobeShape::kGgx && ax == ay) {
        IsotropicGgxRow(rows[i], ax * ax + blur2_[rows[i]], &f, &sum, &out.o[i]);
      } else if (rows[i] >= 0 && microfacet_) {
        MicrofacetRow<double>(rows[i], ax * ax + blur2_[rows[i]], ay * ay + blur2_[rows[i]], &sum,
                              &out.o[i]);
      } else if (rows[i] >= 0) {
        // The row's lobe: α² widened by its pixel's spread of normals.
        const double ax2 = ax * ax + blur2_[rows[i]], ay2 = ay * ay + blur2_[rows[i]];
        const float ix = float(1.0 / ax2), iy = float(1.0 / ay2);
        const float cut = float(kMaxExponent * std::max(ax2, ay2));
        const double scale = 1.0 / std::sqrt(ax2 * ay2);
        const int b = begin_[rows[i]];
        const int e =
            int(std::lower_bound(qs_.begin() + b, qs_.begin() + begin_[rows[i] + 1], cut) -
                qs_.begin());
        f.resize(size_t(e - b));
        Exponentials(qx_.data() + b, qy_.data() + b, e - b, ix, iy, f.data());
        sum = WeightedSum(f.data(), b, e - b, gr_, gg_, gb_) * scale;
        for (int k = 0; k < e - b; ++k) f[size_t(k)] *= half_[size_t(b + k)];
        half = WeightedSum(f.data(), b, e - b, gr_, gg_, gb_) * scale;
      }
      if (!half.allFinite()) half = sum;
      if (in.use_held_albedo && !in.fit_rho_d && s.held_lobe.allFinite()) {
        const Eigen::Vector3d held = s.held_lobe.cwiseProduct(s.irradiance) / render::kPi;
        sum -= held, half -= held;
      }
      out.t[i] = sum;
      out.half[i] = half;
    }
    return out;
  }

 private:
  static constexpr double kMaxExponent = 60.0;
  static constexpr double kMaxGgxQ = 3e4;  // (1 + Q)² = 1e9

  // A microfacet row's sums at the widened (αx², αy²): t and o of Term.
  template <typename T>
  void MicrofacetRow(int row, const T& ax2, const T& ay2, Eigen::Matrix<T, 3, 1>* t,
                     Eigen::Matrix<T, 3, 1>* o) const {
    using std::exp;
    using std::sqrt;
    const T ix = T(1.0) / ax2, iy = T(1.0) / ay2;
    const double imin = std::min(ScalarPart(ix), ScalarPart(iy));
    const bool ggx = shape_ == recon::LobeShape::kGgx;
    const double cut = ggx ? kMaxGgxQ : kMaxExponent;
    const T lambda_o =
        render::microfacet::LambdaOfA2<T>(shape_, ax2 * wo_l_[row][0] + ay2 * wo_l_[row][1]);
    const T norm = T(1.0) / sqrt(ax2 * ay2);
    for (int k = begin_[row]; k < begin_[row + 1]; ++k) {
      if (imin * double(qs_[k]) >= cut) break;
      const T q = T(double(qx_[k])) * ix + T(double(qy_[k])) * iy;
      T d;
      if (ggx) {
        const T d1 = T(1.0) + q;
        d = T(1.0) / (d1 * d1);
      } else {
        d = exp(-q);
      }
      const T g2 = T(1.0) / (T(1.0) + lambda_o +
                             render::microfacet::LambdaOfA2<T>(
                                 shape_, ax2 * T(double(lx_[k])) + ay2 * T(double(ly_[k]))));
      const T w = d * g2 * norm;
      (*t)[0] += w * double(gr_[k]), (*t)[1] += w * double(gg_[k]), (*t)[2] += w * double(gb_[k]);
      (*o)[0] += w * double(orr_[k]), (*o)[1] += w * double(og_[k]), (*o)[2] += w * double(ob_[k]);
    }
  }

  // MicrofacetRow of an isotropic GGX lobe at a² = `a2` (the α search's inner loop), in one
  // single-precision pass over the row up to its cut-off: with s = √(1 + a²·tan²θ) for wo and
  // wi, 1 + Λo + Λi = (so + si)/2, so each entry's D·G2 is 2/((1 + Q)²·(so + si)), Q = a²·qs.
  void IsotropicGgxRow(int row, double a2, std::vector<float>* f, Eigen::Vector3d* t,
                       Eigen::Vector3d* o) const {
    const int b = begin_[row];
    const int e =
        int(std::lower_bound(qs_.begin() + b, qs_.begin() + begin_[row + 1], float(kMaxGgxQ * a2)) -
            qs_.begin());
    f->resize(size_t(e - b));
    const float ia2 = float(1.0 / a2), a2f = float(a2);
    const float so = float(std::sqrt(1.0 + a2 * (wo_l_[row][0] + wo_l_[row][1])));
    const float* __restrict qs = qs_.data() + b;
    const float* __restrict ls = ls_.data() + b;
    float* __restrict out = f->data();
    for (int k = 0; k < e - b; ++k) {
      const float d1 = 1.0f + qs[k] * ia2;
      out[k] = 2.0f / (d1 * d1 * (so + std::sqrt(1.0f + a2f * ls[k])));
    }
    const double norm = 1.0 / a2;
    *t = WeightedSum(out, b, e - b, gr_, gg_, gb_) * norm;
    *o = WeightedSum(out, b, e - b, orr_, og_, ob_) * norm;
  }

  // IsotropicGgxRow's sums t, o at a² and their derivatives in a² (the polish's Jacobian), in
  // double precision: each entry's weight w = 2a²/((a² + qs)²·(so + si)) has
  // d ln w / d a² = 1/a² − 2/(a² + qs) − (so' + si')/(so + si), s' = tan²θ/(2s).
  void IsotropicGgxRowDerivative(int row, double a2, Eigen::Vector3d* t, Eigen::Vector3d* o,
                                 Eigen::Vector3d* dt, Eigen::Vector3d* d_o) const {
    t->setZero(), o->setZero(), dt->setZero(), d_o->setZero();
    const double lo = wo_l_[row][0] + wo_l_[row][1];
    const double so = std::sqrt(1.0 + a2 * lo), dso = lo / (2.0 * so);
    for (int k = begin_[row]; k < begin_[row + 1]; ++k) {
      const double qs = qs_[k];
      if (qs >= kMaxGgxQ * a2) break;
      const double si = std::sqrt(1.0 + a2 * double(ls_[k]));
      const double sum_s = so + si, aq = a2 + qs;
      const double w = 2.0 * a2 / (aq * aq * sum_s);
      const double dw = w * (1.0 / a2 - 2.0 / aq - (dso + double(ls_[k]) / (2.0 * si)) / sum_s);
      const Eigen::Vector3d g(gr_[k], gg_[k], gb_[k]), m(orr_[k], og_[k], ob_[k]);
      *t += w * g, *o += w * m, *dt += dw * g, *d_o += dw * m;
    }
  }

  // value + d_value·(x − x₀) as a T: the value itself for double, a Jet whose derivative part is
  // d_value times x's for a Jet.
  template <typename T>
  static T Linearised(double value, double d_value, const T& x) {
    if constexpr (std::is_same_v<T, double>) {
      return value;
    } else {
      T out(value);
      out.v = d_value * x.v;
      return out;
    }
  }

  static void Exponentials(const float* __restrict qx, const float* __restrict qy, int n, float ix,
                           float iy, float* __restrict f) {
    for (int k = 0; k < n; ++k) f[k] = ExpNonPositive(-(qx[k] * ix + qy[k] * iy));
  }
  // Σ f_k·(r, g, b)_k over entries [b, b + n), in two-lane double partial sums (SSE2 packets).
  static Eigen::Vector3d WeightedSum(const float* f, int b, int n, const std::vector<float>& r,
                                     const std::vector<float>& g, const std::vector<float>& bl) {
    using A2 = Eigen::Array2d;
    A2 sr = A2::Zero(), sg = sr, sb = sr;
    int k = 0;
    for (; k + 2 <= n; k += 2) {
      const A2 fk(f[k], f[k + 1]);
      sr += fk * A2(r[b + k], r[b + k + 1]);
      sg += fk * A2(g[b + k], g[b + k + 1]);
      sb += fk * A2(bl[b + k], bl[b + k + 1]);
    }
    Eigen::Vector3d sum(sr.sum(), sg.sum(), sb.sum());
    for (; k < n; ++k) sum += double(f[k]) * Eigen::Vector3d(r[b + k], g[b + k], bl[b + k]);
    return sum;
  }
  recon::BrdfModel model_;
  recon::LobeShape shape_;
  bool microfacet_;
  std::vector<const IncidentLocal*> starts_;  // each row's incident list, ascending
  std::vector<int> begin_;                    // each row's first entry (+1: the end)
  std::vector<double> blur2_;                 // each row's addition to α² (FitSample::lobe_blur2)
  std::vector<std::array<double, 2>> wo_l_;   // microfacet: each row's wo (lx, ly)
  // Per entry: h_x²/h_z², h_y²/h_z², their sum (ascending within a row), g·v (Ward: with the
  // Fresnel weight; microfacet: Schlick's (1 − m) part), and its weight in LobeTerms::half.
  std::vector<float> qx_, qy_, qs_, gr_, gg_, gb_, half_;
  // Microfacet entries: wi's (lx, ly) and their sum tan²θi, and g·v's Schlick m part.
  std::vector<float> lx_, ly_, ls_, orr_, og_, ob_;
};

// The linear part for given specular terms: ρs and per-slot ρd by least squares.
struct LinearSolution {
  double cost = std::numeric_limits<double>::infinity();
  Eigen::Vector3d rho_s = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> slot_rho_d;
  double sum_v2 = 0;  // Σ v² of the projected specular column (grey), for ρs's variance
  // ρs² times the incident lists' noise in Σ v² (the part of the cost that is the column's noise
  // alone, taken off `cost`).
  double noise_cost = 0;
};

// Σ v² without the noise's share from the split-half estimate Σ v_half·(2v − v_half), held
// within [½, 1] of Σ v² (a column more than half noise is not taken apart further).
double DenoisedSquares(double squares, double split) {
  return std::clamp(split, 0.5 * squares, squares);
}

// The lobe's part that ρs does not scale (LobeTerms::o) is taken off the observed radiance.
LinearSolution SolveLinear(const RegionFitInput& in, const Prepared& pr, const LobeTerms& lt,
                           bool per_patch) {
  const std::vector<Eigen::Vector3d>& t = lt.t;
  const int slots = per_patch ? in.num_slots : 1;
  std::vector<Eigen::Vector3d> A(slots, Eigen::Vector3d::Zero()), B = A, C = A, C_half = A;
  const size_t n = in.samples.size();
  auto slot_of = [&](size_t i) { return per_patch ? in.samples[i].slot : 0; };
  if (in.fit_rho_d) {
    for (size_t i = 0; i < n; ++i) {
      const Eigen::Vector3d w2 = pr.w[i].cwiseProduct(pr.w[i]);
      const int s = slot_of(i);
      A[s] += w2.cwiseProduct(pr.a[i]).cwiseProduct(pr.a[i]);
      B[s] += w2.cwiseProduct(pr.a[i]).cwiseProduct(in.samples[i].observed - lt.o[i]);
      C[s] += w2.cwiseProduct(pr.a[i]).cwiseProduct(t[i]);
      C_half[s] += w2.cwiseProduct(pr.a[i]).cwiseProduct(lt.half[i]);
    }
  }
  // u: the observed radiance less the albedo's share, v: the specular column less its share,
  // both projected off the albedo column; v_half the same of LobeTerms::half, whose product with
  // the other half's (2v − v_half) sums to Σ v² less the incident lists' noise.
  std::vector<Eigen::Vector3d> u(n), v(n), v_half(n);
  for (size_t i = 0; i < n; ++i) {
    const FitSample& smp = in.samples[i];
    const Eigen::Vector3d observed = smp.observed - lt.o[i];
    for (int c = 0; c < 3; ++c) {
      const double w = pr.w[i][c], a = pr.a[i][c];
      if (in.fit_rho_d) {
        const int s = slot_of(i);
        const double ratio_b = A[s][c] > 0 ? B[s][c] / A[s][c] : 0.0;
        const double ratio_c = A[s][c] > 0 ? C[s][c] / A[s][c] : 0.0;
        const double ratio_h = A[s][c] > 0 ? C_half[s][c] / A[s][c] : 0.0;
        u[i][c] = w * (observed[c] - a * ratio_b);
        v[i][c] = w * (t[i][c] - a * ratio_c);
        v_half[i][c] = w * (lt.half[i][c] - a * ratio_h);
      } else {
        u[i][c] = w * (observed[c] - smp.rho_d_known[c] * a);
        v[i][c] = w * t[i][c];
        v_half[i][c] = w * lt.half[i][c];
      }
    }
  }
  LinearSolution sol;
  const bool spec = recon::HasSpecularLobe(in.model);
  if (spec && (in.rho_s_grey || in.rho_s_rgb)) {
    sol.rho_s = in.rho_s_rgb ? *in.rho_s_rgb : Eigen::Vector3d::Constant(*in.rho_s_grey);
  } else if (spec && in.grey_specular) {
    double uv = 0, vv = 0, vv_split = 0;
    for (size_t i = 0; i < n; ++i) {
      uv += u[i].dot(v[i]);
      vv += v[i].squaredNorm();
      vv_split += v_half[i].dot(2 * v[i] - v_half[i]);
    }
    const double vv_true = DenoisedSquares(vv, vv_split);
    sol.rho_s.setConstant(vv_true > 0 ? std::max(0.0, uv / vv_true) : 0.0);
    sol.sum_v2 = vv_true;
    sol.noise_cost = sol.rho_s[0] * sol.rho_s[0] * (vv - vv_true);
  } else if (spec) {
    for (int c = 0; c < 3; ++c) {
      double uv = 0, vv = 0, vv_split = 0;
      for (size_t i = 0; i < n; ++i) {
        uv += u[i][c] * v[i][c];
        vv += v[i][c] * v[i][c];
        vv_split += v_half[i][c] * (2 * v[i][c] - v_half[i][c]);
      }
      const double vv_true = DenoisedSquares(vv, vv_split);
      sol.rho_s[c] = vv_true > 0 ? std::max(0.0, uv / vv_true) : 0.0;
      sol.sum_v2 += vv_true / 3;
      sol.noise_cost += sol.rho_s[c] * sol.rho_s[c] * (vv - vv_true);
    }
  }
  // The cost less the incident lists' noise in the specular column (ρs²·its share of Σ v²), so
  // that the α search compares the lobes' fits, not their noise.
  sol.cost = -sol.noise_cost;
  for (size_t i = 0; i < n; ++i) sol.cost += (u[i] - v[i].cwiseProduct(sol.rho_s)).squaredNorm();
  sol.slot_rho_d.assign(slots, Eigen::Vector3d::Constant(kNan));
  if (in.fit_rho_d) {
    for (int s = 0; s < slots; ++s) {
      for (int c = 0; c < 3; ++c) {
        if (A[s][c] > 0)
          sol.slot_rho_d[s][c] = std::max(0.0, (B[s][c] - sol.rho_s[c] * C[s][c]) / A[s][c]);
      }
    }
  }
  return sol;
}

struct AlphaSearch {
  double ax = 0.1, ay = 0.1;
  LinearSolution linear;
  double curvature_log_alpha = kNan;  // d²cost/d(log α)² at the minimum (isotropic)
};

// Minimises the projected cost over α (or αx, αy).
AlphaSearch SearchAlpha(const RegionFitInput& in, const Prepared& pr, bool per_patch,
                        const LobeTable& table) {
  AlphaSearch best;
  const bool aniso = recon::IsAnisotropic(in.model);
  const std::vector<int> rows = table.Rows(in);
  auto eval = [&](double ax, double ay) {
    return SolveLinear(in, pr, table.Terms(in, rows, ax, ay), per_patch);
  };
  if (!recon::HasSpecularLobe(in.model)) {
    best.linear = eval(0.1, 0.1);
    return best;
  }
  const std::optional<double> known_x = aniso ? in.alpha_x : in.alpha;
  const std::optional<double> known_y = aniso ? in.alpha_y : in.alpha;
  const double lo = std::log(0.005), hi = std::log(1.0);
  auto minimise = [](double a, double b, auto&& f) { return BrentMinimum(a, b, 1e-4, 40, f); };
  if (!aniso) {
    if (known_x) {
      best.ax = best.ay = *known_x;
      best.linear = eval(best.ax, best.ay);
      return best;
    }
    // The solution at log α = la, with the cost's curvature there (for σ_α).
    auto finish = [&](double la) {
      best.ax = best.ay = std::exp(la);
      best.linear = eval(best.ax, best.ay);
      const double h = 0.02;
      const double cp = eval(std::exp(la + h), std::exp(la + h)).cost;
      const double cm = eval(std::exp(la - h), std::exp(la - h)).cost;
      best.curvature_log_alpha = (cp + cm - 2 * best.linear.cost) / (h * h);
      return best;
    };
    if (in.alpha_hint && *in.alpha_hint > 0) {
      // A window of ±0.4 in log α around the hint; accepted unless the minimum sits at its edge.
      const double c = std::log(*in.alpha_hint), a = std::max(lo, c - 0.4),
                   b = std::min(hi, c + 0.4);
      const double la =
          minimise(a, b, [&](double x) { return eval(std::exp(x), std::exp(x)).cost; });
      if (la > a + 0.02 && la < b - 0.02) return finish(la);
    }
    constexpr int kGrid = 28;
    double best_cost = std::numeric_limits<double>::infinity();
    int best_i = 0;
    for (int i = 0; i < kGrid; ++i) {
      const double la = lo + (hi - lo) * i / (kGrid - 1);
      const double c = eval(std::exp(la), std::exp(la)).cost;
      if (c < best_cost) best_cost = c, best_i = i;
    }
    const double step = (hi - lo) / (kGrid - 1);
    const double a = lo + step * std::max(0, best_i - 1),
                 b = lo + step * std::min(kGrid - 1, best_i + 1);
    return finish(minimise(a, b, [&](double x) { return eval(std::exp(x), std::exp(x)).cost; }));
  }
  // Anisotropic: a coarse grid, then alternating Brent minimisations.
  double bx = known_x.value_or(0.1), by = known_y.value_or(0.1);
  if (!known_x || !known_y) {
    constexpr int kGrid = 12;
    double best_cost = std::numeric_limits<double>::infinity();
    for (int i = 0; i < kGrid; ++i) {
      for (int j = 0; j < kGrid; ++j) {
        const double x = known_x ? *known_x : std::exp(lo + (hi - lo) * i / (kGrid - 1));
        const double y = known_y ? *known_y : std::exp(lo + (hi - lo) * j / (kGrid - 1));
        const double c = eval(x, y).cost;
        if (c < best_cost) best_cost = c, bx = x, by = y;
      }
    }
    for (int round = 0; round < 3; ++round) {
      const double w = (hi - lo) / 11.0 / (round + 1);
      if (!known_x) {
        bx = std::exp(minimise(std::log(bx) - w, std::log(bx) + w,
                               [&](double x) { return eval(std::exp(x), by).cost; }));
      }
      if (!known_y) {
        by = std::exp(minimise(std::log(by) - w, std::log(by) + w,
                               [&](double y) { return eval(bx, std::exp(y)).cost; }));
      }
    }
  }
  best.ax = bx;
  best.ay = by;
  best.linear = eval(bx, by);
  return best;
}

// Ceres residual of one sample for the constant-albedo model; parameter blocks in the order
// ρd (3, if fitted), ρs (1 or 3, if fitted), α (1 or 2, if fitted).
struct SampleResidual {
  const RegionFitInput* in = nullptr;
  const FitSample* s = nullptr;
  const LobeTable* table = nullptr;
  int row = -1;  // s's row in the table
  Eigen::Vector3d w, a;
  int block_d = -1, block_s = -1, block_a = -1;
  Eigen::Vector3d rho_d_fixed, rho_s_fixed;
  double ax_fixed = 0.1, ay_fixed = 0.1;

  template <typename T>
  bool operator()(T const* const* p, T* residual) const {
    using V3 = Eigen::Matrix<T, 3, 1>;
    V3 rho_d = rho_d_fixed.cast<T>(), rho_s = rho_s_fixed.cast<T>();
    if (block_d >= 0) rho_d = V3(p[block_d][0], p[block_d][1], p[block_d][2]);
    if (block_s >= 0) {
      rho_s = in->grey_specular ? V3(p[block_s][0], p[block_s][0], p[block_s][0])
                                : V3(p[block_s][0], p[block_s][1], p[block_s][2]);
    }
    T ax = T(ax_fixed), ay = T(ay_fixed);
    if (block_a >= 0) {
      ax = p[block_a][0];
      ay = recon::IsAnisotropic(in->model) ? p[block_a][1] : p[block_a][0];
    }
    const auto [t, o] = table->Term<T>(row, ax, ay);
    for (int c = 0; c < 3; ++c) {
      residual[c] = T(w[c]) * (rho_d[c] * a[c] + rho_s[c] * t[c] + o[c] - s->observed[c]);
    }
    return true;
  }
};

struct Polish {
  bool ok = false;
  std::string message;
  Eigen::Vector3d rho_d, sigma_rho_d = Eigen::Vector3d::Constant(kNan);
  Eigen::Vector3d rho_s;
  double ax = 0, ay = 0, sigma_rho_s = kNan, sigma_ax = kNan, sigma_ay = kNan;
};

Polish PolishConstant(const RegionFitInput& in, const Prepared& pr, const AlphaSearch& start,
                      const RegionFitOptions& options, const LobeTable& table) {
  Polish out;
  const bool spec = recon::HasSpecularLobe(in.model);
  const bool aniso = recon::IsAnisotropic(in.model);
  const bool fit_s = spec && !in.rho_s_grey && !in.rho_s_rgb;
  const bool fit_a = spec && !(aniso ? (in.alpha_x && in.alpha_y) : bool(in.alpha));
  out.rho_d =
      start.linear.slot_rho_d.empty() ? Eigen::Vector3d::Zero() : start.linear.slot_rho_d[0];
  out.rho_s = start.linear.rho_s;
  out.ax = start.ax;
  out.ay = start.ay;
  if (!in.fit_rho_d && !fit_s && !fit_a) return out;
  double d[3] = {out.rho_d[0], out.rho_d[1], out.rho_d[2]};
  double rs[3] = {out.rho_s[0], out.rho_s[1], out.rho_s[2]};
  double al[2] = {out.ax, out.ay};
  std::vector<double*> blocks;
  int block_d = -1, block_s = -1, block_a = -1;
  const int ns = in.grey_specular ? 1 : 3, na = aniso ? 2 : 1;
  ceres::Problem problem;
  const std::vector<int> rows = table.Rows(in);
  for (size_t i = 0; i < in.samples.size(); ++i) {
    auto* r = new SampleResidual;
    r->row = rows[i];
    r->in = &in;
    r->s = &in.samples[i];
    r->table = &table;
    r->w = pr.w[i];
    r->a = pr.a[i];
    r->rho_d_fixed = in.samples[i].rho_d_known;
    r->rho_s_fixed = out.rho_s;
    r->ax_fixed = out.ax;
    r->ay_fixed = out.ay;
    auto* cost = new ceres::DynamicAutoDiffCostFunction<SampleResidual, 8>(r);
    blocks.clear();
    int b = 0;
    if (in.fit_rho_d) cost->AddParameterBlock(3), blocks.push_back(d), r->block_d = b++;
    if (fit_s) cost->AddParameterBlock(ns), blocks.push_back(rs), r->block_s = b++;
    if (fit_a) cost->AddParameterBlock(na), blocks.push_back(al), r->block_a = b++;
    block_d = r->block_d, block_s = r->block_s, block_a = r->block_a;
    cost->SetNumResiduals(3);
    problem.AddResidualBlock(cost, nullptr, blocks);
  }
  if (in.fit_rho_d) {
    for (int c = 0; c < 3; ++c) problem.SetParameterLowerBound(d, c, 0.0);
  }
  if (fit_s) {
    for (int c = 0; c < ns; ++c) problem.SetParameterLowerBound(rs, c, 0.0);
  }
  if (fit_a) {
    for (int c = 0; c < na; ++c) {
      // scene.json's range for α is (0, 1] (igi-render and the loader refuse more): a fit that
      // wants a broader lobe is held at 1, as the search's grid is.
      problem.SetParameterLowerBound(al, c, 0.002);
      problem.SetParameterUpperBound(al, c, 1.0);
    }
  }
  ceres::Solver::Options so;
  so.max_num_iterations = options.max_polish_iterations;
  so.linear_solver_type = ceres::DENSE_QR;
  so.num_threads = std::max(1, options.num_threads);
  so.logging_type = ceres::SILENT;
  CancelCallback cancel;
  so.callbacks.push_back(&cancel);
  ceres::Solver::Summary summary;
  ceres::Solve(so, &problem, &summary);
  if (CancelRequested()) throw Cancelled("region fit");
  out.ok = summary.IsSolutionUsable();
  out.message = summary.message;
  if (!out.ok) return out;
  if (in.fit_rho_d) out.rho_d = Eigen::Vector3d(d[0], d[1], d[2]);
  if (fit_s)
    out.rho_s =
        in.grey_specular ? Eigen::Vector3d::Constant(rs[0]) : Eigen::Vector3d(rs[0], rs[1], rs[2]);
  if (fit_a) out.ax = al[0], out.ay = aniso ? al[1] : al[0];
  // Covariance scaled by the residual variance (the weights are relative, not true sigmas).
  const int k = (in.fit_rho_d ? 3 : 0) + (fit_s ? ns : 0) + (fit_a ? na : 0);
  const double dof = std::max(1.0, 3.0 * in.samples.size() - k);
  const double s2 = 2.0 * summary.final_cost / dof;
  ceres::Covariance::Options co;
  co.algorithm_type = ceres::DENSE_SVD;
  co.null_space_rank = -1;
  ceres::Covariance cov(co);
  std::vector<const double*> params;
  if (in.fit_rho_d) params.push_back(d);
  if (fit_s) params.push_back(rs);
  if (fit_a) params.push_back(al);
  if (cov.Compute(params, &problem)) {
    std::vector<double> m(size_t(k) * k);
    if (cov.GetCovarianceMatrixInTangentSpace(params, m.data())) {
      int o = 0;
      auto sd = [&](int i) { return std::sqrt(std::max(0.0, m[size_t(i) * k + i] * s2)); };
      if (in.fit_rho_d) out.sigma_rho_d = Eigen::Vector3d(sd(0), sd(1), sd(2)), o = 3;
      if (fit_s) out.sigma_rho_s = sd(o), o += ns;
      if (fit_a) out.sigma_ax = sd(o), out.sigma_ay = aniso ? sd(o + 1) : sd(o);
    }
  }
  (void)block_d, (void)block_s, (void)block_a;
  return out;
}

double RelativeRms(const RegionFitInput& in, const LobeTerms& lt,
                   const std::vector<Eigen::Vector3d>& slot_rho_d, const Eigen::Vector3d& rho_s,
                   bool per_patch) {
  double num = 0, den = 0;
  for (size_t i = 0; i < in.samples.size(); ++i) {
    const FitSample& s = in.samples[i];
    Eigen::Vector3d rd = in.fit_rho_d ? slot_rho_d[per_patch ? s.slot : 0] : s.rho_d_known;
    if (!rd.allFinite()) continue;
    const Eigen::Vector3d pred = rd.cwiseProduct(s.irradiance) / render::kPi + lt.Lobe(i, rho_s);
    num += (pred - s.observed).squaredNorm();
    den += s.observed.squaredNorm();
  }
  return den > 0 ? std::sqrt(num / den) : 0.0;
}

// Each slot's albedo from its samples whose specular part is under 10 % of the radiance (least
// squares per channel); NaN for a slot without such a sample.
std::vector<Eigen::Vector3d> OffHighlightAlbedo(const RegionFitInput& in, const Prepared& pr,
                                                const LobeTerms& lt, const Eigen::Vector3d& rho_s) {
  std::vector<Eigen::Vector3d> num(in.num_slots, Eigen::Vector3d::Zero()), den = num;
  for (size_t i = 0; i < in.samples.size(); ++i) {
    const FitSample& s = in.samples[i];
    const Eigen::Vector3d spec = lt.Lobe(i, rho_s);
    if ((spec.array() > 0.1 * s.observed.array().max(0.0)).any()) continue;
    const Eigen::Vector3d w2 = pr.w[i].cwiseProduct(pr.w[i]);
    num[s.slot] += w2.cwiseProduct(pr.a[i]).cwiseProduct(s.observed - spec);
    den[s.slot] += w2.cwiseProduct(pr.a[i]).cwiseProduct(pr.a[i]);
  }
  std::vector<Eigen::Vector3d> out(in.num_slots, Eigen::Vector3d::Constant(kNan));
  for (int k = 0; k < in.num_slots; ++k) {
    for (int c = 0; c < 3; ++c) {
      if (den[k][c] > 0) out[k][c] = std::max(0.0, num[k][c] / den[k][c]);
    }
  }
  return out;
}

// Whether the per-patch albedos vary beyond their noise: the area-weighted spread of the
// slots' mean albedo must exceed 3 % of the mean and three times the spread noise alone gives.
bool AlbedoVaries(const RegionFitInput& in, const Prepared& pr, const LinearSolution& b,
                  const LobeTerms& lt, std::vector<int>* counts) {
  const int slots = in.num_slots;
  counts->assign(slots, 0);
  std::vector<double> info(slots, 0.0);
  double rss = 0;
  for (size_t i = 0; i < in.samples.size(); ++i) {
    const FitSample& s = in.samples[i];
    ++(*counts)[s.slot];
    for (int c = 0; c < 3; ++c) info[s.slot] += std::pow(pr.w[i][c] * pr.a[i][c], 2) / 3;
    if (!b.slot_rho_d[s.slot].allFinite()) continue;
    const Eigen::Vector3d pred = b.slot_rho_d[s.slot].cwiseProduct(pr.a[i]) + lt.Lobe(i, b.rho_s);
    if (pred.allFinite()) rss += (pr.w[i].cwiseProduct(pred - s.observed)).squaredNorm();
  }
  int used = 0;
  for (int s = 0; s < slots; ++s) used += (*counts)[s] > 0;
  const double s2 = rss / std::max(1.0, 3.0 * in.samples.size() - 3.0 * used - 2);
  double wsum = 0, mean = 0;
  for (int s = 0; s < slots; ++s) {
    if ((*counts)[s] < 3 || !b.slot_rho_d[s].allFinite()) continue;
    wsum += in.slot_area[s];
    mean += in.slot_area[s] * b.slot_rho_d[s].mean();
  }
  if (!(wsum > 0)) return false;
  mean /= wsum;
  double var = 0, noise = 0;
  for (int s = 0; s < slots; ++s) {
    if ((*counts)[s] < 3 || !b.slot_rho_d[s].allFinite()) continue;
    var += in.slot_area[s] * std::pow(b.slot_rho_d[s].mean() - mean, 2);
    noise += in.slot_area[s] * (info[s] > 0 ? s2 / info[s] / 3 : 0.0);
  }
  var /= wsum;
  noise /= wsum;
  return var > std::pow(0.03 * mean, 2) && var > 3 * noise;
}

// The samples whose held-out albedo is known, each with that albedo as its known ρd (in `held`,
// a copy of `in` with fit_rho_d off); false (and `held` unchanged) when fewer than a fifth of
// the samples, or fewer than 50, have one.
bool FitWithHeldAlbedo(const RegionFitInput& in, RegionFitInput* held) {
  std::vector<FitSample> kept;
  for (const FitSample& s : in.samples) {
    if (!s.rho_d_held.allFinite()) continue;
    kept.push_back(s);
    kept.back().rho_d_known = s.rho_d_held;
  }
  if (kept.size() < 50 || kept.size() * 5 < in.samples.size()) {
    held->use_held_albedo = false;
    return false;
  }
  held->samples = std::move(kept);
  held->use_held_albedo = true;
  return true;
}

}  // namespace

constexpr EnumNames<AlbedoModel, 2> kAlbedoModelNames{
    {{AlbedoModel::kConstant, "constant"}, {AlbedoModel::kPerPatch, "per_patch"}}};

std::string_view AlbedoModelName(AlbedoModel model) { return kAlbedoModelNames.Name(model); }
std::optional<AlbedoModel> AlbedoModelFromName(std::string_view name) {
  return kAlbedoModelNames.FromName(name);
}

namespace {

RegionFitResult FitLambertColumn(const RegionFitInput& in, const RegionFitOptions& options);

// `in` with each sample's irradiance replaced by Oren–Nayar's diffuse column A(σ)·E + B(σ)·G
// (`g`: G per sample).
RegionFitInput WithOrenNayarColumn(const RegionFitInput& in, const std::vector<Eigen::Vector3d>& g,
                                   double sigma) {
  RegionFitInput out;
  static_cast<RegionFitSettings&>(out) = in;
  out.diffuse = recon::DiffuseShape::kLambert;
  out.samples = in.samples;
  const double a = render::OrenNayarA(sigma), b = render::OrenNayarB(sigma);
  for (size_t i = 0; i < out.samples.size(); ++i) {
    out.samples[i].irradiance = a * in.samples[i].irradiance + b * g[i];
  }
  return out;
}

// The region fit with Oren–Nayar's diffuse term (RegionFitSettings::diffuse).
RegionFitResult FitOrenNayar(const RegionFitInput& in, const RegionFitOptions& options) {
  std::vector<Eigen::Vector3d> g(in.samples.size(), Eigen::Vector3d::Zero());
  for (size_t i = 0; i < in.samples.size(); ++i) {
    const FitSample& s = in.samples[i];
    const Eigen::Vector3d wo = s.wo.cast<double>();
    if (!(wo.z() > 0.0)) continue;
    for (int64_t k = 0; k < s.incident_count; ++k) {
      const Eigen::Vector3d wi = s.incident[k].Wi().cast<double>();
      if (wi.z() > 0.0)
        g[i] += render::OrenNayarG<double>(wo, wi) * s.incident[k].Value().cast<double>();
    }
  }
  double sigma = in.sigma.value_or(0.0);
  if (!in.sigma) {
    // The profile cost of σ: the α search's projected cost (ρd, ρs solved), with the weights of
    // Lambert's column at every σ so that the costs compare.
    const Prepared weights = Prepare(in);
    const LobeTable table(in);
    std::optional<double> hint = in.alpha_hint;
    auto cost = [&](double sg) {
      RegionFitInput on = WithOrenNayarColumn(in, g, sg);
      on.alpha_hint = hint;
      Prepared pr = Prepare(on);
      pr.w = weights.w;
      const AlphaSearch a = SearchAlpha(on, pr, false, table);
      if (recon::HasSpecularLobe(in.model) && !in.alpha) hint = a.ax;
      return a.linear.cost;
    };
    constexpr int kGrid = 11;
    double best = std::numeric_limits<double>::infinity();
    int best_i = 0;
    for (int i = 0; i < kGrid; ++i) {
      const double c = cost(double(i) / (kGrid - 1));
      if (c < best) best = c, best_i = i;
    }
    const double lo = std::max(0, best_i - 1) / double(kGrid - 1);
    const double hi = std::min(kGrid - 1, best_i + 1) / double(kGrid - 1);
    sigma = BrentMinimum(lo, hi, 1e-3, 30, cost);
  }
  RegionFitResult r = FitLambertColumn(WithOrenNayarColumn(in, g, sigma), options);
  r.sigma = sigma;
  return r;
}

// `in` with each sample's irradiance replaced by the coated base's column Σ_k T(cosθo)·
// T(cosθi_k)·v_k over its incident list.
RegionFitInput WithCoatedColumn(const RegionFitInput& in) {
  RegionFitInput out;
  static_cast<RegionFitSettings&>(out) = in;
  out.diffuse = recon::DiffuseShape::kLambert;
  out.samples = in.samples;
  render::BrdfParams coated;
  coated.diffuse = recon::DiffuseShape::kCoated;
  for (FitSample& s : out.samples) {
    const Eigen::Vector3d wo = s.wo.cast<double>();
    Eigen::Vector3d column = Eigen::Vector3d::Zero();
    for (int64_t k = 0; wo.z() > 0.0 && k < s.incident_count; ++k) {
      const Eigen::Vector3d wi = s.incident[k].Wi().cast<double>();
      if (wi.z() > 0.0)
        column += render::DiffuseFactor(coated, wo, wi) * s.incident[k].Value().cast<double>();
    }
    s.irradiance = column;
  }
  return out;
}

}  // namespace

RegionFitResult FitRegion(const RegionFitInput& in, const RegionFitOptions& options) {
  switch (in.diffuse) {
    case recon::DiffuseShape::kOrenNayar:
      return FitOrenNayar(in, options);
    case recon::DiffuseShape::kCoated:
      return FitLambertColumn(WithCoatedColumn(in), options);
    case recon::DiffuseShape::kLambert:
      break;
  }
  return FitLambertColumn(in, options);
}

namespace {

RegionFitResult FitLambertColumn(const RegionFitInput& in, const RegionFitOptions& options) {
  RegionFitResult r;
  r.samples = static_cast<int>(in.samples.size());
  if (in.samples.empty()) {
    r.message = "no observation";
    return r;
  }
  r.fitted = true;
  const Prepared pr = Prepare(in);
  const LobeTable table(in);  // every search, the polish and the terms below
  const AlphaSearch a = SearchAlpha(in, pr, false, table);
  const Polish pa = PolishConstant(in, pr, a, options, table);
  r.rho_d = pa.rho_d;
  r.rho_s = pa.rho_s;
  r.alpha = r.alpha_x = pa.ax;
  r.alpha_y = pa.ay;
  if (a.linear.noise_cost > 0 && !a.linear.slot_rho_d.empty()) {
    // The search's minimum has the incident lists' noise taken out (SolveLinear); Ceres'
    // polish minimises the plain squares, whose minimum that noise pulls toward a weaker lobe.
    // The polish gives the uncertainties.
    if (in.fit_rho_d) r.rho_d = a.linear.slot_rho_d[0];
    r.rho_s = a.linear.rho_s;
    r.alpha = r.alpha_x = a.ax;
    r.alpha_y = a.ay;
  }
  r.sigma_rho_d = pa.sigma_rho_d;
  r.sigma_rho_s = pa.sigma_rho_s;
  r.sigma_alpha = r.sigma_alpha_x = pa.sigma_ax;
  r.sigma_alpha_y = pa.sigma_ay;
  if (!pa.ok && !pa.message.empty()) r.message = "Ceres: " + pa.message;
  r.slot_rho_d.assign(in.num_slots, in.fit_rho_d ? r.rho_d : Eigen::Vector3d::Constant(kNan));
  r.slot_count.assign(in.num_slots, 0);
  for (const FitSample& s : in.samples) ++r.slot_count[s.slot];
  const std::vector<int> rows = table.Rows(in);
  LobeTerms t = table.Terms(in, rows, r.alpha_x, r.alpha_y);
  r.relative_rms = RelativeRms(in, t, {r.rho_d}, r.rho_s, false);
  if (!in.fit_rho_d || in.num_slots <= 1) return r;
  // Per-patch albedo from the observations off the highlights (specular part < 10 % of the
  // radiance): fitted freely per patch, a highlight that only one photo shows would be absorbed
  // into that patch's albedo instead of constraining ρs and α.
  LinearSolution patch;
  patch.rho_s = r.rho_s;
  patch.slot_rho_d = OffHighlightAlbedo(in, pr, t, r.rho_s);
  std::vector<int> counts;
  r.albedo_varies = in.albedo_varies ? *in.albedo_varies : AlbedoVaries(in, pr, patch, t, &counts);
  if (r.albedo_varies && !in.albedo_varies) {
    // More parameters must earn their place: over the patches of three samples or more (those
    // AlbedoVaries measured), the per-patch albedo's residual variance per degree of freedom
    // has to be under 0.81 of the constant albedo's (its rms 10 % lower). Per degree of freedom,
    // because a patch's albedo fits some of its own samples' noise: on a region of few samples
    // per patch the plain residual falls however uniform the albedo is.
    double rss_patch = 0, rss_constant = 0, values = 0;
    int patch_albedos = 0;
    for (int k = 0; k < in.num_slots; ++k) {
      patch_albedos += counts[k] >= 3 && patch.slot_rho_d[k].allFinite();
    }
    for (size_t i = 0; i < in.samples.size(); ++i) {
      const FitSample& s = in.samples[i];
      const Eigen::Vector3d& rd = patch.slot_rho_d[s.slot];
      if (counts[s.slot] < 3 || !rd.allFinite()) continue;
      const Eigen::Vector3d lobe = t.Lobe(i, r.rho_s);
      rss_patch += (rd.cwiseProduct(pr.a[i]) + lobe - s.observed).squaredNorm();
      rss_constant += (r.rho_d.cwiseProduct(pr.a[i]) + lobe - s.observed).squaredNorm();
      values += 3;
    }
    const double dof_patch = values - 3.0 * patch_albedos;
    r.albedo_varies = dof_patch > 0 && rss_patch / dof_patch < 0.81 * rss_constant / values;
  }
  if (!r.albedo_varies) return r;
  // The albedo varies: ρs and α again with each patch's albedo held (NaN: the region's), twice.
  // The held variant copies the samples but not their incident samples: the lobe table has what
  // the searches need of them (a region with every highlight sample has ~100 MB of them).
  RegionFitInput held;
  static_cast<RegionFitSettings&>(held) = in;
  held.samples = in.samples;
  held.fit_rho_d = false;
  AlphaSearch b;
  if (in.use_held_albedo && FitWithHeldAlbedo(in, &held)) {
    const Prepared ph = Prepare(held);
    b = SearchAlpha(held, ph, false, table);
    t = table.Terms(in, rows, b.ax, b.ay);
    patch.rho_s = b.linear.rho_s;
    patch.slot_rho_d = OffHighlightAlbedo(in, pr, t, b.linear.rho_s);
  }
  for (int round = 0; round < 2 && !held.use_held_albedo; ++round) {
    for (FitSample& smp : held.samples) {
      const Eigen::Vector3d& v = patch.slot_rho_d[smp.slot];
      smp.rho_d_known = v.allFinite() ? v : r.rho_d;
    }
    b = SearchAlpha(held, pr, false, table);
    t = table.Terms(in, rows, b.ax, b.ay);
    patch.rho_s = b.linear.rho_s;
    patch.slot_rho_d = OffHighlightAlbedo(in, pr, t, b.linear.rho_s);
  }
  r.albedo_model = AlbedoModel::kPerPatch;
  r.rho_s = b.linear.rho_s;
  r.alpha = r.alpha_x = b.ax;
  r.alpha_y = b.ay;
  r.slot_rho_d = patch.slot_rho_d;
  // The region's mean albedo with the lobe fitted: per patch Σ(L − specular)/Σ E/π over all its
  // samples (a ratio of sums, highlights included), then the area-weighted mean over the patches
  // that have samples. A ratio of sums over the whole region would weight each patch by its
  // sample count (the fit samples crowd around the highlights, near cameras give more pixels),
  // which biases the mean of a textured region toward the tiles that happen to lie there; the
  // patches' off-highlight albedos favour bright texels near the highlights.
  {
    std::vector<Eigen::Vector3d> num(in.num_slots, Eigen::Vector3d::Zero()), den = num;
    for (size_t i = 0; i < in.samples.size(); ++i) {
      const FitSample& smp = in.samples[i];
      const Eigen::Vector3d w2 = pr.w[i].cwiseProduct(pr.w[i]);
      const Eigen::Vector3d diffuse = smp.observed - t.Lobe(i, r.rho_s);
      num[smp.slot] += w2.cwiseProduct(pr.a[i]).cwiseProduct(diffuse);
      den[smp.slot] += w2.cwiseProduct(pr.a[i]).cwiseProduct(pr.a[i]);
    }
    Eigen::Vector3d sum = Eigen::Vector3d::Zero(), area = sum;
    for (int k = 0; k < in.num_slots; ++k) {
      const double area_k = k < int(in.slot_area.size()) ? in.slot_area[k] : 1.0;
      for (int c = 0; c < 3; ++c) {
        if (!(den[k][c] > 0)) continue;
        sum[c] += area_k * num[k][c] / den[k][c];
        area[c] += area_k;
      }
    }
    for (int c = 0; c < 3; ++c) {
      if (area[c] > 0) r.rho_d[c] = std::max(0.0, sum[c] / area[c]);
    }
  }
  for (Eigen::Vector3d& v : r.slot_rho_d) {
    if (!v.allFinite()) v = r.rho_d;
  }
  // Uncertainties from the projected problem: ρs from its normal equation, α from the
  // curvature of the profile cost in log α (the patches' albedos held).
  const double dof = std::max(1.0, 3.0 * held.samples.size() - 2);
  const double s2 = b.linear.cost / dof;
  r.sigma_rho_s = b.linear.sum_v2 > 0 ? std::sqrt(s2 / b.linear.sum_v2) : kNan;
  r.sigma_alpha = r.sigma_alpha_x = r.sigma_alpha_y =
      b.curvature_log_alpha > 0 ? r.alpha * std::sqrt(2 * s2 / b.curvature_log_alpha) : kNan;
  r.sigma_rho_d = Eigen::Vector3d::Constant(kNan);
  r.relative_rms = RelativeRms(in, t, r.slot_rho_d, r.rho_s, true);
  return r;
}

}  // namespace

}  // namespace igi::solver
