// specular_reflection (docs/diagnose-effects.md): a region declared diffuse that has a highlight.

#include <fmt/format.h>

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "solver/diagnose/effects/effects.h"
#include "solver/diagnose/residual_fit.h"
#include "solver/inverse/observations.h"
#include "solver/render/brdf.h"
#include "solver/render/sampling.h"

namespace igi::diagnose {

namespace {

// The roughnesses specular_reflection tries; its widest value is a bound, not a fit (see there).
constexpr std::array<double, 11> kSpecularAlphaGrid = {0.03, 0.04, 0.05, 0.065, 0.08, 0.1,
                                                       0.12, 0.15, 0.18, 0.25,  0.35};

}  // namespace

CandidateResult SpecularReflection(const CandidateContext& cx, const ResidualFitter& f,
                                   int region) {
  CandidateResult out;
  out.effect = "specular_reflection";
  const std::string& name = cx.model.materials[region].name;
  int count = 0;
  for (const PixelRecord& r : f.records()) count += r.region == region;
  if (count < 50) return out;
  ResidualFit best;
  double best_alpha = 0.1;
  // The records carry the direct light only; the lobe also reflects the lit room around the
  // region (a broad brightening of the whole region). With the albedos given (no nuisance), a
  // free scale of the region's prediction takes that part, so that the lobe's width follows the
  // highlight (the refit renders the reflected room itself).
  const int k = f.nuisance() ? 1 : 2;
  for (double alpha : kSpecularAlphaGrid) {
    const ResidualFit fit = f.Fit(k, [&](const PixelRecord& r, int c, double* b) {
      if (r.region != region) return;
      double s = 0;
      const double a = solver::WidenedAlpha(alpha, r.lobe_blur2);
      for (const RecordLightSample& ls : r.lights) {
        s += IsotropicLobe(recon::BrdfModel::kWard, a, r.normal, r.view, ls.wi) * ls.irradiance[c];
      }
      b[0] = s;
      if (k == 2) b[1] = r.sim[c];
    });
    // A physical lobe only (0 < ρs < 1): a region no highlight reaches leaves the amplitude free.
    if (fit.coef.size() == 0 || !(fit.coef[0] > 0) || !(fit.coef[0] < 1)) continue;
    if (best.coef.size() == 0 || fit.train_after < best.train_after) best = fit, best_alpha = alpha;
  }
  if (best.coef.size() == 0) {
    out.note = "no lobe with 0 < rho_s < 1 fits region " + name;
    return out;
  }
  // The widest lobe searched fitting best is no highlight: a broad brightening of the region (what
  // another effect leaves, e.g. an emission profile's fitted power) that a lobe wider still would
  // fit better, i.e. a change of the region's overall level, not a specular reflection.
  if (best_alpha >= kSpecularAlphaGrid.back()) {
    out.note = fmt::format(
        "region {}: the widest lobe searched (alpha {:.2f}, rho_s {:.3f}) fits best: a broad "
        "brightening, not a highlight",
        name, best_alpha, best.coef[0]);
    return out;
  }
  FillScores(best, &out);
  const double rho_s = best.coef[0];
  out.params = {{"region", name}, {"rho_s", rho_s}, {"alpha", best_alpha}};
  out.where = {{"regions", {name}}, {"frame", "half-vector angle"}};
  out.num_params = 2;
  out.evidence = fmt::format(
      "region '{}' (declared diffuse) is brighter than the model where the half vector nears "
      "its normal, a highlight: a Ward lobe with rho_s ~ {:.3f}, alpha ~ {:.2f} explains it",
      name, rho_s, best_alpha);
  out.valid = true;
  return out;
}

namespace {

class SpecularReflectionEffect final : public Effect {
 public:
  std::string Name() const override { return "specular_reflection"; }
  // Every region declared diffuse.
  void AddFits(const CandidateContext& cx, const RecordFits& in, const KeyFilter& allowed,
               std::vector<CandidateTask>* tasks) const override {
    for (int g = 0; g < int(cx.model.materials.size()); ++g) {
      const recon::Material& m = cx.model.materials[g];
      if (m.brdf != recon::BrdfModel::kLambert || !allowed(Name() + ":" + m.name)) continue;
      tasks->push_back({[&cx, &f = in.fitter, g] { return SpecularReflection(cx, f, g); }});
    }
  }
  HeldOutScope Scope(const CandidateResult& c, const DiagnosisModel& m) const override {
    return RegionScope(c, m);
  }
  // The region becomes "ward" with its albedo as declared (a value, a map or unknown) and its
  // lobe's ρs and α left to igi-solve, which the refit runs on a document with unknown values:
  // the candidate's grid and its free scale of the region's light only locate the lobe (with
  // the albedos given, that scale takes the room the lobe reflects, and a lobe that is not
  // Ward's, such as another renderer's microfacet lobe, is fitted at a wrong height), while the
  // solver fits ρs and α to every observation with the light the lobe really reflects.
  void Write(const CandidateResult& c, recon::SceneDocument* doc) const override {
    const std::string region = c.params.at("region").get<std::string>();
    const Json& m = doc->Material(region);
    Json fresh = {{"brdf", "ward"}};
    if (m.contains("rho_d")) fresh["rho_d"] = m["rho_d"];
    if (m.contains("rho_d_map")) fresh["rho_d_map"] = m["rho_d_map"];
    doc->SetMaterial(region, std::move(fresh));
  }
  // The kept step's description with the lobe the refit solved.
  void DescribeKept(CandidateResult* c, const recon::Scene& refit) const override {
    const std::string region = c->params.at("region").get<std::string>();
    for (const recon::Material& m : refit.materials) {
      if (m.name != region || !m.rho_s || !m.alpha) continue;
      c->params["rho_s_solved"] = m.rho_s->mean();
      c->params["alpha_solved"] = *m.alpha;
      c->evidence += fmt::format("; solved: rho_s {:.3f}, alpha {:.3f}", m.rho_s->mean(), *m.alpha);
    }
  }
};

}  // namespace

std::unique_ptr<Effect> MakeSpecularReflection() {
  return std::make_unique<SpecularReflectionEffect>();
}

}  // namespace igi::diagnose
