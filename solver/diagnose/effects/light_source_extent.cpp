// light_source_extent (docs/diagnose-effects.md): a point (or small sphere) light that is really a
// larger sphere of the same intensity.

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <unordered_map>
#include <vector>

#include "solver/diagnose/effects/effects.h"
#include "solver/diagnose/residual_fit.h"
#include "solver/render/brdf.h"
#include "solver/render/ray_scene.h"
#include "solver/render/sampling.h"
#include "tools/common/parallel.h"

namespace igi::diagnose {

namespace {

using Eigen::Vector3d;

Json Vec(const Vector3d& v) { return Json::array({v.x(), v.y(), v.z()}); }

// Per record: kFootprint points of the pixel's footprint (the photo and the model's render average
// the pixel, and a hard shadow edge inside a pixel is no edge of the record's centre), each with
// kConeSamples directions toward the light: 64 samples, the same for every radius.
constexpr int kFootprint = 16, kConeSamples = 4;
constexpr float kMinChange = 0.15f;
constexpr int kMinBlockRecords = 4;     // in a 16-pixel block; in proportion to the block's area
constexpr double kLargestRadius = 0.5;  // m: the largest sphere ExtentFit tries

// 1 − cos θmax of a cone whose half-angle has sine² `sin2`, without cancellation.
double OneMinusCosMax(double sin2) { return sin2 / (1 + std::sqrt(1 - sin2)); }

// A light as a sphere of `intensity` (W/sr) at `center`.
struct SphereSource {
  Vector3d center = Vector3d::Zero();
  Vector3d intensity = Vector3d::Zero();
};

// A surface point seen through the record's pixel.
struct FootprintPoint {
  Eigen::Vector3f position, normal, view;  // normal toward the camera
  int region = -1;
};

// The direct radiance a sphere source of radius `radius` (0: a point) sends toward the camera
// from footprint point `q` (BRDF of its region with the record's albedo, shadow rays through the
// model's geometry), from the cone samples `u`; adds the unoccluded share to `lit`/`above`.
Vector3d DirectAt(const render::RayScene& impl, int target, const SphereSource& s,
                  const FootprintPoint& q, const Eigen::Vector3f& albedo, double radius,
                  const Eigen::Vector2d* u, int* lit, int* above) {
  const render::ShadingMaterial& sm = impl.material(q.region);
  render::BrdfParams params = sm.params;
  params.rho_d = albedo.cast<double>();
  const Vector3d p = q.position.cast<double>(), n = q.normal.cast<double>();
  const render::Frame frame = recon::IsAnisotropic(params.model) && sm.tangent
                                  ? render::Frame::FromNormalTangent(n, *sm.tangent)
                                  : render::Frame::FromNormal(n);
  const Vector3d lo = frame.ToLocal(q.view.cast<double>());
  const Vector3d origin = p + n * (4 * impl.ray_epsilon());
  const Vector3d to = s.center - p;
  const double d = to.norm();
  if (!(d > 0)) return Vector3d::Zero();
  const Vector3d w = to / d;
  const double cos_center = w.dot(n);
  if (radius <= 0 || radius >= 0.95 * d) {  // a point (or a point inside the sphere)
    if (!(cos_center > 0)) return Vector3d::Zero();
    ++*above;
    if (impl.Occluded(origin, w, d - 4 * impl.ray_epsilon(), target)) return Vector3d::Zero();
    ++*lit;
    return render::EvalBrdf(params, lo, frame.ToLocal(w)).cwiseProduct(s.intensity) *
           (cos_center / (d * d));
  }
  const double sin2 = radius * radius / (d * d);
  const double one_minus = OneMinusCosMax(sin2);
  const render::Frame cone = render::Frame::FromNormal(w);
  const Vector3d radiance = s.intensity / (render::kPi * radius * radius);
  const Vector3d rho_pi = params.rho_d * render::kInvPi;
  Vector3d sum = Vector3d::Zero(), diffuse = Vector3d::Zero();
  for (int k = 0; k < kConeSamples; ++k) {
    const double ct = 1 - u[k].x() * one_minus, st = std::sqrt(std::max(0.0, 1 - ct * ct));
    const double ph = 2 * render::kPi * u[k].y();
    const Vector3d dir = cone.ToWorld({st * std::cos(ph), st * std::sin(ph), ct});
    const double cs = dir.dot(n);
    if (!(cs > 0)) continue;
    ++*above;
    diffuse += rho_pi.cwiseProduct(radiance) * cs;
    const double t = d * ct - std::sqrt(std::max(0.0, radius * radius - d * d * st * st));
    if (impl.Occluded(origin, dir, t - 4 * impl.ray_epsilon(), target)) continue;
    ++*lit;
    sum += render::EvalBrdf(params, lo, frame.ToLocal(dir)).cwiseProduct(radiance) * cs;
  }
  // pdf = 1 / (2π (1 − cos θmax)) per sample.
  const double weight = 2 * render::kPi * one_minus / kConeSamples;
  // Control variate: a sphere wholly above the horizon gives exactly the irradiance of a point
  // of the same intensity at its centre, I·cos/d²; the samples' estimate of that unoccluded
  // diffuse term is swapped for the exact value, so a fully lit diffuse point shows no change.
  if (cos_center > std::sqrt(sin2)) {
    const Vector3d exact = rho_pi.cwiseProduct(s.intensity) * (cos_center / (d * d));
    return (sum - diffuse) * weight + exact;
  }
  return sum * weight;
}

// The change is kept where it can show: on records where it reaches kMinChange of the model's
// value (below that, the render's own noise at a few hundred paths per pixel hides it), in
// held-out blocks with at least kMinBlockRecords such records per 16 × 16 pixels of the block (a
// 16-pixel block of one changed record scores noise). Elsewhere it is set to zero: those records
// are outside the candidate's support. On a subsample of one record in `stride` the blocks hold
// that many times fewer records. (In proportion to the area: with 8-pixel blocks
// the fixed 4 left no held-out block to a penumbra 2–3 records wide, and the suite's
// light_source_extent candidate, at the right radius, predicted a gain of exactly 0.)
void KeepMarkedChanges(const std::vector<PixelRecord>& recs, int block_px, int stride,
                       std::vector<Eigen::Vector3f>* change) {
  const int min_records = std::max(1, int(std::lround(kMinBlockRecords * (block_px / 16.0) *
                                                      (block_px / 16.0) / std::max(1, stride))));
  std::unordered_map<int64_t, int> count;
  auto block = [&](const PixelRecord& r) {
    return (int64_t(r.photo) << 40) + (int64_t(r.y / block_px) << 20) + r.x / block_px;
  };
  for (size_t i = 0; i < recs.size(); ++i) {
    if ((*change)[i].norm() <= kMinChange * recs[i].sim.norm()) {
      (*change)[i].setZero();
    } else {
      ++count[block(recs[i])];
    }
  }
  for (size_t i = 0; i < recs.size(); ++i) {
    if (count[block(recs[i])] < min_records) (*change)[i].setZero();
  }
}

class ExtentModel {
 public:
  // With `hidden`, also what Hidden needs (a shadow ray and a ray beyond the light per record);
  // the callers that ask for the direct term only (the tail's edges, WhereLightSizeShows) skip it.
  ExtentModel(const CandidateContext& cx, const std::vector<PixelRecord>& records, int light,
              bool hidden = false)
      : cx_(cx),
        records_(records),
        impls_(cx.model.lightings.size()),
        target_(cx.model.lightings.size(), -1),
        u_(records.size()),
        points_(records.size()),
        hidden_(records.size(), Eigen::Vector3f::Zero()),
        hidden_distance_(records.size(), 0.0f) {
    const recon::Light& l = cx.model.lights[light];
    source_.center = l.type == recon::LightType::kSphere ? l.center : l.position;
    source_.intensity = l.type == recon::LightType::kSphere
                            ? Vector3d(l.radiance * (render::kPi * l.radius * l.radius))
                            : l.intensity;
    declared_radius_ = l.type == recon::LightType::kSphere ? l.radius : 0.0;
    for (size_t g = 0; g < cx.model.lightings.size(); ++g) {
      const std::vector<int>& ids = cx.model.lightings[g].lights;
      const auto it = std::find(ids.begin(), ids.end(), light);
      if (it != ids.end()) target_[g] = int(it - ids.begin());
    }
    for (const recon::Photo& p : cx.model.photos) {
      if (target_[p.lighting] >= 0 && !impls_[p.lighting]) {
        impls_[p.lighting] = std::make_unique<render::RayScene>(cx.model, p.lighting);
      }
    }
    ParallelFor(0, int64_t(records.size()), [&](int64_t i) { Prepare(size_t(i), hidden); });
  }

