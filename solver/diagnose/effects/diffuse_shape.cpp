// diffuse_shape (docs/diagnose-effects.md): a region whose diffuse reflection is not Lambert's
// but Oren–Nayar's rough surface (solver/render/brdf.h): brighter where the light comes from the
// viewer's side (back-scatter), flatter toward the terminator; or a coated base's, darker toward
// grazing light and view.

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "solver/diagnose/effects/effects.h"
#include "solver/diagnose/residual_fit.h"
#include "solver/render/brdf.h"
#include "solver/render/sampling.h"
#include "tools/common/strings.h"

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

namespace {

// A record's diffuse parts (DiffuseShape below): false where the record is not of the regions.
using DiffuseParts = std::function<bool(const PixelRecord&, int, double*)>;

// Materials solved: one Lambert column per region (what re-fitted albedos alone explain, the
// base) and a shape's own column `extra` (of the parts), credited with what it explains beyond
// them.
ResidualFit FitBeyondAlbedos(const ResidualFitter& f, int n, const DiffuseParts& parts,
                             double (*extra)(const double* p)) {
  return f.FitBeyond(n + 1, n, [&](const PixelRecord& r, int c, double* b) {
    double p[4];
    if (!parts(r, c, p)) return;
    b[int(p[3])] = p[0];
    b[n] = extra(p);
  });
}

// Oren–Nayar's term in place of Lambert's on the records' regions: σ and the fit.
ResidualFit FitOrenNayar(const ResidualFitter& f, int n, const DiffuseParts& parts, double* sigma,
                         double* ratio) {
  ResidualFit fit;
  if (f.nuisance()) {
    // Materials solved: after the refit a region reflects s·ρd·(A·E + B·G)/π (s its albedo's
    // change), so the change is (s·A − 1)·ρd·E/π + s·B·ρd·G/π: one Lambert column per region
    // (what re-fitted albedos alone explain, the base) and the shared G column, credited with
    // what it explains beyond them; B/A = c_G/(1 + c̄), c̄ the regions' mean base coefficient.
    fit = FitBeyondAlbedos(f, n, parts, [](const double* p) { return p[1]; });
    if (fit.coef.size() == n + 1) {
      const double mean_base = fit.coef.head(n).mean();
      if (1 + mean_base > 0) *ratio = fit.coef[n] / (1 + mean_base);
    }
    *sigma = OrenNayarSigmaOfRatio(*ratio);
    return fit;
  }
  // Materials given: the refit renders ρd·(A·E + B·G)/π with the declared ρd, a change
  // ρd·((A − 1)·E + B·G)/π fixed by σ: σ searched on a grid, the change's amplitude near 1.
  for (int i = 1; i <= 20; ++i) {
    const double sg = 0.05 * i;
    const double a = render::OrenNayarA(sg), bb = render::OrenNayarB(sg);
    const ResidualFit at = f.Fit(1, [&](const PixelRecord& r, int c, double* b) {
      double p[4];
      if (parts(r, c, p)) b[0] = (a - 1) * p[0] + bb * p[1];
    });
    if (at.coef.size() == 0 || !(at.coef[0] > 0.7 && at.coef[0] < 1.4)) continue;
    if (fit.coef.size() == 0 || at.train_after < fit.train_after) fit = at, *sigma = sg;
  }
  *ratio = render::OrenNayarB(*sigma) / render::OrenNayarA(*sigma);
  return fit;
}

// The coated base's term in place of Lambert's: the change ρd·(C − E)/π, C the coat's column.
// With the materials solved it is credited beyond a re-fitted albedo per region (the refit's
// ρd takes the term's level); its coefficient must then be positive. With them given it is
// fixed, its amplitude near 1. Empty when neither holds.
ResidualFit FitCoated(const ResidualFitter& f, int n, const DiffuseParts& parts) {
  ResidualFit fit;
  if (f.nuisance()) {
    fit = FitBeyondAlbedos(f, n, parts, [](const double* p) { return p[2] - p[0]; });
    if (fit.coef.size() == n + 1 && fit.coef[n] > 0) return fit;
    return {};
  }
  fit = f.Fit(1, [&](const PixelRecord& r, int c, double* b) {
    double p[4];
    if (parts(r, c, p)) b[0] = p[2] - p[0];
  });
  if (fit.coef.size() == 1 && fit.coef[0] > 0.7 && fit.coef[0] < 1.4) return fit;
  return {};
}

}  // namespace

