// light_emission_profile (docs/diagnose-effects.md): a light brighter in some directions than
// others.

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "solver/diagnose/effects/effects.h"
#include "solver/diagnose/residual_fit.h"
#include "solver/render/brdf.h"
#include "solver/render/sampling.h"

namespace igi::diagnose {

namespace {

// Whether photo `photo`'s lighting has light `light`.
bool LitBy(const recon::Scene& model, int photo, int light) {
  if (photo < 0 || photo >= int(model.photos.size())) return false;
  const int g = model.photos[photo].lighting;
  if (g < 0 || g >= int(model.lightings.size())) return false;
  const std::vector<int>& ids = model.lightings[g].lights;
  return std::find(ids.begin(), ids.end(), light) != ids.end();
}

// Whether `l` is a spot with a cos^n profile (an emission profile kept in an earlier step).
bool CosProfiled(const recon::Light& l) {
  return l.type == recon::LightType::kSpot && l.profile.kind == recon::SpotProfile::Kind::kCosPower;
}

// The direct light of one light at a record toward the camera, Σ f(wi, view)·irradiance with the
// region's BRDF (ρd from the record; an anisotropic lobe, whose tangent the records lack, counts
// as its diffuse part only), and the mean direction from the light to the point.
struct LightTerm {
  Eigen::Vector3f direct = Eigen::Vector3f::Zero();
  Eigen::Vector3f from_light = Eigen::Vector3f::Zero();
  bool lit = false;
};

LightTerm TermOf(const recon::Scene& model, const PixelRecord& r, int light) {
  LightTerm t;
  render::BrdfParams p;
  if (r.region >= 0 && r.region < int(model.materials.size())) {
    const recon::Material& m = model.materials[r.region];
    if (recon::IsReflective(m.brdf) && !recon::IsAnisotropic(m.brdf) && m.rho_s && m.alpha) {
      p.model = m.brdf;
      p.rho_s = *m.rho_s;
      p.alpha = *m.alpha;
      p.ior = m.ior.value_or(recon::Material::kDefaultIor);
    }
  }
  p.rho_d = r.albedo.cast<double>();
  const render::Frame frame = render::Frame::FromNormal(r.normal.cast<double>());
  const Eigen::Vector3d wo = frame.ToLocal(r.view.cast<double>());
  for (const RecordLightSample& s : r.lights) {
    if (s.light != light) continue;
    const Eigen::Vector3d f = render::EvalBrdf(p, wo, frame.ToLocal(s.wi.cast<double>()));
    t.direct += f.cast<float>().cwiseProduct(s.irradiance);
    t.from_light -= s.wi;
    t.lit = true;
  }
  if (t.lit) t.from_light.normalize();
  return t;
}

std::vector<Eigen::Vector3d> SphereDirections(int n) {
  std::vector<Eigen::Vector3d> d;
  const double golden = render::kPi * (3 - std::sqrt(5.0));
  for (int i = 0; i < n; ++i) {
    const double z = 1 - 2 * (i + 0.5) / n, rr = std::sqrt(1 - z * z);
    d.emplace_back(rr * std::cos(golden * i), rr * std::sin(golden * i), z);
  }
  return d;
}

// The median of the records' mean model value (a response's reference level).
double MedianSim(const std::vector<PixelRecord>& records) {
  std::vector<float> values;
  for (const PixelRecord& r : records) {
    if (!r.held_out && !r.outlier) values.push_back(r.sim.mean());
  }
  if (values.empty()) return 1.0;
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return std::max(1e-12, double(values[values.size() / 2]));
}

// The fit of light `light`'s emission profile on one fitter's records: its direct terms once,
// then a fit per (axis, power).
class ProfileFit {
 public:
  ProfileFit(const CandidateContext& cx, const ResidualFitter& f, int light)
      : f_(f),
        num_regions_(int(cx.model.materials.size())),
        terms_(f.records().size()),
        current_(f.records().size(), 1.0f),
        in_lighting_(f.records().size(), 0) {
    const std::vector<PixelRecord>& recs = f.records();
    // A spot with a cos^n profile already (a profile kept earlier, refitted): its direct term
    // carries the current profile, which the new one replaces.
    const recon::Light& l = cx.model.lights[light];
    const bool profiled = CosProfiled(l);
    const Eigen::Vector3f axis0 = l.direction.normalized().cast<float>();
    for (size_t i = 0; i < terms_.size(); ++i) {
      terms_[i] = TermOf(cx.model, recs[i], light);
      in_lighting_[i] = LitBy(cx.model, recs[i].photo, light);
      if (profiled && terms_[i].lit) {
        current_[i] =
            std::pow(std::max(0.0f, terms_[i].from_light.dot(axis0)), float(l.profile.cos_power));
        if (!(current_[i] > 1e-3f)) terms_[i].lit = false;  // no light there to rescale
      }
      lit_ += terms_[i].lit;
    }
    ref_ = MedianSim(recs);
    current_flux_ = profiled ? 1 / (2 * (l.profile.cos_power + 1)) : 1.0;
  }
  int lit() const { return lit_; }