  double declared_radius() const { return declared_radius_; }
  const SphereSource& source() const { return source_; }

  // The direct term of the light at every record (scaled to the photo's values) for `radius`,
  // and its visible share.
  std::vector<Eigen::Vector3f> Direct(double radius, std::vector<float>* visible = nullptr) const {
    std::vector<Eigen::Vector3f> out(records_.size(), Eigen::Vector3f::Zero());
    if (visible) visible->assign(records_.size(), 0.0f);
    ParallelFor(0, int64_t(records_.size()), [&](int64_t i) {
      const PixelRecord& r = records_[i];
      const recon::Photo& photo = cx_.model.photos[r.photo];
      if (target_[photo.lighting] < 0 || points_[i].empty()) return;
      const render::RayScene& impl = *impls_[photo.lighting];
      Vector3d sum = Vector3d::Zero();
      int lit = 0, above = 0;
      for (size_t k = 0; k < points_[i].size(); ++k) {
        sum += DirectAt(impl, target_[photo.lighting], source_, points_[i][k], r.albedo, radius,
                        &u_[i][k * kConeSamples], &lit, &above);
      }
      out[i] = (sum * (Scale(r) / double(points_[i].size()))).cast<float>();
      if (visible) (*visible)[i] = above ? float(lit) / float(above) : 0.0f;
    });
    return out;
  }