CandidateResult DiffuseShape(const CandidateContext& cx, const ResidualFitter& f,
                             const std::vector<int>& regions) {
  CandidateResult out;
  out.effect = "diffuse_shape";
  const int n = int(regions.size());
  std::vector<int> slot(cx.model.materials.size(), -1);  // each region's place in `regions`
  std::vector<std::string> names;
  for (int k = 0; k < n; ++k)
    slot[regions[k]] = k, names.push_back(cx.model.materials[regions[k]].name);
  const std::string label = n == 1 ? "region '" + names[0] + "'" : "regions " + Join(names, ", ");
  // Its target from the start: the key (CandidateResult::Key) of a fit that fails names it too.
  if (n == 1) {
    out.params = {{"region", names[0]}};
  } else {
    out.params = {{"regions", names}};
  }
  int count = 0;
  for (const PixelRecord& r : f.records())
    count += r.region >= 0 && slot[r.region] >= 0 && !r.outlier;
  if (n == 0 || count < 50) return out;
  // A record's diffuse reflection in parts, p[0..3]: Lambert's ρd·E/π, Oren–Nayar's geometric
  // term ρd·G/π, the coated base's ρd·C/π (all zero off `regions`) and the region's slot. The
  // direct light gives G = Σ OrenNayarG(wo, wi)·E_light and C = Σ T(cosθo)·T(cosθi)·E_light. On
  // a region without a lobe the model's value is its whole diffuse reflection, ρd·E/π with the
  // light the room bounces in: that light, E − E_direct, arrives from the whole hemisphere and
  // adds OrenNayarMeanG(cosθo) times itself to G and T(cosθo)·20/21 times itself to C. (On a
  // region with a lobe only the direct light is split so.)
  auto parts = [&](const PixelRecord& r, int c, double* p) {
    p[0] = p[1] = p[2] = p[3] = 0;
    if (r.region < 0 || slot[r.region] < 0 || !(r.albedo[c] > 0)) return false;
    const render::Frame frame = render::Frame::FromNormal(r.normal.cast<double>());
    const Eigen::Vector3d wo = frame.ToLocal(r.view.cast<double>());
    if (!(wo.z() > 0)) return false;
    const double t_o = render::CoatTransmission(wo.z());
    double e = 0, g = 0, coat = 0;
    for (const RecordLightSample& ls : r.lights) {
      const Eigen::Vector3d wi = frame.ToLocal(ls.wi.cast<double>());
      if (!(wi.z() > 0)) continue;
      e += ls.irradiance[c];
      g += render::OrenNayarG<double>(wo, wi) * ls.irradiance[c];
      coat += t_o * render::CoatTransmission(wi.z()) * ls.irradiance[c];
    }
    if (!recon::HasSpecularLobe(cx.model.materials[r.region].brdf)) {
      const double e_all = r.sim[c] * render::kPi / r.albedo[c];
      if (e_all > e) {
        g += render::OrenNayarMeanG(wo.z()) * (e_all - e);
        coat += t_o * render::kMeanCoatTransmission * (e_all - e);
        e = e_all;
      }
    }
    p[0] = r.albedo[c] * e / render::kPi;
    p[1] = r.albedo[c] * g / render::kPi;
    p[2] = r.albedo[c] * coat / render::kPi;
    p[3] = slot[r.region];
    return true;
  };
  double sigma = 0, ratio = 0;
  ResidualFit fit = FitOrenNayar(f, n, parts, &sigma, &ratio);
  if (!(sigma > 0)) fit = {};
  const ResidualFit coated = FitCoated(f, n, parts);
  // The shape that explains more of the residual (the lower squared error after the fit).
  const bool coat =
      coated.coef.size() > 0 && (fit.coef.size() == 0 || coated.train_after < fit.train_after);
  if (!coat && fit.coef.size() == 0) {
    out.note = fmt::format(
        "{}: the residual neither rises toward back-scatter as a rough diffuse surface's does "
        "(B/A {:.3f}) nor falls toward grazing light as a coated one's",
        label, ratio);
    return out;
  }
  out.where = {{"regions", names}, {"frame", "light and view directions"}};
  out.num_params = coat ? 0 : 1;
  out.valid = true;
  if (coat) {
    FillScores(coated, &out);
    out.params["to"] = "coated";
    out.evidence = fmt::format(
        "{}: the diffuse reflection falls toward grazing light and view below Lambert's "
        "cosine: a Lambertian base under a smooth clear coat, each crossing of the coat "
        "losing Schlick's reflectance, explains it",
        label);
    return out;
  }
  FillScores(fit, &out);
  out.params["to"] = "oren_nayar";
  out.params["sigma"] = sigma;
  out.params["b_over_a"] = ratio;
  out.evidence = fmt::format(
      "{}: the diffuse reflection is brighter where light and view share an azimuth and "
      "flatter toward the terminator than Lambert's: Oren-Nayar's rough surface with sigma "
      "~ {:.2f} rad explains it",
      label, sigma);
  return out;
}