  // The profile with its bounced light fixed by its flux (materials given): the light's direct
  // term becomes peak·D·cos^n, and what is not its direct term, in its own photos, scales as the
  // light's emitted flux, peak·Φ(n)/Φ0 (Φ(n) = ∫ max(0, cos)^n dω / 4π = 1 / (2(n + 1)) for the
  // cos^n spot, Φ0 the current light's: 1 for an isotropic one). One coefficient, the peak: the
  // change fitted is peak·(D·cos^n + q·(sim − D)) − sim, q = Φ(n)/Φ0, which is what a refit
  // renders, up to how each region's bounces differ from the room's mean. The free per-region
  // scales of operator() can stand in for light the profile takes away (a profile whose back
  // hemisphere is dark, the ceiling above the lamp left to its bounces: 9.6 % predicted held-out
  // gain for a lamp RADIANCE rendered as an isotropic sphere, +130 % in the trial); this fit
  // cannot.
  ResidualFit FluxBounced(const Eigen::Vector3d& axis, double n) const {
    const Eigen::Vector3f ax = axis.cast<float>();
    const PixelRecord* base = f_.records().data();
    const double q = 1 / (2 * (n + 1)) / current_flux_;
    auto relative = [&](const PixelRecord& r) {
      const size_t i = size_t(&r - base);
      return std::pow(double(std::max(0.0f, terms_[i].from_light.dot(ax))), n) /
             double(current_[i]);
    };
    // The change at peak 1 (the offset) and per unit of the peak's change (the basis).
    auto parts = [&](const PixelRecord& r, int c, double* offset, double* per_peak) {
      const size_t i = size_t(&r - base);
      const LightTerm& t = terms_[i];
      const double d = t.lit ? double(t.direct[c]) : 0.0;
      const double bounced = in_lighting_[i] ? double(r.sim[c]) - d : 0.0;
      *per_peak = d * (t.lit ? relative(r) : 1.0) + q * bounced;
      *offset = *per_peak - d - bounced;
    };
    return f_.Fit(
        1,
        [&](const PixelRecord& r, int c, double* b) {
          double o;
          parts(r, c, &o, b);
        },
        [&](const PixelRecord& r, int c) {
          double o, b;
          parts(r, c, &o, &b);
          return o;
        });
  }

  // The direct light of `light` (diffuse and specular) becomes D·cos^n(angle from the axis): a
  // fixed change of amplitude 1. The light it sends after a bounce changes too, by a share that
  // differs between surfaces (the ceiling, lit only by bounces from what the spot lights, loses
  // more than the floor): what is not its direct term gets a free scale per region (the albedos'
  // nuisance covers that when they are solved). With the materials given, the spot's peak
  // intensity is free too (the last coefficient scales D·cos^n): a lamp with a reflector sends
  // more than its declared intensity along its axis and less elsewhere (the RADIANCE room's lamp
  // rendered by Cycles as 2·cos θ about straight down: with the peak held at the declared
  // intensity, the profile's power ran to 0.03, and light_intensity (0.60x) was kept in its place).
  // With the materials solved, the refit's albedos absorb a scale of the light. With
  // `response_nuisance`, a camera response beside the profile (its expansion to second order,
  // u·ln(u/ref) and u·ln²(u/ref), u the profiled value; a power r·(u/r)^e = u·exp((e −
  // 1)·ln(u/r))).
  ResidualFit operator()(const Eigen::Vector3d& axis, double n, bool response_nuisance) const {
    const Eigen::Vector3f ax = axis.cast<float>();
    const PixelRecord* base = f_.records().data();
    const int k_regions = f_.nuisance() ? 1 : num_regions_;
    const int k_response = response_nuisance ? 2 : 0;
    const bool peak = !f_.nuisance();
    // cos^n − 1 of the last record asked for (the fit asks per channel, record by record).
    const PixelRecord* last = nullptr;
    double change = 0;
    auto offset = [&](const PixelRecord& r, int c) {
      const LightTerm& t = terms_[size_t(&r - base)];
      if (!t.lit) return 0.0;
      if (&r != last) {
        last = &r;
        change = std::pow(double(std::max(0.0f, t.from_light.dot(ax))), n) /
                     double(current_[size_t(&r - base)]) -
                 1;
      }
      return double(t.direct[c]) * change;
    };
    return f_.Fit(
        k_regions + k_response + (peak ? 1 : 0),
        [&](const PixelRecord& r, int c, double* b) {
          const LightTerm& t = terms_[size_t(&r - base)];
          // The bounced light changes in the light's own photos only: a scale per region there
          // (in other lightings' photos it would be a free scale of their whole light, and
          // lamp2's profile, scaled so, stood in for the lamp's brightness at 69 %).
          if (!f_.nuisance() && r.region >= 0 && r.region < num_regions_ &&
              in_lighting_[size_t(&r - base)]) {
            b[r.region] = double(r.sim[c]) - double(t.direct[c]);
          }
          const double o = offset(r, c);
          const double u = double(r.sim[c]) + o;
          if (response_nuisance && u > 0) {
            const double log_u = std::log(u / ref_);
            b[k_regions] = u * log_u;
            b[k_regions + 1] = u * log_u * log_u;
          }
          if (peak) b[k_regions + k_response] = double(t.direct[c]) + o;  // D·cos^n, profiled
        },
        offset);
  }

