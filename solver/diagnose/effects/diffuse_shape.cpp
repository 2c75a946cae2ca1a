// diffuse_shape (docs/diagnose-effects.md): a region whose diffuse reflection is not Lambert's
// but Oren–Nayar's rough surface (solver/render/brdf.h): brighter where the light comes from the
// viewer's side (back-scatter), flatter toward the terminator.

#include <fmt/format.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "solver/diagnose/effects/effects.h"
#include "solver/diagnose/residual_fit.h"
#include "solver/render/brdf.h"
#include "solver/render/sampling.h"

namespace igi::diagnose {

double OrenNayarSigmaOfRatio(double b_over_a) {
  if (!(b_over_a > 0)) return 0.0;
  // B/A rises monotonically with σ (0 at 0, 0.42 at 1): bisection on [0, 1].
  double lo = 0, hi = 1;
  auto ratio = [](double s) { return render::OrenNayarB(s) / render::OrenNayarA(s); };
  if (b_over_a >= ratio(hi)) return hi;
  for (int it = 0; it < 60; ++it) {
    const double mid = 0.5 * (lo + hi);
    (ratio(mid) < b_over_a ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

CandidateResult DiffuseShape(const CandidateContext& cx, const ResidualFitter& f, int region) {
  CandidateResult out;
  out.effect = "diffuse_shape";
  const recon::Material& m = cx.model.materials[region];
  int count = 0;
  for (const PixelRecord& r : f.records()) count += r.region == region && !r.outlier;
  if (count < 50) return out;
  // The direct light's diffuse reflection in two parts: Lambert's ρd·E/π and Oren–Nayar's
  // geometric term ρd·G/π, G = Σ OrenNayarG(wo, wi)·E_light. After a refit with Oren–Nayar's
  // term the region reflects s·ρd·(A·E + B·G)/π (s: the refit's albedo change), so the change
  // is (s·A − 1)·ρd·E/π + s·B·ρd·G/π: linear in the two columns, credited only with what G
  // explains beyond the first (a re-fitted albedo alone), and B/A = c₁/(1 + c₀).
  const ResidualFit fit = f.FitBeyond(2, 1, [&](const PixelRecord& r, int c, double* b) {
    if (r.region != region) return;
    const render::Frame frame = render::Frame::FromNormal(r.normal.cast<double>());
    const Eigen::Vector3d wo = frame.ToLocal(r.view.cast<double>());
    if (!(wo.z() > 0)) return;
    double e = 0, g = 0;
    for (const RecordLightSample& ls : r.lights) {
      const Eigen::Vector3d wi = frame.ToLocal(ls.wi.cast<double>());
      if (!(wi.z() > 0)) continue;
      e += ls.irradiance[c];
      g += render::OrenNayarG<double>(wo, wi) * ls.irradiance[c];
    }
    b[0] = r.albedo[c] * e / render::kPi;
    b[1] = r.albedo[c] * g / render::kPi;
  });
  if (fit.coef.size() < 2 || !(1 + fit.coef[0] > 0)) {
    out.note = "region " + m.name + ": no fit of the diffuse term's shape";
    return out;
  }
  const double ratio = fit.coef[1] / (1 + fit.coef[0]);
  if (!(ratio > 0)) {
    out.note = fmt::format(
        "region {}: the residual does not rise toward back-scatter as a rough diffuse surface's "
        "does (B/A {:.3f})",
        m.name, ratio);
    return out;
  }
  const double sigma = OrenNayarSigmaOfRatio(ratio);
  FillScores(fit, &out);
  out.params = {{"region", m.name}, {"sigma", sigma}, {"b_over_a", ratio}};
  out.where = {{"regions", {m.name}}, {"frame", "light and view azimuths"}};
  out.num_params = 1;
  out.evidence = fmt::format(
      "region '{}': its diffuse reflection is brighter where light and view share an azimuth "
      "and flatter toward the terminator than Lambert's: Oren-Nayar's rough surface with sigma "
      "~ {:.2f} rad explains it",
      m.name, sigma);
  out.valid = true;
  return out;
}

namespace {

class DiffuseShapeEffect final : public Effect {
 public:
  std::string Name() const override { return "diffuse_shape"; }
  // Every reflective region with Lambert's diffuse term.
  void AddFits(const CandidateContext& cx, const RecordFits& in, const KeyFilter& allowed,
               std::vector<CandidateTask>* tasks) const override {
    for (int g = 0; g < int(cx.model.materials.size()); ++g) {
      const recon::Material& m = cx.model.materials[g];
      if (!recon::IsReflective(m.brdf) || m.diffuse != recon::DiffuseShape::kLambert ||
          !allowed(Name() + ":" + m.name)) {
        continue;
      }
      tasks->push_back({[&cx, &f = in.fitter, g] { return DiffuseShape(cx, f, g); }, true});
    }
  }
  HeldOutScope Scope(const CandidateResult& c, const DiagnosisModel& m) const override {
    return RegionScope(c, m);
  }
  // The region's diffuse term becomes Oren–Nayar's: with its σ where the region's albedo is
  // declared (nothing is solved then), without it otherwise (igi-solve fits σ with ρd).
  void Write(const CandidateResult& c, recon::SceneDocument* doc) const override {
    const std::string region = c.params.at("region").get<std::string>();
    Json m = doc->Material(region);
    m["diffuse"] = "oren_nayar";
    m.erase("sigma");
    if (m.contains("rho_d") || m.contains("rho_d_map")) m["sigma"] = c.params.at("sigma");
    doc->SetMaterial(region, std::move(m));
  }
  // The kept step's description with the σ the refit solved.
  void DescribeKept(CandidateResult* c, const recon::Scene& refit) const override {
    const std::string region = c->params.at("region").get<std::string>();
    for (const recon::Material& m : refit.materials) {
      if (m.name != region || !m.sigma) continue;
      c->params["sigma_solved"] = *m.sigma;
      c->evidence += fmt::format("; solved: sigma {:.3f}", *m.sigma);
    }
  }
};

}  // namespace

std::unique_ptr<Effect> MakeDiffuseShape() { return std::make_unique<DiffuseShapeEffect>(); }

}  // namespace igi::diagnose
