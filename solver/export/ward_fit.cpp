#include "solver/export/ward_fit.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace igi::exporter {
namespace {

// One (wo, wi) pair of the fitting grid with its weight cos²θi·cos²θo·dωi·dωo.
struct DirectionPair {
  Eigen::Vector3d wo, wi;
  double weight = 0;
};

// Pairs around the lobe of roughness `alpha_grid`: view elevations uniform in [0, 88°], half
// vectors with tanθh = alpha_grid·t (t in [0, 8]) and uniform azimuth; wi = wo mirrored about h,
// dωi = 4 (wo·ĥ) dωh.
std::vector<DirectionPair> BuildPairs(double alpha_grid, bool anisotropic,
                                      const LobeFitOptions& options) {
  std::vector<DirectionPair> pairs;
  const int n_o = options.theta_o_steps, n_h = options.half_steps;
  const int n_phi_o = anisotropic ? 8 : 1;
  const double theta_o_max = options.max_theta_o_deg * render::kPi / 180.0, t_max = 8.0;
  for (int io = 0; io < n_o; ++io) {
    const double theta_o = (io + 0.5) * theta_o_max / n_o;
    for (int jo = 0; jo < n_phi_o; ++jo) {
      const double phi_o =
          (jo + 0.5) * render::kPi / n_phi_o;  // lobes are symmetric under φ -> φ + π
      const Eigen::Vector3d wo(std::sin(theta_o) * std::cos(phi_o),
                               std::sin(theta_o) * std::sin(phi_o), std::cos(theta_o));
      const double w_o = std::cos(theta_o) * std::cos(theta_o) * std::sin(theta_o);
      for (int ih = 0; ih < n_h; ++ih) {
        const double t = (ih + 0.5) * t_max / n_h;
        const double theta_h = std::atan(alpha_grid * t);
        const double dtheta_dt = alpha_grid / (1.0 + alpha_grid * alpha_grid * t * t);
        for (int jh = 0; jh < n_h; ++jh) {
          const double phi_h = (jh + 0.5) * 2.0 * render::kPi / n_h;
          const Eigen::Vector3d h(std::sin(theta_h) * std::cos(phi_h),
                                  std::sin(theta_h) * std::sin(phi_h), std::cos(theta_h));
          const double c = wo.dot(h);
          if (c <= 0) continue;
          const Eigen::Vector3d wi = 2.0 * c * h - wo;
          if (wi.z() <= 1e-6) continue;
          const double d_omega_h = std::sin(theta_h) * dtheta_dt;
          pairs.push_back({wo, wi, w_o * wi.z() * wi.z() * 4.0 * c * d_omega_h});
        }
      }
    }
  }
  return pairs;
}

// Smith's G1 of the Beckmann distribution by Walter et al.'s rational approximation (the form
// Mitsuba 3 evaluates).
double SmithG1Beckmann(const Eigen::Vector3d& v, double alpha) {
  const double tan2 = (v.x() * v.x() + v.y() * v.y()) / (v.z() * v.z());
  if (tan2 <= 0) return 1.0;
  const double a = 1.0 / (alpha * std::sqrt(tan2));
  if (a >= 1.6) return 1.0;
  return (3.535 * a + 2.181 * a * a) / (1.0 + 2.276 * a + 2.577 * a * a);
}

// Smith's G1 of the GGX distribution: 2 / (1 + √(1 + α² tan²θ)).
double SmithG1Ggx(const Eigen::Vector3d& v, double alpha) {
  const double tan2 = (v.x() * v.x() + v.y() * v.y()) / (v.z() * v.z());
  return 2.0 / (1.0 + std::sqrt(1.0 + alpha * alpha * tan2));
}

// The fit of `source` (grey ρs) at roughness `alpha` over `pairs`: k solved in closed form (the
// target is affine in k) unless `fixed_scale` is given; the relative RMS error.
LobeFit FitAt(const render::BrdfParams& source, const std::vector<DirectionPair>& pairs,
              const LobeFitOptions& options, double alpha, const double* fixed_scale) {
  double aa = 0, ab = 0, norm = 0;
  std::vector<double> a(pairs.size()), b(pairs.size()), f(pairs.size());
  for (size_t p = 0; p < pairs.size(); ++p) {
    const auto& q = pairs[p];
    f[p] = render::EvalBrdf(source, q.wo, q.wi).x();
    b[p] = TargetLobeValue(options.target, alpha, 0.0, options.target_ior, q.wo, q.wi);
    a[p] = TargetLobeValue(options.target, alpha, 1.0, options.target_ior, q.wo, q.wi) - b[p];
    aa += q.weight * a[p] * a[p];
    ab += q.weight * a[p] * (f[p] - b[p]);
    norm += q.weight * f[p] * f[p];
  }
  LobeFit fit;
  fit.alpha = alpha;
  fit.scale = fixed_scale ? *fixed_scale : (aa > 0 ? ab / aa : 0.0);
  double err = 0;
  for (size_t p = 0; p < pairs.size(); ++p) {
    const double r = fit.scale * a[p] + b[p] - f[p];
    err += pairs[p].weight * r * r;
  }
  fit.relative_error = norm > 0 ? std::sqrt(err / norm) : 0.0;
  return fit;
}

}  // namespace