  // The change of every record's value when the light is a sphere of `radius` rather than the
  // declared one: an opaque emitter hides the surface behind it from the record's point (light
  // that point no longer receives after a bounce). Without its shadow edges and highlights
  // (Direct's change), this is smooth and touches every record that sees the light: a lamp just
  // under a ceiling hides the ceiling's brightest patch, much of the room's bounced light
  // (a 0.25 m sphere 0.6 m under the ceiling made the room's interreflected light
  // 6.5 % dimmer, which a weaker lamp had stood in for). Each record loses the hidden surface's
  // radiance (its region's albedo under the light's direct irradiance; its own bounced light left
  // out) over the sphere's solid angle, through the record's diffuse reflectance. The surface's
  // radiance is taken on the cone's axis: its mean over 8 directions in the cone (the patch behind
  // a lamp under a ceiling falls off within the cone) moved the suite's fitted amplitude from
  // 0.717 to 0.721 at three times the cost).
  std::vector<Eigen::Vector3f> Hidden(double radius) const {
    std::vector<Eigen::Vector3f> out(records_.size(), Eigen::Vector3f::Zero());
    auto solid_angle = [](double r, double d) {
      if (!(r > 0) || !(d > 0)) return 0.0;
      const double sin2 = std::min(0.95, r * r / (d * d));
      return 2 * render::kPi * OneMinusCosMax(sin2);
    };
    for (size_t i = 0; i < records_.size(); ++i) {
      const double d = hidden_distance_[i];
      if (!(d > 0)) continue;
      const double change = solid_angle(radius, d) - solid_angle(declared_radius_, d);
      out[i] = -hidden_[i] * float(change);
    }
    return out;
  }

 private:
  // The photo's exposure scale and its camera's vignetting at the record's pixel.
  double Scale(const PixelRecord& r) const {
    const recon::Photo& photo = cx_.model.photos[r.photo];
    double scale = photo.exposure_scale;
    if (photo.camera >= 0 && photo.camera < int(cx_.model.cameras.size())) {
      scale *=
          cx_.model.cameras[photo.camera].VignettingFactor(Eigen::Vector2d(r.x + 0.5, r.y + 0.5));
    }
    return scale;
  }

