// camera_response (docs/diagnose-effects.md): the photos follow the model's value through a
// power.

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "solver/diagnose/effects/effects.h"
#include "solver/diagnose/residual_fit.h"
#include "solver/render/brdf.h"
#include "solver/render/sampling.h"

namespace igi::diagnose {

CandidateResult Response(const CandidateContext& cx, const ResidualFitter& f) {
  CandidateResult out;
  out.effect = "camera_response";
  std::vector<float> values;
  for (const PixelRecord& r : f.records()) {
    if (!r.held_out && !r.outlier) values.push_back(r.sim.mean());
  }
  if (values.size() < 100) return out;
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  const double ref = std::max(1e-12, double(values[values.size() / 2]));
  auto model = [ref](double s, double e) {
    const double mag = ref * std::pow(std::abs(s) / ref, e);
    return s < 0 ? -mag : mag;
  };
  ResidualFit best;
  double best_e = 1;
  // With the materials known the reference is free too: a scale of the powered values.
  const int k = f.nuisance() ? 1 : 2;
  auto basis_at = [&](double e) {
    return [&, e](const PixelRecord& r, int c, double* b) {
      const double m = model(r.sim[c], e);
      b[0] = m - r.sim[c];
      if (k == 2) b[1] = m;
    };
  };
  // The basis is a curve of the render's noisy value: its fits are corrected for that noise
  // (ResidualFitter::FitNoisyBasis) with m'(s) = e (|s|/r)^(e−1) and m''(s) = sign(s) e (e − 1)
  // (|s|/r)^(e−2) / r, where the noise is small beside the value (a second-order expansion; on
  // darker pixels the power is too curved for it, and their share of the sums is small).
  auto derivatives_at = [&](double e) {
    return [&, e](const PixelRecord& r, int c, double* d1, double* d2) {
      const double s = r.sim[c], u = std::abs(s) / ref;
      if (!(double(r.sim_var[c]) < 0.09 * s * s)) return false;
      const double m1 = e * std::pow(u, e - 1), m2 = e * (e - 1) * std::pow(u, e - 2) / ref;
      d1[0] = m1 - 1;
      d2[0] = s < 0 ? -m2 : m2;
      if (k == 2) d1[1] = m1, d2[1] = d2[0];
      return true;
    };
  };
  for (double e : {0.5, 0.6, 0.7, 0.8, 0.9, 1.1, 1.25, 1.4, 1.6, 1.8, 2.0}) {
    const ResidualFit fit = f.FitNoisyBasis(k, basis_at(e), derivatives_at(e));
    if (fit.coef.size() && (best.coef.size() == 0 || fit.train_after < best.train_after)) {
      best = fit, best_e = e;
    }
  }
  if (best.coef.size() == 0) return out;
  // Refine e around the best grid value by golden section on the train error.
  double lo = best_e * 0.85, hi = best_e * 1.15;
  for (int it = 0; it < 14; ++it) {
    const double m1 = lo + (hi - lo) * 0.382, m2 = lo + (hi - lo) * 0.618;
    auto err = [&](double e) {
      return f.FitNoisyBasis(k, basis_at(e), derivatives_at(e)).train_after;
    };
    if (err(m1) < err(m2)) {
      hi = m2;
    } else {
      lo = m1;
    }
  }
  const double e_grid = 0.5 * (lo + hi);
  best = f.FitNoisyBasis(k, basis_at(e_grid), derivatives_at(e_grid));
  if (best.coef.size() == 0) return out;
  FillScores(best, &out);
  // photo ≈ f(v) = v + c·(m(v) − v) + d·m(v), m(v) = r·(v/r)^e_grid: the one power g(v) =
  // (1 + d)·r·(v/r)^e with f's value, (1 + d)·r, and log-log slope, (1 − c + (c + d)·e_grid) /
  // (1 + d), at the reference level v = r. For c near 1 the exponent is e_grid; with d = 0 it is
  // 1 + c(e_grid − 1). The scale moves the reference: (1 + d)·r·(u/r)^e = r'·(u/r')^e.
  const double d = k == 2 ? best.coef[1] : 0.0;
  if (!(1 + d > 0.05)) {
    out.note = fmt::format("the level curve is not a camera response: its scale is {:.3g}", 1 + d);
    return out;
  }
  const double e = (1 - best.coef[0] + (best.coef[0] + d) * e_grid) / (1 + d);
  // Near e = 1 the basis is about c·(e − 1)·s·ln(s/r): c and the searched exponent trade off,
  // and only 1 + c(e − 1) is determined. An exponent outside the range a response can take
  // (the scene's [0.1, 10]; a camera's gamma lies within [0.2, 5]) is the basis fitting
  // something else through the albedos' freedom (−0.18 for a true 0.8, its refit refused by the
  // scene's range check): not a response.
  if (!(e >= 0.2 && e <= 5)) {
    out.note = fmt::format(
        "the level curve is not a camera response: exponent {:.3g} (coefficient {:.3g} at "
        "{:.3g})",
        e, best.coef[0], e_grid);
    return out;
  }
  double reference = k == 2 && std::abs(e - 1) > 1e-3 ? ref * std::pow(1 + d, 1 / (1 - e)) : ref;
  if (!std::isfinite(reference) || !(reference > 1e-3 * ref) || !(reference < 1e3 * ref)) {
    reference = ref;  // an exponent near 1 leaves the reference undetermined
  }
  out.params = {{"exponent", e}, {"reference", reference}};
  out.where = {{"photos", PhotoFiles(cx.model)}, {"frame", "pixel value"}};
  out.num_params = 1;
  out.evidence = fmt::format(
      "photo/model depends on the pixel's level, not on its place or surface: the photos follow "
      "the model's value to the power {:.3f} (slope {:.3f} in log-log)",
      e, e);
  out.valid = true;
  return out;
}

namespace {

class CameraResponseEffect final : public Effect {
 public:
  std::string Name() const override { return "camera_response"; }
  void AddFits(const CandidateContext& cx, const RecordFits& in, const KeyFilter& allowed,
               std::vector<CandidateTask>* tasks) const override {
    if (allowed(Name())) tasks->push_back({[&cx, &f = in.fitter] { return Response(cx, f); }});
  }