std::string_view LobeTargetName(LobeTarget target) {
  switch (target) {
    case LobeTarget::kWardGmd:
      return "ward_gmd";
    case LobeTarget::kBeckmannDielectric:
      return "beckmann_dielectric";
    case LobeTarget::kGgxDielectric:
      return "ggx_dielectric";
    case LobeTarget::kGgxSchlick:
      return "ggx_schlick";
  }
  return "?";
}

double DielectricFresnel(double c, double eta) {
  c = std::clamp(c, 0.0, 1.0);
  const double sin_t2 = (1.0 - c * c) / (eta * eta);
  if (sin_t2 >= 1.0) return 1.0;
  const double cos_t = std::sqrt(1.0 - sin_t2);
  const double rs = (c - eta * cos_t) / (c + eta * cos_t);
  const double rp = (eta * c - cos_t) / (eta * c + cos_t);
  return 0.5 * (rs * rs + rp * rp);
}

double TargetLobeValue(LobeTarget target, double alpha, double scale, double target_ior,
                       const Eigen::Vector3d& wo, const Eigen::Vector3d& wi) {
  if (wo.z() <= 0 || wi.z() <= 0) return 0.0;
  const Eigen::Matrix<double, 3, 1> o = wo, i = wi;
  if (target == LobeTarget::kWardGmd) {
    return scale * render::SpecularFactor<double>(recon::BrdfModel::kWardGmd, alpha, alpha, o, i);
  }
  const Eigen::Vector3d h = (wo + wi).normalized();
  const double c = std::max(0.0, h.dot(wi));
  const double cos_h2 = h.z() * h.z();
  const double a2 = alpha * alpha;
  const double ggx_denom = cos_h2 * (a2 - 1.0) + 1.0;
  const double d_ggx = a2 / (render::kPi * ggx_denom * ggx_denom);
  if (target == LobeTarget::kBeckmannDielectric) {
    const double tan2 = (1.0 - cos_h2) / cos_h2;
    const double d = std::exp(-tan2 / a2) / (render::kPi * a2 * cos_h2 * cos_h2);
    const double g = SmithG1Beckmann(wo, alpha) * SmithG1Beckmann(wi, alpha);
    return scale * DielectricFresnel(c, target_ior) * d * g / (4.0 * wo.z() * wi.z());
  }
  if (target == LobeTarget::kGgxDielectric) {
    const double g = SmithG1Ggx(wo, alpha) * SmithG1Ggx(wi, alpha);
    return scale * DielectricFresnel(c, target_ior) * d_ggx * g / (4.0 * wo.z() * wi.z());
  }
  const double nl = wi.z(), nv = wo.z();
  const double v =
      0.5 / (nl * std::sqrt(nv * nv * (1.0 - a2) + a2) + nv * std::sqrt(nl * nl * (1.0 - a2) + a2));
  const double m = std::pow(1.0 - c, 5.0);
  return (scale + (1.0 - scale) * m) * d_ggx * v;
}

LobeFit FitSpecularLobe(const render::BrdfParams& source, const LobeFitOptions& options) {
  if (!recon::HasSpecularLobe(source.model)) {
    throw std::invalid_argument("FitSpecularLobe: the source model has no specular lobe");
  }
  render::BrdfParams src = source;
  src.rho_d.setZero();
  src.rho_s.setConstant(source.rho_s.mean());
  const double alpha_grid = std::max(src.AlphaX(), src.AlphaY());
  const std::vector<DirectionPair> pairs =
      BuildPairs(alpha_grid, recon::IsAnisotropic(src.model), options);
  // For a roughness, the best k (closed form: the target is affine in k) and the error.
  auto fit_at = [&](double alpha) { return FitAt(src, pairs, options, alpha, nullptr); };
  // Golden section on log α over [α/4, 4α] (the lobes' widths are within a factor 2).
  const double geo = std::sqrt(src.AlphaX() * src.AlphaY());
  double lo = std::log(geo / 4.0), hi = std::log(std::min(4.0 * geo, 2.0));
  const double g = (std::sqrt(5.0) - 1.0) / 2.0;
  double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo);
  LobeFit f1 = fit_at(std::exp(x1)), f2 = fit_at(std::exp(x2));
  for (int it = 0; it < 60 && hi - lo > 1e-9; ++it) {
    if (f1.relative_error < f2.relative_error) {
      hi = x2, x2 = x1, f2 = f1;
      x1 = hi - g * (hi - lo), f1 = fit_at(std::exp(x1));
    } else {
      lo = x1, x1 = x2, f1 = f2;
      x2 = lo + g * (hi - lo), f2 = fit_at(std::exp(x2));
    }
  }
  LobeFit best = f1.relative_error < f2.relative_error ? f1 : f2;
  LobeFitOptions wide = options;
  wide.max_theta_o_deg = 88;
  const auto wide_pairs = BuildPairs(alpha_grid, recon::IsAnisotropic(src.model), wide);
  best.relative_error_to_88deg =
      FitAt(src, wide_pairs, options, best.alpha, &best.scale).relative_error;
  return best;
}

}  // namespace igi::exporter