  // The radiance per steradian the light's sphere hides from the record's point (Hidden).
  void PrepareHidden(size_t i) {
    const PixelRecord& r = records_[i];
    const recon::Photo& photo = cx_.model.photos[r.photo];
    const render::RayScene& impl = *impls_[photo.lighting];
    const Vector3d p = r.position.cast<double>(), n = r.normal.cast<double>();
    const Vector3d to = source_.center - p;
    const double d = to.norm();
    if (!(d > kLargestRadius)) return;
    const Vector3d w = to / d;
    const double cos_p = w.dot(n);
    if (!(cos_p > 0)) return;
    const Vector3d origin = p + n * (4 * impl.ray_epsilon());
    if (impl.Occluded(origin, w, d - 4 * impl.ray_epsilon(), target_[photo.lighting])) return;
    // The surface behind the light, seen from the point through its centre.
    const std::optional<render::SurfaceHit> hit =
        impl.TraceSurface(source_.center + w * (declared_radius_ + 4 * impl.ray_epsilon()), w);
    if (!hit || hit->region < 0 || hit->region >= int(cx_.model.materials.size())) return;
    const recon::Material& m = cx_.model.materials[hit->region];
    const double t = (hit->position - source_.center).norm();
    const double cos_h = -hit->n_s.dot(w);
    if (!m.rho_d || !(t > 0) || !(cos_h > 0)) return;
    const Vector3d behind =
        m.rho_d->cwiseProduct(source_.intensity) * (render::kInvPi * cos_h / (t * t));
    hidden_[i] =
        (r.albedo.cast<double>().cwiseProduct(behind) * (render::kInvPi * cos_p * Scale(r)))
            .cast<float>();
    hidden_distance_[i] = float(d);
  }

  // The record's footprint points and cone samples.
  void Prepare(size_t i, bool hidden) {
    const PixelRecord& r = records_[i];
    const recon::Photo& photo = cx_.model.photos[r.photo];
    if (target_[photo.lighting] < 0 || r.region < 0) return;
    if (hidden) PrepareHidden(i);
    render::Pcg32 rng = render::PixelSampleRng(0x5eed, i, 0);
    const bool camera = photo.camera >= 0 && photo.camera < int(cx_.model.cameras.size());
    for (int k = 0; k < kFootprint; ++k) {  // without a camera: the centre kFootprint times
      FootprintPoint q{r.position, r.normal, r.view, r.region};
      if (camera) {
        const recon::Camera& cam = cx_.model.cameras[photo.camera];
        const double sx = (k % 4 + rng.UniformDouble()) / 4, sy = (k / 4 + rng.UniformDouble()) / 4;
        const Vector3d eye = cam.CenterInWorld();
        const Vector3d dir = cam.WorldRayFromImg(Eigen::Vector2d(r.x + sx, r.y + sy));
        const std::optional<render::SurfaceHit> hit =
            impls_[photo.lighting]->TraceSurface(eye, dir);
        if (!hit || hit->region != r.region) continue;  // off the record's surface
        q = {hit->position.cast<float>(), hit->n_s.cast<float>(), (-dir).cast<float>(),
             hit->region};
      }
      points_[i].push_back(q);
    }
    // Cone samples: stratified over the points together (8×8 strata for 16 points × 4).
    const int n = int(points_[i].size()) * kConeSamples;
    const int side = std::max(1, int(std::lround(std::sqrt(double(n)))));
    for (int k = 0; k < n; ++k) {
      const int cell = int((uint64_t(k) * 37) % uint64_t(n));  // decorrelated from the points
      u_[i].emplace_back((cell % side + rng.UniformDouble()) / side,
                         std::min(0.999999, ((cell / side) % side + rng.UniformDouble()) / side));
    }
  }

  const CandidateContext& cx_;
  const std::vector<PixelRecord>& records_;
  std::vector<std::unique_ptr<render::RayScene>> impls_;
  std::vector<int> target_;  // per lighting: the light's index among its emitters, or -1
  std::vector<std::vector<Eigen::Vector2d>> u_;
  std::vector<std::vector<FootprintPoint>> points_;
  std::vector<Eigen::Vector3f> hidden_;  // per record: Hidden's change per steradian
  std::vector<float> hidden_distance_;   // per record: distance to the light (0: none hidden)
  SphereSource source_;
  double declared_radius_ = 0;
};

// A larger sphere's change of the direct term on one fitter's records, fitted per radius.
class ExtentChange {
 public:
  ExtentChange(const CandidateContext& cx, const ResidualFitter& f, int light, int stride)
      : cx_(cx), f_(f), model_(cx, f.records(), light, true), stride_(stride) {
    d0_ = model_.Direct(model_.declared_radius(), &vis0_);
  }
  const ExtentModel& model() const { return model_; }
  const std::vector<Eigen::Vector3f>& d0() const { return d0_; }
  const std::vector<float>& vis0() const { return vis0_; }

