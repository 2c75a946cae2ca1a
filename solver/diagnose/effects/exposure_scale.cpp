// exposure_scale (docs/diagnose-effects.md): one photo (or a few) brighter or darker than the
// model as a whole, on every surface alike.

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "solver/diagnose/effects/effects.h"
#include "solver/diagnose/residual_fit.h"
#include "solver/render/brdf.h"
#include "solver/render/sampling.h"

namespace igi::diagnose {

namespace {

// Whether `light` is the only light of every photographed lighting: then everything the photos
// record comes from it (bounces too), and a scale common to all photos is its intensity.
bool AloneInEveryPhoto(const recon::Scene& model, int light) {
  for (const recon::Photo& p : model.photos) {
    if (p.lighting < 0 || p.lighting >= int(model.lightings.size())) return false;
    const std::vector<int>& lights = model.lightings[p.lighting].lights;
    if (lights.size() != 1 || lights[0] != light) return false;
  }
  return !model.photos.empty();
}

// The light that is alone in every photographed lighting, or -1.
int LoneLight(const recon::Scene& model) {
  for (int l = 0; l < int(model.lights.size()); ++l) {
    if (AloneInEveryPhoto(model, l)) return l;
  }
  return -1;
}

}  // namespace

CandidateResult ExposureScale(const CandidateContext& cx, const ResidualFitter& f) {
  CandidateResult out;
  out.effect = "exposure_scale";
  const int n = int(cx.model.photos.size());
  if (n < 2) {
    out.note = "one photo: a scale of its own cannot be told from the model's";
    return out;
  }
  ResidualFit fit =
      f.Fit(n, [&](const PixelRecord& r, int c, double* b) { b[r.photo] = r.sim[c]; });
  if (fit.coef.size() == 0) return out;
  std::vector<double> scale(n);
  for (int j = 0; j < n; ++j) scale[j] = 1 + fit.coef[j];
  std::vector<double> sorted = scale;
  std::nth_element(sorted.begin(), sorted.begin() + n / 2, sorted.end());
  double ref = cx.materials_solved ? sorted[n / 2] : 1.0;
  // Materials given and one light alone in every photo: a scale common to all photos is that
  // light's intensity (light_intensity, one parameter), so the photos' scales are fitted relative
  // to the photo at the median (n − 1 parameters).
  const int lone = cx.materials_solved ? -1 : LoneLight(cx.model);
  int num_groups = 0;
  if (lone >= 0) {
    int ref_photo = 0;
    for (int j = 0; j < n; ++j) {
      if (scale[j] == sorted[n / 2]) ref_photo = j;
    }
    auto slot = [ref_photo](int photo) { return photo < ref_photo ? photo : photo - 1; };
    fit = f.Fit(n - 1, [&](const PixelRecord& r, int c, double* b) {
      if (r.photo != ref_photo) b[slot(r.photo)] = r.sim[c];
    });
    if (fit.coef.size() == 0) return out;
    for (int j = 0; j < n; ++j) scale[j] = j == ref_photo ? 1.0 : 1 + fit.coef[slot(j)];
    ref = 1.0;
    num_groups = 1;
  }
  // Photos under several lightings: a scale common to one lighting's photos is its lights'
  // (their intensity, or an emission profile that leaves the room darker as a whole), and, with
  // the materials solved, a scale common to every photo the albedos'. The photos' scales are
  // credited only with what they explain beyond a scale per lighting (the fit's "before"), and
  // fitted relative to their lighting's photo at its median (n − lightings parameters). Fitted
  // free, 11 photo scales (0.13-0.42 under the lamp, 1.06-1.20 under lamp2) were applied first in
  // the place of the suite's seed-107 hidden emission profile (materials solved), and the three
  // photos under the RADIANCE room's lamp, rendered by Cycles with the lamp 1.3x as bright, were
  // named exposure_scale, not light_intensity (materials given).
  std::vector<int> group(n, 0);
  std::map<int, int> ids;
  for (int j = 0; j < n; ++j) {
    group[j] = ids.emplace(cx.model.photos[j].lighting, int(ids.size())).first->second;
  }
  if (ids.size() >= 2) num_groups = int(ids.size());
  if (num_groups >= 2) {
    std::vector<int> is_ref(n, 0);
    for (int g = 0; g < num_groups; ++g) {
      std::vector<std::pair<double, int>> members;
      for (int j = 0; j < n; ++j) {
        if (group[j] == g) members.emplace_back(scale[j], j);
      }
      std::nth_element(members.begin(), members.begin() + members.size() / 2, members.end());
      is_ref[members[members.size() / 2].second] = 1;
    }
    std::vector<int> slot(n, -1);
    int k = 0;
    for (int j = 0; j < n; ++j) {
      if (!is_ref[j]) slot[j] = num_groups + k++;
    }
    if (k == 0) {
      out.note = "one photo per lighting: a photo's scale cannot be told from its lights'";
      return out;
    }
    fit = f.FitBeyond(num_groups + k, num_groups, [&](const PixelRecord& r, int c, double* b) {
      b[group[r.photo]] = r.sim[c];
      if (slot[r.photo] >= 0) b[slot[r.photo]] = r.sim[c];
    });
    if (fit.coef.size() == 0) return out;
    // A photo's scale relative to its lighting's reference photo, (m + c) / m: m, the reference
    // photo's level against the model (1 + its cell's albedo change + its lighting's scale: only
    // their sum is determined), measured on its records; c, the photo's own coefficient.
    std::vector<double> sp(num_groups, 0.0), ss(num_groups, 0.0);
    for (const PixelRecord& r : f.records()) {
      if (r.held_out || r.outlier || r.photo < 0 || r.photo >= n || !is_ref[r.photo]) continue;
      sp[group[r.photo]] += r.recorded.cast<double>().dot(r.sim.cast<double>());
      ss[group[r.photo]] += r.sim.cast<double>().squaredNorm();
    }
    for (int j = 0; j < n; ++j) {
      const int g = group[j];
      const double m = ss[g] > 0 ? sp[g] / ss[g] : 1.0;
      scale[j] = slot[j] < 0 || !(m > 0) ? 1.0 : (m + fit.coef[slot[j]]) / m;
    }
    ref = 1.0;
  }
  FillScores(fit, &out);
  const std::vector<std::string> files = PhotoFiles(cx.model);
  Json scales = Json::object();
  Json photos = Json::array();
  std::string worst = files[0];
  double worst_dev = -1;
  for (int j = 0; j < n; ++j) {
    const double v = scale[j] / ref;
    scales[files[j]] = v;
    if (std::abs(v - 1) > 0.02) photos.push_back(files[j]);
    if (std::abs(v - 1) > worst_dev) worst_dev = std::abs(v - 1), worst = files[j];
  }
  out.params = {{"scale", scales}};
  out.where = {{"photos", photos}, {"frame", "photo"}};
  out.num_params = n - num_groups;
  out.evidence = fmt::format(
      "per-photo level: {} is {:.3f}x the model where the other photos agree with it, on every "
      "surface alike: a scale of the whole photo",
      worst, double(scales[worst]));
  out.valid = true;
  return out;
}

namespace {

class ExposureScaleEffect final : public Effect {
 public:
  std::string Name() const override { return "exposure_scale"; }
  void AddFits(const CandidateContext& cx, const RecordFits& in, const KeyFilter& allowed,
               std::vector<CandidateTask>* tasks) const override {
    if (allowed(Name())) tasks->push_back({[&cx, &f = in.fitter] { return ExposureScale(cx, f); }});
  }
  // Each photo's exposure_scale is multiplied by its fitted scale.
  void Write(const CandidateResult& c, recon::SceneDocument* doc) const override {
    const Json& scales = c.params.at("scale");
    for (size_t i = 0; i < doc->NumPhotos(); ++i) {
      const std::string file = std::filesystem::path(doc->PhotoFile(i)).filename().string();
      if (!scales.contains(file)) continue;
      doc->SetPhotoExposure(i, doc->PhotoExposure(i).value_or(1.0) * scales[file].get<double>());
    }
  }
};

}  // namespace

std::unique_ptr<Effect> MakeExposureScale() { return std::make_unique<ExposureScaleEffect>(); }

}  // namespace igi::diagnose
