#include "solver/diagnose/candidates_brdf_light.h"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <optional>
#include <set>
#include <unordered_map>

#include "solver/brdf.h"
#include "solver/render_internal.h"
#include "solver/sampling.h"
#include "solver/surface_hit.h"
#include "tools/common/parallel.h"

namespace igi {
namespace {

using Eigen::Vector3d;

Json Vec(const Vector3d& v) { return Json::array({v.x(), v.y(), v.z()}); }

// The records' change of model for one parameter set, per record and channel (zero where the
// candidate does not touch the record), fitted with one free amplitude against a fixed offset.
struct Change {
  std::vector<Eigen::Vector3f> basis;   // amplitude-1 value of the new term
  std::vector<Eigen::Vector3f> offset;  // fixed change (the old term removed), or empty
};

ResidualFit FitChange(const ResidualFitter& f, const Change& ch) {
  const PixelRecord* base = f.records().data();
  return f.Fit(
      1, [&](const PixelRecord& r, int c, double* b) { b[0] = ch.basis[size_t(&r - base)][c]; },
      [&](const PixelRecord& r, int c) {
        return ch.offset.empty() ? 0.0 : double(ch.offset[size_t(&r - base)][c]);
      });
}

// ---------------------------------------------------------------- anisotropic_reflection
BrdfModel AnisotropicOf(BrdfModel m) {
  switch (m) {
    case BrdfModel::kWard:
      return BrdfModel::kWardAniso;
    case BrdfModel::kWardGmd:
      return BrdfModel::kWardGmdAniso;
    case BrdfModel::kWardFresnel:
      return BrdfModel::kWardAnisoFresnel;
    case BrdfModel::kWardGmdFresnel:
      return BrdfModel::kWardGmdAnisoFresnel;
    default:
      return m;
  }
}

// The colourless specular factor of `model` (with its Fresnel weight) in `frame`.
double Specular(BrdfModel model, double ax, double ay, double ior, const Frame& frame,
                const Vector3d& wo, const Vector3d& wi) {
  const Vector3d lo = frame.ToLocal(wo), li = frame.ToLocal(wi);
  double s = SpecularFactor<double>(model, ax, ay, lo, li);
  if (s > 0 && HasFresnel(model)) s *= FresnelWeight<double>(ior, lo, li);
  return s;
}

// The lobe of one region at its records, for a lobe model and parameters.
class RegionLobe {
 public:
  RegionLobe(const std::vector<PixelRecord>& records, int region, const Material& m)
      : records_(records),
        region_(region),
        rho_s_(m.rho_s.value_or(Vector3d::Zero())),
        ior_(m.ior.value_or(Material::kDefaultIor)) {}