  ResidualFit operator()(double radius) {
    ch_.basis = model_.Direct(radius);
    for (size_t i = 0; i < ch_.basis.size(); ++i) ch_.basis[i] -= d0_[i];
    KeepMarkedChanges(f_.records(), cx_.block_px, stride_, &ch_.basis);
    const std::vector<Eigen::Vector3f> hidden = model_.Hidden(radius);
    for (size_t i = 0; i < ch_.basis.size(); ++i) ch_.basis[i] += hidden[i];
    return FitChange(f_, ch_);
  }

  // The held-out blocks where the last call's change is kept (KeepMarkedChanges' support).
  std::vector<std::array<int, 3>> HeldOutSupport() const {
    std::set<std::array<int, 3>> blocks;
    const std::vector<PixelRecord>& recs = f_.records();
    for (size_t i = 0; i < recs.size() && i < ch_.basis.size(); ++i) {
      if (recs[i].held_out && ch_.basis[i].squaredNorm() > 0) {
        blocks.insert({recs[i].photo, recs[i].x / cx_.block_px, recs[i].y / cx_.block_px});
      }
    }
    return {blocks.begin(), blocks.end()};
  }

 private:
  const CandidateContext& cx_;
  const ResidualFitter& f_;
  const ExtentModel model_;
  int stride_;
  std::vector<float> vis0_;
  std::vector<Eigen::Vector3f> d0_;
  Change ch_;
};

// The radius is searched on `search`'s records (one in `stride` of f's), then fitted and scored
// on f's.
CandidateResult ExtentFit(const CandidateContext& cx, const ResidualFitter& f,
                          const ResidualFitter& search, int stride, int light) {
  CandidateResult out;
  out.effect = "light_source_extent";
  const recon::Light& l = cx.model.lights[light];
  const std::vector<PixelRecord>& recs = f.records();
  bool photographed = false;
  for (const recon::Photo& p : cx.model.photos) {
    const std::vector<int>& ids = cx.model.lightings[p.lighting].lights;
    photographed |= std::find(ids.begin(), ids.end(), light) != ids.end();
  }
  if (!photographed) {
    out.note = "light '" + l.name + "' lights no photo";
    return out;
  }
  ExtentChange fit_at(cx, search, light, &search == &f ? 1 : stride);
  const double r0 = fit_at.model().declared_radius();
  auto physical = [](const ResidualFit& fit) {
    return fit.coef.size() == 1 && fit.coef[0] > 0.3 && fit.coef[0] < 3;
  };
  // The model has no free amplitude (a sphere of the same intensity): the fit's amplitude is a
  // check, and r is chosen by the train error at amplitude 1. The error is quadratic in the
  // amplitude a: E(1) = E(a*) + (1 − a*)² (E(0) − E(a*)) / a*².
  auto error_at_one = [](const ResidualFit& fit) {
    const double a = fit.coef[0];
    return fit.train_after + (1 - a) * (1 - a) * (fit.train_before - fit.train_after) / (a * a);
  };
  std::vector<std::pair<double, ResidualFit>> tried;
  for (double radius : {0.02, 0.035, 0.05, 0.08, 0.12, 0.17, 0.23, 0.3, 0.4, kLargestRadius}) {
    if (radius > 1.25 * r0 + 0.005) tried.emplace_back(radius, fit_at(radius));
  }
  int best = -1;
  for (int i = 0; i < int(tried.size()); ++i) {
    if (physical(tried[i].second) &&
        (best < 0 || error_at_one(tried[i].second) < error_at_one(tried[best].second))) {
      best = i;
    }
  }
  if (best < 0) {
    out.note = "no larger sphere for light '" + l.name + "' explains the residual";
    return out;
  }
  // Golden section on log r between the best grid value's neighbours.
  double lo = std::log(tried[std::max(0, best - 1)].first);
  double hi = std::log(tried[std::min(int(tried.size()) - 1, best + 1)].first);
  double radius = tried[best].first;
  ResidualFit fit = tried[best].second;
  for (int it = 0; it < 6; ++it) {
    const double m1 = lo + 0.382 * (hi - lo), m2 = lo + 0.618 * (hi - lo);
    const ResidualFit f1 = fit_at(std::exp(m1)), f2 = fit_at(std::exp(m2));
    if (!physical(f1) || !physical(f2)) break;
    const bool left = error_at_one(f1) < error_at_one(f2);
    (left ? hi : lo) = left ? m2 : m1;
    const ResidualFit& fb = left ? f1 : f2;
    if (error_at_one(fb) < error_at_one(fit)) {
      fit = fb, radius = std::exp(left ? m1 : m2);
    }
  }
  std::optional<ExtentChange> every;
  if (&search != &f) {
    every.emplace(cx, f, light, 1);
    fit = (*every)(radius);
    if (!physical(fit)) {
      out.note = fmt::format(
          "light '{}': the radius found on a subsample ({:.3f} m) does not fit every record",
          l.name, radius);
      return out;
    }
  }
  if (!every) fit = fit_at(radius);  // the golden section's last call may be another radius
  const ExtentChange& scored = every ? *every : fit_at;
  const ExtentModel& model = scored.model();
  const std::vector<Eigen::Vector3f>& d0 = scored.d0();
  const std::vector<float>& vis0 = scored.vis0();
  // Where the change lies: at shadow edges (penumbrae) or elsewhere (highlights).
  std::vector<float> vis;
  const std::vector<Eigen::Vector3f> dr = model.Direct(radius, &vis);
  int edge = 0, other = 0;  // records the change marks (KeepMarkedChanges' first rule)
  for (size_t i = 0; i < recs.size(); ++i) {
    if (!((dr[i] - d0[i]).norm() > kMinChange * recs[i].sim.norm())) continue;
    const bool penumbra = (vis[i] > 0.02f && vis[i] < 0.98f) || std::abs(vis[i] - vis0[i]) > 0.02f;
    ++(penumbra ? edge : other);
  }
  // The light the sphere hides (Hidden): its mean share of the records' values.
  const std::vector<Eigen::Vector3f> hidden = model.Hidden(radius);
  double hidden_sum = 0, sim_sum = 0;
  for (size_t i = 0; i < recs.size(); ++i) {
    if (hidden[i].squaredNorm() > 0) hidden_sum -= hidden[i].sum(), sim_sum += recs[i].sim.sum();
  }
  FillScores(fit, &out);
  out.support_blocks = scored.HeldOutSupport();
  const double amplitude = fit.coef[0];
  const Vector3d center = model.source().center, intensity = model.source().intensity;
  out.params = {{"light", l.name},        {"radius", radius},      {"declared_radius", r0},
                {"amplitude", amplitude}, {"center", Vec(center)}, {"intensity", Vec(intensity)}};
  out.where = {{"light", l.name}, {"frame", "shadow and highlight edges"}};
  out.num_params = 1;
  out.evidence = fmt::format(
      "light '{}' is larger than a {}: a sphere of radius {:.3f} m with the same intensity "
      "predicts softer shadow edges and broader highlights ({} samples changed by more than "
      "{:.0f}% in penumbrae at shadow edges, {} in highlights) and, an opaque emitter, hides the "
      "surfaces behind it from the rest ({:.1f}% of the light of the records that see it); "
      "fitted amplitude {:.2f} of the predicted change",
      l.name, r0 > 0 ? fmt::format("sphere of {:.3f} m", r0) : std::string("point"), radius, edge,
      100 * kMinChange, other, sim_sum > 0 ? 100 * hidden_sum / sim_sum : 0.0, amplitude);
  out.valid = true;
  return out;
}

}  // namespace

CandidateResult LightSourceExtent(const CandidateContext& cx, const ResidualFitter& f, int light,
                                  const RecordSubset* search) {
  const recon::Light& l = cx.model.lights[light];
  if (l.type != recon::LightType::kPoint && l.type != recon::LightType::kSphere) {
    CandidateResult out;
    out.effect = "light_source_extent";
    return out;
  }
  // Records flagged as outliers (far in the residual's tail) take no part in the other fits; at
  // this light's shadow edges the tail is the extent's own signal (a hard shadow where the photos
  // show a penumbra): those whose direct term the largest sphere tried changes take part here, as
  // pose_error takes back its camera's sharp edges.
  const std::vector<PixelRecord>& recs = f.records();
  std::vector<size_t> flagged;
  for (size_t i = 0; i < recs.size(); ++i) {
    if (recs[i].outlier) flagged.push_back(i);
  }
  std::vector<PixelRecord> tail;
  for (size_t i : flagged) tail.push_back(recs[i]);
  int taken_back = 0;
  std::vector<PixelRecord> records;
  if (!tail.empty()) {
    const ExtentModel model(cx, tail, light);
    std::vector<float> vis0, vis1;
    const std::vector<Eigen::Vector3f> d0 = model.Direct(model.declared_radius(), &vis0);
    const std::vector<Eigen::Vector3f> d1 = model.Direct(kLargestRadius, &vis1);
    for (size_t k = 0; k < tail.size(); ++k) {
      const bool edge = (vis1[k] > 0.02f && vis1[k] < 0.98f) || std::abs(vis1[k] - vis0[k]) > 0.02f;
      if (edge && (d1[k] - d0[k]).norm() > kMinChange * tail[k].sim.norm()) {
        if (records.empty()) records = recs;
        records[flagged[k]].outlier = false;
        ++taken_back;
      }
    }
  }
  CandidateResult out;
  if (taken_back == 0) {
    out = search ? ExtentFit(cx, f, search->fitter(), search->stride(), light)
                 : ExtentFit(cx, f, f, 1, light);
  } else {
    const RecordSubset edges(cx.model, std::move(records), cx.cell_m, f.nuisance(), cx.block_px);
    if (search) {
      const RecordSubset sub(cx.model, edges.records(), cx.cell_m, f.nuisance(), cx.block_px,
                             search->stride());
      out = ExtentFit(cx, edges.fitter(), sub.fitter(), search->stride(), light);
    } else {
      out = ExtentFit(cx, edges.fitter(), edges.fitter(), 1, light);
    }
    const std::string taken = fmt::format(
        "; {} records of the residual's tail at the light's shadow edges taken back", taken_back);
    (out.valid ? out.evidence : out.note) += taken;
  }
  return out;
}

std::vector<bool> WhereLightSizeShows(const CandidateContext& cx,
                                      const std::vector<PixelRecord>& records, int light) {
  std::vector<bool> out(records.size(), false);
  const recon::Light& l = cx.model.lights[light];
  if (l.type != recon::LightType::kPoint && l.type != recon::LightType::kSphere) return out;
  if (records.empty()) return out;
  const ExtentModel model(cx, records, light);
  if (!(kLargestRadius > model.declared_radius())) return out;
  const std::vector<Eigen::Vector3f> d0 = model.Direct(model.declared_radius());
  const std::vector<Eigen::Vector3f> d1 = model.Direct(kLargestRadius);
  for (size_t i = 0; i < records.size(); ++i) {
    out[i] = (d1[i] - d0[i]).norm() > kMinChange * records[i].sim.norm();
  }
  return out;
}

namespace {

class LightSourceExtentEffect final : public Effect {
 public:
  std::string Name() const override { return "light_source_extent"; }
  void AddFits(const CandidateContext& cx, const RecordFits& in, const KeyFilter& allowed,
               std::vector<CandidateTask>* tasks) const override {
    for (int l = 0; l < int(cx.model.lights.size()); ++l) {
      const recon::Light& light = cx.model.lights[l];
      if ((light.type != recon::LightType::kPoint && light.type != recon::LightType::kSphere) ||
          !allowed(Name() + ":" + light.name)) {
        continue;
      }
      tasks->push_back(
          {[&cx, &f = in.fitter, sub = in.search, l] { return LightSourceExtent(cx, f, l, sub); }});
    }
  }
  // The light becomes a sphere of the fitted radius at its position, with its intensity.
  void Write(const CandidateResult& c, recon::SceneDocument* doc) const override {
    const double radius = c.params.at("radius").get<double>();
    const Json& intensity = c.params.at("intensity");
    Json radiance = Json::array();
    for (const Json& v : intensity)
      radiance.push_back(v.get<double>() / (render::kPi * radius * radius));
    doc->SetLight(c.params.at("light").get<std::string>(), {{"type", "sphere"},
                                                            {"center", c.params.at("center")},
                                                            {"radius", radius},
                                                            {"radiance", radiance}});
  }
};

}  // namespace

std::unique_ptr<Effect> MakeLightSourceExtent() {
  return std::make_unique<LightSourceExtentEffect>();
}

}  // namespace igi::diagnose