  // An exponent fitted on a model whose albedos were solved without it comes out attenuated: the
  // albedos (and maps) had absorbed part of the curve, and the refit's albedos absorb less of the
  // rest. The seed-103 capture with the materials unknown: 0.868 for 0.8 on the baseline, 0.943
  // after the floor's maps, whose refit then lost to an ambient term (−8.9 % against −12.8 % held
  // out) that the true exponent beats. The candidate is fitted again on the refit's own residual
  // (its records where the trial is rendered): in log e, the second fit g1 at x1 (the first step,
  // g0 from 0) gives the attenuation κ = (g0 − g1) / x1 and the fixed point x1 + g1 / κ (a
  // secant), refitted once more. Taken only when the second fit moves the same way as the first
  // and κ is in [0.1, 1] (a fit that absorbs nothing, or overshoots, is left as it was); the
  // held-out test judges the last refit as any other.
  std::optional<Refinement> Refine(const CandidateResult& c, const Json& document,
                                   const recon::Scene& refit, const Simulation& refit_sim,
                                   const DiagnosisModel& m) const override {
    if (!m.materials_solved) return std::nullopt;
    const double e1 = c.params.value("exponent", 1.0);
    if (!(e1 > 0) || std::abs(std::log(e1)) < 1e-3) return std::nullopt;
    const std::vector<PixelRecord> records =
        BuildRecords(refit, m.photos, refit_sim.sims, m.options, &refit_sim.variance);
    int num_cells = 0;
    std::vector<int> cells = RecordCells(refit, records, m.cell_m, &num_cells);
    const ResidualFitter f(records, std::move(cells), num_cells, true, m.options.holdout_block_px);
    const CandidateResult again =
        Response({refit, document, true, m.cell_m, m.options.holdout_block_px}, f);
    if (!again.valid) return std::nullopt;
    const double x1 = std::log(e1), g0 = x1, g1 = std::log(again.params.value("exponent", 1.0));
    const double kappa = (g0 - g1) / x1;
    spdlog::info(
        "igi-diagnose: camera_response refitted on its own residual: exponent {:.4f} more "
        "(attenuation {:.2f})",
        std::exp(g1), kappa);
    if (!(g1 * g0 > 0) || !(kappa >= 0.1 && kappa <= 1)) return std::nullopt;
    const double x = x1 + g1 / kappa, e = std::exp(x);
    const double reference = again.params.value("reference", c.params.value("reference", 1.0));
    // The document's exponents carry the first step's: it is taken back and the fixed point
    // written in its place.
    recon::SceneDocument doc(document);
    for (size_t i = 0; i < doc.NumPhotos(); ++i) {
      const std::optional<double> exponent = doc.PhotoResponseExponent(i);
      doc.SetPhotoResponse(i, (exponent ? *exponent / e1 : 1.0) * e, reference);
    }
    Refinement out{std::move(doc).json(), c};
    CandidateResult& revised = out.candidate;
    revised.params["first_exponent"] = e1;
    revised.params["exponent"] = e;
    revised.params["reference"] = reference;
    revised.evidence += fmt::format(
        "; fitted again on the refit's residual (a further {:.3f}: the albedos had absorbed a "
        "share {:.2f} of the curve), the exponent's fixed point is {:.3f}",
        std::exp(g1), 1 - kappa, e);
    return out;
  }

  // Every photo's response is composed with the fitted power: exponents multiply, the reference
  // is the fitted one.
  void Write(const CandidateResult& c, recon::SceneDocument* doc) const override {
    const double e = c.params.at("exponent").get<double>();
    const double reference = c.params.at("reference").get<double>();
    for (size_t i = 0; i < doc->NumPhotos(); ++i) {
      doc->SetPhotoResponse(i, doc->PhotoResponseExponent(i).value_or(1.0) * e, reference);
    }
  }
};

}  // namespace

std::unique_ptr<Effect> MakeCameraResponse() { return std::make_unique<CameraResponseEffect>(); }

}  // namespace igi::diagnose
