// light_intensity (docs/diagnose-effects.md): a light brighter or dimmer than declared.

#include <fmt/format.h>

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

CandidateResult LightIntensity(const CandidateContext& cx, const ResidualFitter& f, int light) {
  CandidateResult out;
  out.effect = "light_intensity";
  const recon::Light& l = cx.model.lights[light];
  const std::vector<PixelRecord>& recs = f.records();
  std::vector<float> share(recs.size(), 0.0f);
  bool any = false;
  float share_min = 1, share_max = 0;
  // Photos whose lighting is this light alone: all they record comes from it, the light it sends
  // after bounces (shadows too) included.
  std::vector<bool> alone(cx.model.photos.size(), false);
  for (size_t j = 0; j < alone.size(); ++j) {
    const int g = cx.model.photos[j].lighting;
    alone[j] = g >= 0 && g < int(cx.model.lightings.size()) &&
               cx.model.lightings[g].lights == std::vector<int>{light};
  }
  for (size_t i = 0; i < share.size(); ++i) {
    float mine = 0, all = 0;
    for (const RecordLightSample& s : recs[i].lights) {
      all += s.irradiance.sum();
      if (s.light == light) mine += s.irradiance.sum();
    }
    share[i] = all > 0 ? mine / all : 0;
    if (recs[i].photo >= 0 && recs[i].photo < int(alone.size()) && alone[recs[i].photo]) {
      share[i] = 1;
    }
    any |= mine > 0;
    if (all > 0 && !recs[i].outlier) {  // records in shadow scale with the light's bounces
      share_min = std::min(share_min, share[i]);
      share_max = std::max(share_max, share[i]);
    }
  }
  if (!any) return out;
  // With the albedos free, a light that brings all the direct light of every lit sample (the
  // only one of every photographed lighting) scales like the albedos: nothing is left of its basis
  // after the nuisance. (A light alone in its own lighting among others — one directional light per
  // photo, as in DiLiGenT — is a scale of its photos and can be told apart.)
  if (f.nuisance() && share_max - share_min < 1e-4f) {
    out.note = "light '" + l.name +
               "' is alone in every photographed lighting: its intensity cannot be told from "
               "the albedos";
    return out;
  }
  // Where the light's size shows (penumbrae, highlights: WhereLightSizeShows) its intensity is
  // not fitted: the records there take no part (as outliers do) and the cells are drawn again.
  const std::vector<bool> size_shows = WhereLightSizeShows(cx, recs, light);
  int left_out = 0;
  std::vector<PixelRecord> kept_records;
  for (size_t i = 0; i < recs.size(); ++i) {
    if (!size_shows[i] || recs[i].outlier) continue;
    if (kept_records.empty()) kept_records = recs;
    kept_records[i].outlier = true;
    ++left_out;
  }
  std::optional<RecordSubset> kept;
  if (left_out > 0) {
    kept.emplace(cx.model, std::move(kept_records), cx.cell_m, f.nuisance(), cx.block_px);
  }
  const ResidualFitter& fitter = kept ? kept->fitter() : f;
  const PixelRecord* first = fitter.records().data();
  const ResidualFit fit = fitter.Fit(1, [&](const PixelRecord& r, int c, double* b) {
    b[0] = r.sim[c] * share[size_t(&r - first)];
  });
  if (fit.coef.size() == 0) return out;
  FillScores(fit, &out);
  const double factor = 1 + fit.coef[0];
  if (!(factor > 0)) return out;
  out.params = {{"light", l.name}, {"factor", factor}};
  out.where = {{"light", l.name}, {"frame", "light"}};
  out.num_params = 1;
  out.evidence = fmt::format(
      "where light '{}' dominates, the photos are {:.3f}x the model; elsewhere they agree", l.name,
      factor);
  if (left_out > 0) {
    out.evidence += fmt::format(
        " ({} samples in its penumbrae and highlights, where a larger source would differ, left "
        "out of the fit)",
        left_out);
  }
  out.valid = true;
  return out;
}

namespace {

class LightIntensityEffect final : public Effect {
 public:
  std::string Name() const override { return "light_intensity"; }
  void AddFits(const CandidateContext& cx, const RecordFits& in, const KeyFilter& allowed,
               std::vector<CandidateTask>* tasks) const override {
    for (int l = 0; l < int(cx.model.lights.size()); ++l) {
      const recon::Light& light = cx.model.lights[l];
      if (light.type == recon::LightType::kAmbient || !allowed(Name() + ":" + light.name)) continue;
      tasks->push_back({[&cx, &f = in.fitter, l] { return LightIntensity(cx, f, l); }});
    }
  }
  // The light's intensity (or radiance, or irradiance) is multiplied by the fitted factor.
  void Write(const CandidateResult& c, recon::SceneDocument* doc) const override {
    doc->ScaleLightEmission(c.params.at("light").get<std::string>(),
                            c.params.at("factor").get<double>());
  }
};

}  // namespace

std::unique_ptr<Effect> MakeLightIntensity() { return std::make_unique<LightIntensityEffect>(); }

}  // namespace igi::diagnose