namespace {

class DiffuseShapeEffect final : public Effect {
 public:
  std::string Name() const override { return "diffuse_shape"; }
  // Every reflective region with Lambert's diffuse term on its own, and the regions without a
  // lobe together (one σ: a room's walls of one paint darken and back-scatter alike, which one
  // region's fit sees only in part).
  void AddFits(const CandidateContext& cx, const RecordFits& in, const KeyFilter& allowed,
               std::vector<CandidateTask>* tasks) const override {
    std::vector<int> matte;
    for (int g = 0; g < int(cx.model.materials.size()); ++g) {
      const recon::Material& m = cx.model.materials[g];
      if (!recon::IsReflective(m.brdf) || m.diffuse != recon::DiffuseShape::kLambert) continue;
      if (!recon::HasSpecularLobe(m.brdf)) matte.push_back(g);
      if (!allowed(Name() + ":" + m.name)) continue;
      tasks->push_back({[&cx, &f = in.fitter, g] { return DiffuseShape(cx, f, {g}); }, true});
    }
    if (matte.size() >= 2 && allowed(Name())) {
      tasks->push_back({[&cx, &f = in.fitter, matte] { return DiffuseShape(cx, f, matte); }, true});
    }
  }
  HeldOutScope Scope(const CandidateResult& c, const DiagnosisModel& m) const override {
    return RegionScope(c, m);
  }
  // The region's diffuse term becomes the named one; Oren–Nayar's with its σ where the region's
  // albedo is declared (nothing is solved then), without it otherwise (igi-solve fits σ with ρd).
  void Write(const CandidateResult& c, recon::SceneDocument* doc) const override {
    const std::string to = c.params.value("to", "oren_nayar");
    for (const std::string& region : Regions(c)) {
      Json m = doc->Material(region);
      m["diffuse"] = to;
      m.erase("sigma");
      if (to == "oren_nayar" && (m.contains("rho_d") || m.contains("rho_d_map")))
        m["sigma"] = c.params.at("sigma");
      doc->SetMaterial(region, std::move(m));
    }
  }
  // The kept step's description with the σ the refit solved.
  void DescribeKept(CandidateResult* c, const recon::Scene& refit) const override {
    Json solved = Json::object();
    for (const std::string& region : Regions(*c)) {
      const int r = refit.FindMaterial(region);
      if (r >= 0 && refit.materials[r].sigma) solved[region] = *refit.materials[r].sigma;
    }
    if (solved.empty()) return;
    c->params["sigma_solved"] = solved;
    c->evidence += "; solved sigma: " + solved.dump();
  }

 private:
  static std::vector<std::string> Regions(const CandidateResult& c) {
    if (c.params.contains("region")) return {c.params.at("region").get<std::string>()};
    return c.params.at("regions").get<std::vector<std::string>>();
  }
};

}  // namespace

std::unique_ptr<Effect> MakeDiffuseShape() { return std::make_unique<DiffuseShapeEffect>(); }

}  // namespace igi::diagnose
