// anisotropic_reflection (docs/diagnose-effects.md): a glossy region whose highlight is stretched
// along a surface direction.

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "solver/diagnose/effects/effects.h"
#include "solver/diagnose/residual_fit.h"
#include "solver/render/brdf.h"
#include "solver/render/sampling.h"

namespace igi::diagnose {

namespace {

using Eigen::Vector3d;

Json Vec(const Vector3d& v) { return Json::array({v.x(), v.y(), v.z()}); }

recon::BrdfModel AnisotropicOf(recon::BrdfModel m) {
  switch (m) {
    case recon::BrdfModel::kWard:
      return recon::BrdfModel::kWardAniso;
    case recon::BrdfModel::kWardGmd:
      return recon::BrdfModel::kWardGmdAniso;
    case recon::BrdfModel::kWardFresnel:
      return recon::BrdfModel::kWardAnisoFresnel;
    case recon::BrdfModel::kWardGmdFresnel:
      return recon::BrdfModel::kWardGmdAnisoFresnel;
    default:
      return m;
  }
}

// The colourless specular factor of `model` (with its Fresnel weight) in `frame`.
double Specular(recon::BrdfModel model, double ax, double ay, double ior,
                const render::Frame& frame, const Vector3d& wo, const Vector3d& wi) {
  const Vector3d lo = frame.ToLocal(wo), li = frame.ToLocal(wi);
  double s = render::SpecularFactor<double>(model, ax, ay, lo, li);
  if (s > 0 && recon::HasFresnel(model)) s *= render::FresnelWeight<double>(ior, lo, li);
  return s;
}

// The lobe of one region at its records, for a lobe model and parameters.
class RegionLobe {
 public:
  RegionLobe(const std::vector<PixelRecord>& records, int region, const recon::Material& m)
      : records_(records),
        region_(region),
        rho_s_(m.rho_s.value_or(Vector3d::Zero())),
        ior_(m.ior.value_or(recon::Material::kDefaultIor)) {}

  // ρs_c Σ S(wo, wi)·E_c per record (zero off the region); tangent only for anisotropic models.
  std::vector<Eigen::Vector3f> Term(recon::BrdfModel model, double ax, double ay,
                                    const Vector3d& tangent) const {
    std::vector<Eigen::Vector3f> out(records_.size(), Eigen::Vector3f::Zero());
    for (size_t i = 0; i < records_.size(); ++i) {
      const PixelRecord& r = records_[i];
      if (r.region != region_) continue;
      const Vector3d n = r.normal.cast<double>(), wo = r.view.cast<double>();
      const render::Frame frame = recon::IsAnisotropic(model)
                                      ? render::Frame::FromNormalTangent(n, tangent)
                                      : render::Frame::FromNormal(n);
      Vector3d sum = Vector3d::Zero();
      for (const RecordLightSample& ls : r.lights) {
        const double s = Specular(model, ax, ay, ior_, frame, wo, ls.wi.cast<double>());
        sum += s * ls.irradiance.cast<double>();
      }
      out[i] = sum.cwiseProduct(rho_s_).cast<float>();
    }
    return out;
  }

 private:
  const std::vector<PixelRecord>& records_;
  int region_;
  Vector3d rho_s_;
  double ior_;
};

// The region's normal where its current highlight is (weights: the current lobe's value), and
// two directions spanning its plane.
std::array<Vector3d, 3> HighlightPlane(const std::vector<PixelRecord>& records, int region,
                                       const std::vector<Eigen::Vector3f>& lobe) {
  Vector3d n = Vector3d::Zero(), plain = Vector3d::Zero();
  for (size_t i = 0; i < records.size(); ++i) {
    if (records[i].region != region || records[i].outlier) continue;
    n += double(lobe[i].sum()) * records[i].normal.cast<double>();
    plain += records[i].normal.cast<double>();
  }
  if (!(n.norm() > 1e-9)) n = plain;
  if (!(n.norm() > 1e-9)) n = Vector3d::UnitZ();
  const render::Frame f = render::Frame::FromNormal(n.normalized());
  return {f.n, f.t, f.b};
}

struct LobeParams {
  double phi = 0, ax = 0.1, ay = 0.1;  // tangent angle (radians) in the highlight plane
};

// The region's current lobe and an anisotropic one on one fitter's records.
class LobeFit {
 public:
  LobeFit(const ResidualFitter& f, int region, const recon::Material& m)
      : f_(f), lobe_(f.records(), region, m), to_(AnisotropicOf(m.brdf)) {
    const double alpha = *m.alpha;
    current_ = lobe_.Term(m.brdf, alpha, alpha, Vector3d::UnitX());
    ch_.offset = current_;
    for (Eigen::Vector3f& v : ch_.offset) v = -v;  // the current lobe is removed
  }
  const std::vector<Eigen::Vector3f>& current() const { return current_; }

