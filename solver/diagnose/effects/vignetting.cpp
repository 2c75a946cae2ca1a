// vignetting (docs/diagnose-effects.md): an image-fixed radial fall-off, the same in every photo.

#include <fmt/format.h>

#include <Eigen/Dense>
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

std::string Pct(double v) { return fmt::format("{:.1f}%", 100 * v); }

}  // namespace

CandidateResult Vignetting(const CandidateContext& cx, const ResidualFitter& f) {
  CandidateResult out;
  out.effect = "vignetting";
  if (!cx.declared.contains("cameras") || cx.declared["cameras"].contains("colmap")) {
    out.note = "cameras come from a COLMAP model: no place for a vignetting model";
    return out;
  }
  const ResidualFit fit = f.Fit(2, [&](const PixelRecord& r, int c, double* b) {
    b[0] = r.sim[c] * r.r2;
    b[1] = r.sim[c] * r.r2 * r.r2;
  });
  if (fit.coef.size() == 0) return out;
  const double k1 = fit.coef[0], k2 = fit.coef[1];
  if (!(std::abs(k1) <= 1) || !(std::abs(k2) <= 1) || !(1 + k1 + k2 >= 0.05)) {
    out.note = fmt::format("the radial fit (k1 {:.3g}, k2 {:.3g}) is not a lens fall-off", k1, k2);
    return out;
  }
  FillScores(fit, &out);
  out.params = {{"k1", k1}, {"k2", k2}};
  out.where = {{"photos", PhotoFiles(cx.model)}, {"frame", "image"}};
  out.num_params = 2;
  out.evidence = fmt::format(
      "image-fixed radial fall-off, the same in all {} photos: photo/model is {} lower in the "
      "corners than at the principal point, whichever surface is seen there (fit 1 + k1 r^2 + "
      "k2 r^4)",
      cx.model.photos.size(), Pct(-(k1 + k2)));
  out.valid = true;
  return out;
}

namespace {

class VignettingEffect final : public Effect {
 public:
  std::string Name() const override { return "vignetting"; }
  void AddFits(const CandidateContext& cx, const RecordFits& in, const KeyFilter& allowed,
               std::vector<CandidateTask>* tasks) const override {
    if (allowed(Name())) tasks->push_back({[&cx, &f = in.fitter] { return Vignetting(cx, f); }});
  }
  // Every camera's fall-off becomes the product of its declared one and the fitted one (to r⁴).
  void Write(const CandidateResult& c, recon::SceneDocument* doc) const override {
    const double k1 = c.params.at("k1").get<double>(), k2 = c.params.at("k2").get<double>();
    for (const std::string& name : doc->CameraNames()) {
      const Eigen::Vector2d old = doc->CameraVignetting(name);
      doc->SetCameraVignetting(name, old[0] + k1, old[1] + k2 + old[0] * k1);
    }
  }
};

}  // namespace

std::unique_ptr<Effect> MakeVignetting() { return std::make_unique<VignettingEffect>(); }

}  // namespace igi::diagnose