 private:
  const ResidualFitter& f_;
  int num_regions_;
  std::vector<LightTerm> terms_;
  std::vector<float> current_;  // per record: the light's current relative intensity toward it
  std::vector<uint8_t> in_lighting_;  // per record: its photo's lighting has the light
  int lit_ = 0;
  double ref_ = 1;
  double current_flux_ = 1;  // Φ0: the light's current flux relative to an isotropic light's
};

}  // namespace

CandidateResult EmissionProfile(const CandidateContext& cx, const ResidualFitter& f, int light,
                                const RecordSubset* search) {
  CandidateResult out;
  out.effect = "light_emission_profile";
  const recon::Light& l = cx.model.lights[light];
  const ProfileFit all(cx, f, light);
  if (all.lit() < 100) return out;
  // The axis and power are searched with a camera response beside the profile as a nuisance: a
  // response the photos also hide (a power of the pixel value) would otherwise bend the
  // profile's fit (an 11° axis error and power 2.38 for 2 in the light_emission_profile +
  // camera_response capture), and the response could then no longer be proven. The search runs
  // on `search`'s records when given (a subsample), the final fit on every record; the scores
  // come from the fit without the response: the profile must explain on its own what it is
  // credited with.
  //
  // With the materials solved and photos under lightings without the light, the search runs on
  // the light's own photos only, with their own albedo nuisance. Shared by the lightings, the
  // baseline's albedos are a compromise between them, and the light's bounced light, which its
  // profile changes in its own photos only, cannot go into them: the search then follows the
  // lightings' difference, not the profile's shape (the suite's seed-107 capture, a cos² spot
  // straight down: cos^14 about an axis pointing up; on the lamp's photos alone, cos^1.43 about
  // an axis 6.8° from the true one, then applied first with 85 % of the held-out residual²). The
  // scores still come from every record with the albedos shared: what the refit will face.
  const std::vector<PixelRecord>& pool = search ? search->records() : f.records();
  std::vector<PixelRecord> own;
  bool others = false;
  for (const PixelRecord& r : pool) {
    if (LitBy(cx.model, r.photo, light)) {
      own.push_back(r);
    } else {
      others = true;
    }
  }
  std::optional<RecordSubset> own_subset;
  if (f.nuisance() && others && own.size() >= 1000) {
    own_subset.emplace(cx.model, std::move(own), cx.cell_m, true, cx.block_px);
  }
  std::optional<ProfileFit> subset;
  if (own_subset) {
    subset.emplace(cx, own_subset->fitter(), light);
  } else if (search) {
    subset.emplace(cx, search->fitter(), light);
  }
  const ProfileFit& fit_at = subset ? *subset : all;
  ResidualFit best;
  double best_n = 1;
  Eigen::Vector3d best_axis = -Eigen::Vector3d::UnitZ();
  auto consider = [&](const Eigen::Vector3d& axis, double n) {
    const ResidualFit fit = fit_at(axis, n, true);
    if (fit.coef.size() == 0) return false;
    if (best.coef.size() && fit.train_after >= best.train_after) return false;
    best = fit, best_axis = axis, best_n = n;
    return true;
  };
  const bool refit = CosProfiled(l);
  const Eigen::Vector3d axis0 = l.direction.normalized();  // the current profile's, if refit
  if (refit) consider(axis0, l.profile.cos_power);
  for (const Eigen::Vector3d& axis : SphereDirections(64)) {
    for (double n : {1.0, 3.0}) consider(axis, n);
  }
  if (best.coef.size() == 0) {
    out.note = "no axis makes the light's own direct term explain the residual";
    return out;
  }
  for (double step : {0.2, 0.08, 0.03}) {
    for (int round = 0; round < 10; ++round) {
      bool moved = false;
      for (int d = 0; d < 6; ++d) {
        Eigen::Vector3d axis = best_axis;
        axis[d / 2] += (d % 2 ? -step : step);
        moved |= consider(axis.normalized(), best_n);
      }
      for (double factor : {1 - step, 1 / (1 - step)})
        moved |= consider(best_axis, best_n * factor);
      if (!moved) break;
    }
  }
  // With the materials given, the axis and power found are fitted with the bounced light fixed
  // by the profile's flux (FluxBounced): the candidate is credited with what a refit can render.
  best = f.nuisance() ? all(best_axis, best_n, false) : all.FluxBounced(best_axis, best_n);
  if (best.coef.size() == 0) {
    out.note = "the profile alone does not fit (degenerate)";
    return out;
  }
  // The spot's peak intensity relative to the declared one (materials given: the last
  // coefficient; solved: 1). A profile that needs a light of no intensity, or one that leaves the
  // room more than ten times as bright, is no emission profile.
  const double peak = f.nuisance() ? 1.0 : 1 + best.coef[best.coef.size() - 1];
  if (!(peak > 0.05 && peak < 10)) {
    out.note = fmt::format("the profile's peak intensity comes out {:.3f}x the declared one", peak);
    return out;
  }
  FillScores(best, &out);
  const double n = best_n;
  const Eigen::Vector3d position = l.type == recon::LightType::kSphere ? l.center : l.position;
  const Eigen::Vector3d intensity =
      peak * (l.type == recon::LightType::kSphere
                  ? Eigen::Vector3d(l.radiance * (std::numbers::pi * l.radius * l.radius))
                  : l.intensity);
  out.params = {{"light", l.name},
                {"direction", {best_axis.x(), best_axis.y(), best_axis.z()}},
                {"cos_power", n},
                {"position", {position.x(), position.y(), position.z()}},
                {"intensity", {intensity.x(), intensity.y(), intensity.z()}}};
  if (refit) {
    out.params["refined_from"] = {{"direction", {axis0.x(), axis0.y(), axis0.z()}},
                                  {"cos_power", l.profile.cos_power}};
  }
  out.params["peak_factor"] = peak;
  out.where = {{"light", l.name}, {"frame", "angle from the light"}};
  out.num_params = f.nuisance() ? 3 : 4;
  out.evidence = fmt::format(
      "the residual follows the direction from light '{}': surfaces it reaches at larger angles "
      "from ({:.2f}, {:.2f}, {:.2f}) are darker in the photos than the model, as cos^{:.2f} of "
      "that angle, whatever their distance, region or image position (peak {:.2f}x the declared "
      "intensity)",
      l.name, best_axis.x(), best_axis.y(), best_axis.z(), n, peak);
  if (refit) {
    out.evidence += fmt::format(
        " (its profile refitted: it was cos^{:.2f} about ({:.2f}, {:.2f}, {:.2f}), {:.1f} deg "
        "from the new axis)",
        l.profile.cos_power, axis0.x(), axis0.y(), axis0.z(),
        std::acos(std::clamp(axis0.dot(best_axis), -1.0, 1.0)) * 180 / std::numbers::pi);
  }
  out.valid = true;
  return out;
}

namespace {

class LightEmissionProfileEffect final : public Effect {
 public:
  std::string Name() const override { return "light_emission_profile"; }
  // Every point-like light; a profile kept in an earlier step (found while other effects were
  // still unmodelled, or while the albedos were a compromise of the lightings) is refitted once.
  void AddFits(const CandidateContext& cx, const RecordFits& in, const KeyFilter& allowed,
               std::vector<CandidateTask>* tasks) const override {
    for (int l = 0; l < int(cx.model.lights.size()); ++l) {
      const recon::Light& light = cx.model.lights[l];
      const bool point_like = light.type == recon::LightType::kPoint ||
                              light.type == recon::LightType::kSphere ||
                              (light.type == recon::LightType::kSpot &&
                               light.profile.kind == recon::SpotProfile::Kind::kNone);
      const std::string key = Name() + ":" + light.name;
      if ((point_like && allowed(key)) || (CosProfiled(light) && allowed(key + ":refit"))) {
        tasks->push_back(
            {[&cx, &f = in.fitter, sub = in.search, l] { return EmissionProfile(cx, f, l, sub); }});
      }
    }
  }
  // The light becomes a spot at its position, with its intensity, the fitted axis and cos^n.
  void Write(const CandidateResult& c, recon::SceneDocument* doc) const override {
    doc->SetLight(c.params.at("light").get<std::string>(),
                  {{"type", "spot"},
                   {"position", c.params.at("position")},
                   {"direction", c.params.at("direction")},
                   {"intensity", c.params.at("intensity")},
                   {"profile", {{"cos_power", c.params.at("cos_power")}}}});
  }
};

}  // namespace

std::unique_ptr<Effect> MakeLightEmissionProfile() {
  return std::make_unique<LightEmissionProfileEffect>();
}

}  // namespace igi::diagnose