  // ρs_c Σ S(wo, wi)·E_c per record (zero off the region); tangent only for anisotropic models.
  std::vector<Eigen::Vector3f> Term(BrdfModel model, double ax, double ay,
                                    const Vector3d& tangent) const {
    std::vector<Eigen::Vector3f> out(records_.size(), Eigen::Vector3f::Zero());
    for (size_t i = 0; i < records_.size(); ++i) {
      const PixelRecord& r = records_[i];
      if (r.region != region_) continue;
      const Vector3d n = r.normal.cast<double>(), wo = r.view.cast<double>();
      const Frame frame =
          IsAnisotropic(model) ? Frame::FromNormalTangent(n, tangent) : Frame::FromNormal(n);
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
  const Frame f = Frame::FromNormal(n.normalized());
  return {f.n, f.t, f.b};
}

struct LobeParams {
  double phi = 0, ax = 0.1, ay = 0.1;  // tangent angle (radians) in the highlight plane
};

// The region's current lobe and an anisotropic one on one fitter's records.
class LobeFit {
 public:
  LobeFit(const ResidualFitter& f, int region, const Material& m)
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
  BrdfModel to_;
  std::vector<Eigen::Vector3f> current_;
  Change ch_;
};

// The lobe's parameters are searched on `search`'s records (the region's, subsampled), then
// fitted and scored on `f`'s.
CandidateResult AnisotropicFit(const CandidateContext& cx, const ResidualFitter& f,
                               const ResidualFitter& search, int region) {
  CandidateResult out;
  out.effect = "anisotropic_reflection";
  const Material& m = cx.model.materials[region];
  LobeFit lobe(search, region, m);
  const std::array<Vector3d, 3> plane = HighlightPlane(search.records(), region, lobe.current());
  const BrdfModel to = AnisotropicOf(m.brdf);
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
      for (size_t j = i + 1; j < grid.size(); ++j) consider({k * kPi / 12, grid[i], grid[j]});
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
        moved |= consider({bp.phi + s * step * kPi / 24, bp.ax, bp.ay});
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
  const std::string to_name(BrdfModelName(to));
  out.params = {{"region", m.name}, {"from", BrdfModelName(m.brdf)},
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
  const std::string name = m.name;
  const double ax = bp.ax, ay = bp.ay;
  out.apply = [name, to_name, tangent, ax, ay, k](Json* doc) {
    Json& j = (*doc)["materials"][name];
    j["brdf"] = to_name;
    j["tangent"] = Vec(tangent);
    const bool known_alpha = j.contains("alpha");
    j.erase("alpha");
    if (known_alpha) j["alpha_x"] = ax, j["alpha_y"] = ay;
    if (j.contains("rho_s")) {
      if (j["rho_s"].is_number()) j["rho_s"] = j["rho_s"].get<double>() * k;
      if (j["rho_s"].is_array()) {
        for (Json& v : j["rho_s"]) v = v.get<double>() * k;
      }
    }
  };
  return out;
}

// ---------------------------------------------------------------- light_source_extent
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
Vector3d DirectAt(const Renderer::Impl& impl, int target, const SphereSource& s,
                  const FootprintPoint& q, const Eigen::Vector3f& albedo, double radius,
                  const Eigen::Vector2d* u, int* lit, int* above) {
  const ShadingMaterial& sm = impl.materials[q.region];
  BrdfParams params = sm.params;
  params.rho_d = albedo.cast<double>();
  const Vector3d p = q.position.cast<double>(), n = q.normal.cast<double>();
  const Frame frame = IsAnisotropic(params.model) && sm.tangent
                          ? Frame::FromNormalTangent(n, *sm.tangent)
                          : Frame::FromNormal(n);
  const Vector3d lo = frame.ToLocal(q.view.cast<double>());
  const Vector3d origin = p + n * (4 * impl.ray_epsilon);
  const Vector3d to = s.center - p;
  const double d = to.norm();
  if (!(d > 0)) return Vector3d::Zero();
  const Vector3d w = to / d;
  const double cos_center = w.dot(n);
  if (radius <= 0 || radius >= 0.95 * d) {  // a point (or a point inside the sphere)
    if (!(cos_center > 0)) return Vector3d::Zero();
    ++*above;
    if (impl.Occluded(origin, w, d - 4 * impl.ray_epsilon, target)) return Vector3d::Zero();
    ++*lit;
    return EvalBrdf(params, lo, frame.ToLocal(w)).cwiseProduct(s.intensity) *
           (cos_center / (d * d));
  }
  const double sin2 = radius * radius / (d * d);
  const double one_minus = OneMinusCosMax(sin2);
  const Frame cone = Frame::FromNormal(w);
  const Vector3d radiance = s.intensity / (kPi * radius * radius);
  const Vector3d rho_pi = params.rho_d * kInvPi;
  Vector3d sum = Vector3d::Zero(), diffuse = Vector3d::Zero();
  for (int k = 0; k < kConeSamples; ++k) {
    const double ct = 1 - u[k].x() * one_minus, st = std::sqrt(std::max(0.0, 1 - ct * ct));
    const double ph = 2 * kPi * u[k].y();
    const Vector3d dir = cone.ToWorld({st * std::cos(ph), st * std::sin(ph), ct});
    const double cs = dir.dot(n);
    if (!(cs > 0)) continue;
    ++*above;
    diffuse += rho_pi.cwiseProduct(radiance) * cs;
    const double t = d * ct - std::sqrt(std::max(0.0, radius * radius - d * d * st * st));
    if (impl.Occluded(origin, dir, t - 4 * impl.ray_epsilon, target)) continue;
    ++*lit;
    sum += EvalBrdf(params, lo, frame.ToLocal(dir)).cwiseProduct(radiance) * cs;
  }
  // pdf = 1 / (2π (1 − cos θmax)) per sample.
  const double weight = 2 * kPi * one_minus / kConeSamples;
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
// that many times fewer records. (In proportion to the area since session 16: with 8-pixel blocks
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
    const Light& l = cx.model.lights[light];
    source_.center = l.type == LightType::kSphere ? l.center : l.position;
    source_.intensity = l.type == LightType::kSphere
                            ? Vector3d(l.radiance * (kPi * l.radius * l.radius))
                            : l.intensity;
    declared_radius_ = l.type == LightType::kSphere ? l.radius : 0.0;
    for (size_t g = 0; g < cx.model.lightings.size(); ++g) {
      const std::vector<int>& ids = cx.model.lightings[g].lights;
      const auto it = std::find(ids.begin(), ids.end(), light);
      if (it != ids.end()) target_[g] = int(it - ids.begin());
    }
    for (const Photo& p : cx.model.photos) {
      if (target_[p.lighting] >= 0 && !impls_[p.lighting]) {
        impls_[p.lighting] = BuildRenderScene(cx.model, p.lighting);
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
      const Photo& photo = cx_.model.photos[r.photo];
      if (target_[photo.lighting] < 0 || points_[i].empty()) return;
      const Renderer::Impl& impl = *impls_[photo.lighting];
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
  // (session 19: a 0.25 m sphere 0.6 m under the ceiling made the room's interreflected light
  // 6.5 % dimmer, which a weaker lamp had stood in for). Each record loses the hidden surface's
  // radiance (its region's albedo under the light's direct irradiance; its own bounced light left
  // out) over the sphere's solid angle, through the record's diffuse reflectance. The surface's
  // radiance is taken on the cone's axis: its mean over 8 directions in the cone (the patch behind
  // a lamp under a ceiling falls off within the cone) moved the suite's fitted amplitude from
  // 0.717 to 0.721 at three times the cost (session 21).
  std::vector<Eigen::Vector3f> Hidden(double radius) const {
    std::vector<Eigen::Vector3f> out(records_.size(), Eigen::Vector3f::Zero());
    auto solid_angle = [](double r, double d) {
      if (!(r > 0) || !(d > 0)) return 0.0;
      const double sin2 = std::min(0.95, r * r / (d * d));
      return 2 * kPi * OneMinusCosMax(sin2);
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
    const Photo& photo = cx_.model.photos[r.photo];
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
    const Photo& photo = cx_.model.photos[r.photo];
    const Renderer::Impl& impl = *impls_[photo.lighting];
    const Vector3d p = r.position.cast<double>(), n = r.normal.cast<double>();
    const Vector3d to = source_.center - p;
    const double d = to.norm();
    if (!(d > kLargestRadius)) return;
    const Vector3d w = to / d;
    const double cos_p = w.dot(n);
    if (!(cos_p > 0)) return;
    const Vector3d origin = p + n * (4 * impl.ray_epsilon);
    if (impl.Occluded(origin, w, d - 4 * impl.ray_epsilon, target_[photo.lighting])) return;
    // The surface behind the light, seen from the point through its centre.
    const std::optional<SurfaceHit> hit =
        TraceSurface(impl, source_.center + w * (declared_radius_ + 4 * impl.ray_epsilon), w);
    if (!hit || hit->region < 0 || hit->region >= int(cx_.model.materials.size())) return;
    const Material& m = cx_.model.materials[hit->region];
    const double t = (hit->position - source_.center).norm();
    const double cos_h = -hit->n_s.dot(w);
    if (!m.rho_d || !(t > 0) || !(cos_h > 0)) return;
    const Vector3d behind = m.rho_d->cwiseProduct(source_.intensity) * (kInvPi * cos_h / (t * t));
    hidden_[i] =
        (r.albedo.cast<double>().cwiseProduct(behind) * (kInvPi * cos_p * Scale(r))).cast<float>();
    hidden_distance_[i] = float(d);
  }

  // The record's footprint points and cone samples.
  void Prepare(size_t i, bool hidden) {
    const PixelRecord& r = records_[i];
    const Photo& photo = cx_.model.photos[r.photo];
    if (target_[photo.lighting] < 0 || r.region < 0) return;
    if (hidden) PrepareHidden(i);
    Pcg32 rng = PixelSampleRng(0x5eed, i, 0);
    const bool camera = photo.camera >= 0 && photo.camera < int(cx_.model.cameras.size());
    for (int k = 0; k < kFootprint; ++k) {  // without a camera: the centre kFootprint times
      FootprintPoint q{r.position, r.normal, r.view, r.region};
      if (camera) {
        const Camera& cam = cx_.model.cameras[photo.camera];
        const double sx = (k % 4 + rng.UniformDouble()) / 4, sy = (k / 4 + rng.UniformDouble()) / 4;
        const Vector3d eye = cam.CenterInWorld();
        const Vector3d dir = cam.WorldRayFromImg(Eigen::Vector2d(r.x + sx, r.y + sy));
        const std::optional<SurfaceHit> hit = TraceSurface(*impls_[photo.lighting], eye, dir);
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
  std::vector<std::unique_ptr<Renderer::Impl>> impls_;
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
  const Light& l = cx.model.lights[light];
  const std::vector<PixelRecord>& recs = f.records();
  bool photographed = false;
  for (const Photo& p : cx.model.photos) {
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
  out.params = {
      {"light", l.name}, {"radius", radius}, {"declared_radius", r0}, {"amplitude", amplitude}};
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
  const std::string name = l.name;
  out.apply = [name, center, intensity, radius](Json* doc) {
    const Vector3d radiance = intensity / (kPi * radius * radius);
    (*doc)["lights"][name] = {{"type", "sphere"},
                              {"center", Vec(center)},
                              {"radius", radius},
                              {"radiance", Vec(radiance)}};
  };
  return out;
}

}  // namespace

CandidateResult AnisotropicReflection(const CandidateContext& cx, const ResidualFitter& f,
                                      int region) {
  const Material& m = cx.model.materials[region];
  const bool plain = m.brdf == BrdfModel::kWard || m.brdf == BrdfModel::kWardGmd ||
                     m.brdf == BrdfModel::kWardFresnel || m.brdf == BrdfModel::kWardGmdFresnel;
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

CandidateResult LightSourceExtent(const CandidateContext& cx, const ResidualFitter& f, int light,
                                  const RecordSubset* search) {
  const Light& l = cx.model.lights[light];
  if (l.type != LightType::kPoint && l.type != LightType::kSphere) {
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
  const Light& l = cx.model.lights[light];
  if (l.type != LightType::kPoint && l.type != LightType::kSphere) return out;
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

// ---------------------------------------------------------------- ambient_light
// What an ambient light of unit radiance adds at each record, as the photo sees it: the radiance
// reflected toward the camera (ρd·1 at the point, plus what the room reflects of it: every bounce,
// rendered with the model's materials and no other light; emitters made black), times the photo's
// exposure scale and the camera's vignetting. 16 paths per record: the first vertex is exact for
// the diffuse term (the renderer evaluates ambient light exactly), the bounces are averaged.
std::vector<Eigen::Vector3f> UnitAmbientResponse(const Scene& model,
                                                 const std::vector<PixelRecord>& records) {
  Scene unit = model;
  Light ambient;
  ambient.name = "unit_ambient";
  ambient.type = LightType::kAmbient;
  ambient.radiance = Eigen::Vector3d::Ones();
  unit.lights = {ambient};
  unit.lightings = {Lighting{"unit_ambient", {0}}};
  for (Material& m : unit.materials) {
    if (m.brdf == BrdfModel::kEmitter) m.brdf = BrdfModel::kBlack;
  }
  const Renderer renderer(unit, 0);
  std::vector<Eigen::Vector3f> out(records.size(), Eigen::Vector3f::Zero());
  ParallelFor(0, int64_t(records.size()), [&](int64_t i) {
    const PixelRecord& r = records[i];
    const Photo& photo = model.photos[r.photo];
    const Camera& camera = model.cameras[photo.camera];
    const Eigen::Vector3d center = camera.CenterInWorld();
    const Eigen::Vector3d dir = r.position.cast<double>() - center;
    if (!(dir.norm() > 0)) return;
    const Eigen::Vector3d l = renderer.ReflectedRadiance(center, dir, 16, uint64_t(i) + 1);
    const double k =
        photo.exposure_scale * camera.VignettingFactor(Eigen::Vector2d(r.x + 0.5, r.y + 0.5));
    out[i] = (l * k).cast<float>();
  });
  return out;
}

// The first reflection alone of a unit ambient light at each record: the directional albedo of
// the point's BRDF (the record's ρd, its region's lobe) toward the camera, ∫ f cos θi dωi over the
// hemisphere (the ambient light is never occluded), times the photo's exposure scale and the
// camera's vignetting. 64 stratified BRDF samples (exact for the diffuse term).
std::vector<Eigen::Vector3f> UnitAmbientFirstReflection(const Scene& model,
                                                        const std::vector<PixelRecord>& records) {
  constexpr int kSide = 8;
  std::vector<ShadingMaterial> materials;
  for (const Material& m : model.materials) materials.push_back(MakeShadingMaterial(m));
  std::vector<Eigen::Vector3f> out(records.size(), Eigen::Vector3f::Zero());
  ParallelFor(0, int64_t(records.size()), [&](int64_t i) {
    const PixelRecord& r = records[i];
    if (r.region < 0 || r.region >= int(materials.size())) return;
    const ShadingMaterial& sm = materials[r.region];
    if (!IsReflective(sm.model)) return;
    BrdfParams params = sm.params;
    params.rho_d = r.albedo.cast<double>();
    const Vector3d n = r.normal.cast<double>();
    const Frame frame = IsAnisotropic(params.model) && sm.tangent
                            ? Frame::FromNormalTangent(n, *sm.tangent)
                            : Frame::FromNormal(n);
    const Vector3d wo = frame.ToLocal(r.view.cast<double>());
    Pcg32 rng(uint64_t(i) + 1, 17);
    Vector3d sum = Vector3d::Zero();
    for (int a = 0; a < kSide; ++a) {
      for (int b = 0; b < kSide; ++b) {
        const Eigen::Vector2d u((a + rng.UniformDouble()) / kSide,
                                (b + rng.UniformDouble()) / kSide);
        const BrdfSample smp = SampleBrdf(params, wo, rng.UniformDouble(), u);
        if (smp.Valid()) sum += smp.weight;
      }
    }
    const Photo& photo = model.photos[r.photo];
    const Camera& camera = model.cameras[photo.camera];
    const double k =
        photo.exposure_scale * camera.VignettingFactor(Eigen::Vector2d(r.x + 0.5, r.y + 0.5));
    out[i] = (sum * (k / (kSide * kSide))).cast<float>();
  });
  return out;
}

}  // namespace

CandidateResult AmbientLight(const CandidateContext& cx, const ResidualFitter& f) {
  CandidateResult out;
  out.effect = "ambient_light";
  // An ambient light of radiance L adds L times the unit light's response where it lands (the
  // point's ρd and what the lit room reflects of it), in shadow too. With the materials solved,
  // the first reflection only: the solve has put the ambient light's share of every surface's
  // radiance into its albedo, so the model's interreflections already carry the light the
  // ambient term sends around the room (an albedo too high by the factor k lights the others as
  // the true albedo under the lamp and the ambient light together); what the model lacks is the
  // ambient light's own reflection at the point, against which the re-solve then lowers the
  // albedos. The full response there counts the bounced light twice: on the suite's capture
  // (session 17) it fitted 0.12 for the true 0.4.
  const bool first_only = f.nuisance();
  const std::vector<Eigen::Vector3f> response =
      first_only ? UnitAmbientFirstReflection(cx.model, f.records())
                 : UnitAmbientResponse(cx.model, f.records());
  const PixelRecord* first = f.records().data();
  // The response is rendered on its own paths: no part of the simulation's noise (a plain fit
  // would credit it with the noise of the sim it partly replaces when the albedos are refitted).
  const ResidualFit fit = f.FitNoiseFreeBasis(
      3, [&](const PixelRecord& r, int c, double* b) { b[c] = response[&r - first][c]; });
  if (fit.coef.size() == 0) return out;
  const Eigen::Vector3d radiance(fit.coef[0], fit.coef[1], fit.coef[2]);
  if (!(radiance.minCoeff() > 0)) {
    out.note = "the offset that fits is negative in some channel: not an ambient light";
    return out;
  }
  FillScores(fit, &out);
  out.params = {{"radiance", {radiance.x(), radiance.y(), radiance.z()}}};
  out.where = {{"photos", PhotoFiles(cx.model)}, {"frame", "surface (smooth offset)"}};
  out.num_params = 3;
  double mean_sim = 0;
  int n = 0;
  for (const PixelRecord& r : f.records()) mean_sim += r.sim.mean(), ++n;
  out.evidence = fmt::format(
      "a smooth offset proportional to the albedo everywhere, in shadow too, that no change of "
      "the albedos explains: the photos are brighter than the model by what an ambient light of "
      "radiance {:.4g} adds ({}; mean model radiance {:.4g}), light from no declared source",
      radiance.mean(),
      first_only ? "its first reflection, the solved albedos carrying its share of the room's "
                   "interreflections"
                 : "on each surface and through the room's bounces",
      n ? mean_sim / n : 0.0);
  out.valid = true;
  out.apply = [radiance](Json* doc) {
    std::string name = "ambient";
    while ((*doc)["lights"].contains(name)) name += "_";
    (*doc)["lights"][name] = {{"type", "ambient"},
                              {"radiance", {radiance.x(), radiance.y(), radiance.z()}}};
    for (auto& [lname, list] : (*doc)["lightings"].items()) list.push_back(name);
  };
  return out;
}

}  // namespace igi