  ResidualFit operator()(double ax, double ay, const Vector3d& tangent) {
    ch_.basis = lobe_.Term(to_, ax, ay, tangent);
    return FitChange(f_, ch_);
  }

 private:
  const ResidualFitter& f_;
  RegionLobe lobe_;
  recon::BrdfModel to_;
  std::vector<Eigen::Vector3f> current_;
  Change ch_;
};

// The lobe's parameters are searched on `search`'s records (the region's, subsampled), then
// fitted and scored on `f`'s.
CandidateResult AnisotropicFit(const CandidateContext& cx, const ResidualFitter& f,
                               const ResidualFitter& search, int region) {
  CandidateResult out;
  out.effect = "anisotropic_reflection";
  const recon::Material& m = cx.model.materials[region];
  LobeFit lobe(search, region, m);
  const std::array<Vector3d, 3> plane = HighlightPlane(search.records(), region, lobe.current());
  const recon::BrdfModel to = AnisotropicOf(m.brdf);
  auto tangent_of = [&](double phi) {
    return (std::cos(phi) * plane[1] + std::sin(phi) * plane[2]).normalized();
  };
  auto fit_at = [&](const LobeParams& p) { return lobe(p.ax, p.ay, tangent_of(p.phi)); };
  auto physical = [](const ResidualFit& fit) {
    return fit.coef.size() == 1 && fit.coef[0] > 0.2 && fit.coef[0] < 5;
  };
  // The best isotropic lobe (ratio 1) is the reference the anisotropy must beat.
  ResidualFit iso;
  for (double a = 0.02; a < 0.45; a *= 1.25) {
    const ResidualFit fit = fit_at({0, a, a});
    if (physical(fit) && (iso.coef.size() == 0 || fit.train_after < iso.train_after)) iso = fit;
  }
  ResidualFit best;
  LobeParams bp;
  auto consider = [&](const LobeParams& p) {
    if (!(p.ax > 0.005 && p.ax < 1 && p.ay > 0.005 && p.ay < 1)) return false;
    const ResidualFit fit = fit_at(p);
    if (!physical(fit) || (best.coef.size() && fit.train_after >= best.train_after)) return false;
    best = fit, bp = p;
    return true;
  };
  const std::vector<double> grid = {0.02, 0.03, 0.045, 0.065, 0.095, 0.14, 0.2, 0.3};
  for (int k = 0; k < 12; ++k) {
    for (size_t i = 0; i < grid.size(); ++i) {
      for (size_t j = i + 1; j < grid.size(); ++j)
        consider({k * render::kPi / 12, grid[i], grid[j]});
    }
  }
  if (best.coef.size() == 0) {
    out.note = "no anisotropic lobe with 0.2 < rho_s ratio < 5 fits region " + m.name;
    return out;
  }
  for (double step : {1.0, 0.5, 0.25, 0.12}) {
    for (int round = 0; round < 8; ++round) {
      bool moved = false;
      for (double s : {-1.0, 1.0}) {
        moved |= consider({bp.phi + s * step * render::kPi / 24, bp.ax, bp.ay});
        moved |= consider({bp.phi, bp.ax * std::pow(1.2, s * step), bp.ay});
        moved |= consider({bp.phi, bp.ax, bp.ay * std::pow(1.2, s * step)});
      }
      if (!moved) break;
    }
  }
  // As for specular_reflection: a lobe whose wide direction reaches the widest roughness of the
  // grid is a broad brightening of the region, not a highlight stretched along a tangent.
  if (std::max(bp.ax, bp.ay) >= grid.back()) {
    out.note = fmt::format(
        "region {}: the lobe's wide direction reaches the widest roughness searched (alpha {:.3f} "
        "/ {:.3f}): a broad brightening, not a highlight",
        m.name, bp.ax, bp.ay);
    return out;
  }
  const double explained = best.train_before - best.train_after;
  const double share = iso.coef.size() ? (iso.train_after - best.train_after) / explained : 1.0;
  const double ratio = std::max(bp.ax, bp.ay) / std::min(bp.ax, bp.ay);
  if (!(explained > 0) || !(share >= 0.1) || !(ratio >= 1.5)) {
    out.note = fmt::format(
        "region {}: an isotropic lobe explains as much (anisotropic lobe ratio {:.2f}, "
        "{:.0f}% of its gain beyond the best isotropic one)",
        m.name, ratio, 100 * share);
    return out;
  }
  // The narrow direction first is a convention only: report the tangent of alpha_x as fitted.
  const Vector3d tangent = tangent_of(bp.phi);
  if (&search != &f) {
    best = LobeFit(f, region, m)(bp.ax, bp.ay, tangent);
    if (!physical(best)) {
      out.note =
          fmt::format("region {}: the lobe found on a subsample does not fit every record", m.name);
      return out;
    }
  }
  FillScores(best, &out);
  const double k = best.coef[0];
  const std::string to_name(recon::BrdfModelName(to));
  out.params = {{"region", m.name}, {"from", recon::BrdfModelName(m.brdf)},
                {"to", to_name},    {"tangent", Vec(tangent)},
                {"alpha_x", bp.ax}, {"alpha_y", bp.ay},
                {"rho_s_factor", k}};
  out.where = {{"regions", {m.name}}, {"frame", "half-vector azimuth in the tangent frame"}};
  out.num_params = 4;  // tangent angle, two roughnesses, ρs scale
  out.evidence = fmt::format(
      "region '{}': the highlight's residual depends on the half vector's azimuth around the "
      "normal, not only on its angle: the lobe is stretched, alpha {:.3f} along ({:.2f}, {:.2f}, "
      "{:.2f}) and {:.3f} across it (ratio {:.1f}); {:.0f}% of the residual it explains is beyond "
      "the best isotropic lobe",
      m.name, bp.ax, tangent.x(), tangent.y(), tangent.z(), bp.ay, ratio, 100 * share);
  out.valid = true;
  return out;
}

}  // namespace

CandidateResult AnisotropicReflection(const CandidateContext& cx, const ResidualFitter& f,
                                      int region) {
  const recon::Material& m = cx.model.materials[region];
  const bool plain = m.brdf == recon::BrdfModel::kWard || m.brdf == recon::BrdfModel::kWardGmd ||
                     m.brdf == recon::BrdfModel::kWardFresnel ||
                     m.brdf == recon::BrdfModel::kWardGmdFresnel;
  if (!plain || !m.rho_s || !m.alpha || !(m.rho_s->mean() > 0)) {
    CandidateResult out;
    out.effect = "anisotropic_reflection";
    return out;
  }
  int count = 0, fitted = 0;
  for (const PixelRecord& r : f.records()) {
    count += r.region == region && !r.outlier;
    fitted += r.region == region && !r.outlier && !r.held_out;
  }
  if (count < 50) {
    CandidateResult out;
    out.effect = "anisotropic_reflection";
    return out;
  }
  // The search sees the region's records only (the others' residual is the same for every lobe,
  // and cells do not cross regions), subsampled to about cx.search_records fitted ones.
  const RecordSubset search(cx.model, f.records(), cx.cell_m, f.nuisance(), cx.block_px,
                            std::max(1, fitted / std::max(1, cx.search_records)), region);
  return AnisotropicFit(cx, f, search.fitter(), region);
}

namespace {

class AnisotropicReflectionEffect final : public Effect {
 public:
  std::string Name() const override { return "anisotropic_reflection"; }
  void AddFits(const CandidateContext& cx, const RecordFits& in, const KeyFilter& allowed,
               std::vector<CandidateTask>* tasks) const override {
    for (int g = 0; g < int(cx.model.materials.size()); ++g) {
      if (!allowed(Name() + ":" + cx.model.materials[g].name)) continue;
      tasks->push_back(
          {[&cx, &f = in.fitter, g] { return AnisotropicReflection(cx, f, g); }, true});
    }
  }
  HeldOutScope Scope(const CandidateResult& c, const DiagnosisModel& m) const override {
    return RegionScope(c, m);
  }
  // The region's model becomes its *_aniso form with the fitted tangent; where the declared
  // region has α and ρs, they become the fitted α_x, α_y and the scaled ρs.
  void Write(const CandidateResult& c, recon::SceneDocument* doc) const override {
    const std::string region = c.params.at("region").get<std::string>();
    doc->SetMaterialBrdf(region,
                         recon::BrdfModelFromName(c.params.at("to").get<std::string>()).value());
    doc->SetMaterialValue(region, "tangent", c.params.at("tangent"));
    const bool known_alpha = doc->Material(region).contains("alpha");
    doc->EraseMaterialValue(region, "alpha");
    if (known_alpha) {
      doc->SetMaterialValue(region, "alpha_x", c.params.at("alpha_x"));
      doc->SetMaterialValue(region, "alpha_y", c.params.at("alpha_y"));
    }
    doc->ScaleMaterialValue(region, "rho_s", c.params.at("rho_s_factor").get<double>());
  }
};

}  // namespace

std::unique_ptr<Effect> MakeAnisotropicReflection() {
  return std::make_unique<AnisotropicReflectionEffect>();
}

}  // namespace igi::diagnose
