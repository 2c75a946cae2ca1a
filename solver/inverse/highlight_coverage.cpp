// Highlight coverage (solver/inverse/highlight_coverage.h): which observations see a specular
// highlight, and where a camera would need to stand for a region that none shows.
#include "solver/inverse/highlight_coverage.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <set>

#include "solver/render/ray_scene.h"
#include "solver/render/sampling.h"
#include "tools/common/error.h"
#include "tools/common/parallel.h"

namespace igi::solver {
namespace {

using Eigen::Vector3d;
constexpr double kInf = std::numeric_limits<double>::infinity();
// A suggested camera sees the points within this half-angle of its line of sight (a normal
// lens); the highlight area it is credited with counts those only.
constexpr double kHalfFieldDeg = 30.0;
// A camera closer to the surface than this fraction of the wanted distance is not proposed.
constexpr double kMinDistanceFraction = 0.1;

bool RoughnessKnown(const recon::Material& m) {
  return recon::IsAnisotropic(m.brdf) ? (m.alpha_x.has_value() && m.alpha_y.has_value())
                                      : m.alpha.has_value();
}

bool NeedsCoverage(const recon::Material& m) {
  return recon::HasSpecularLobe(m.brdf) && (!m.rho_s.has_value() || !RoughnessKnown(m));
}

double LobeAlpha(const recon::Material& m, const HighlightCoverageOptions& options) {
  if (!RoughnessKnown(m)) return options.alpha_assumed;
  const double a = recon::IsAnisotropic(m.brdf) ? std::sqrt(*m.alpha_x * *m.alpha_y) : *m.alpha;
  return a > 0 ? a : options.alpha_assumed;
}

// A direction toward one sample of a light (shadows not yet tested).
struct LightDir {
  Vector3d wi;
  double distance = 0;
  int light = -1;
};

// Samples of `light` above the surface (n_geo) at p: one for delta lights, `samples` otherwise.
void SampleLightDirs(const render::RayScene& impl, int light, const Vector3d& p,
                     const Vector3d& n_geo, int samples, render::Pcg32* rng,
                     std::vector<LightDir>* out) {
  const recon::LightType type = impl.light_type(light);
  if (type == recon::LightType::kAmbient) return;  // light from everywhere: no highlight to place
  const bool delta = type == recon::LightType::kPoint || type == recon::LightType::kSpot ||
                     type == recon::LightType::kDirectional;
  const int count = delta ? 1 : samples;
  for (int s = 0; s < count; ++s) {
    const double u0 = rng->UniformDouble(), u1 = rng->UniformDouble();
    const render::LightSample ls =
        impl.SampleLight(light, p, Vector3d(u0, u1, rng->UniformDouble()));
    if (!(ls.pdf > 0) || !(ls.value.maxCoeff() > 0) || !(ls.wi.dot(n_geo) > 0)) continue;
    out->push_back({ls.wi, ls.distance, light});
  }
}

// The shadow test of the renderer (solver/render/render.cpp): offset origin, segment stopped short
// of the light.
bool Shadowed(const render::RayScene& impl, const Vector3d& p, const Vector3d& n_geo,
              const LightDir& d) {
  const double eps = impl.ray_epsilon();
  const double distance =
      std::isfinite(d.distance) ? d.distance - std::max(4 * eps, 1e-6 * d.distance) : d.distance;
  return impl.Occluded(p + n_geo * eps, d.wi, distance, d.light);
}

// tanθh / α for light direction wi and view direction about the shading normal n; infinity
// when either direction is below the surface.
double TanRatio(const Vector3d& n, const Vector3d& wi, const Vector3d& view, double alpha) {
  if (!(n.dot(wi) > 0) || !(n.dot(view) > 0)) return kInf;
  const Vector3d h = (wi + view).normalized();
  const double c = n.dot(h);
  if (!(c > 0)) return kInf;
  return std::sqrt(std::max(0.0, 1 - c * c)) / c / alpha;
}

// The smallest tanθh / α over the unshadowed light samples seen by one observation. Samples are
// tested for shadow in order of increasing ratio, so usually one shadow ray suffices.
double ObservationMinRatio(const render::RayScene& impl, const Observation& o, double alpha,
                           const HighlightCoverageOptions& options, uint64_t index) {
  const Vector3d p = o.position.cast<double>();
  const Vector3d n = o.normal.cast<double>().normalized();
  const Vector3d v = o.view.cast<double>().normalized();
  Vector3d n_geo = impl.face_normal(o.triangle);
  if (n_geo.dot(v) < 0) n_geo = -n_geo;
  render::Pcg32 rng(options.seed, index);
  std::vector<LightDir> dirs;
  for (int l = 0; l < impl.num_lights(); ++l) {
    SampleLightDirs(impl, l, p, n_geo, options.light_samples, &rng, &dirs);
  }
  std::vector<std::pair<double, size_t>> order;
  for (size_t i = 0; i < dirs.size(); ++i) {
    const double r = TanRatio(n, dirs[i].wi, v, alpha);
    if (std::isfinite(r)) order.emplace_back(r, i);
  }
  std::sort(order.begin(), order.end());
  for (const auto& [ratio, i] : order) {
    if (!Shadowed(impl, p, n_geo, dirs[i])) return ratio;
  }
  return kInf;
}

const render::RayScene* LightingScene(const recon::Scene& scene,
                                      const std::vector<std::unique_ptr<render::RayScene>>& scenes,
                                      int photo) {
  if (photo < 0 || photo >= static_cast<int>(scene.photos.size())) return nullptr;
  const int lighting = scene.photos[photo].lighting;
  if (lighting < 0 || lighting >= static_cast<int>(scenes.size())) return nullptr;
  return scenes[lighting].get();
}

// Fills observed, highlight_pixels, observations, photos and min_tan_theta_h_over_alpha.
void AnalyseObservations(const recon::Scene& scene, const std::vector<Observation>& observations,
                         const std::vector<std::unique_ptr<render::RayScene>>& scenes,
                         const HighlightCoverageOptions& options, const std::vector<int>& slot,
                         std::vector<RegionHighlightCoverage>* coverage) {
  const int64_t count = static_cast<int64_t>(observations.size());
  std::vector<double> ratio(observations.size(), kInf);
  std::vector<char> analysed(observations.size(), 0);
  ParallelFor(
      0, count,
      [&](int64_t i) {
        const Observation& o = observations[i];
        if (o.region < 0 || o.region >= static_cast<int>(slot.size()) || slot[o.region] < 0) return;
        const render::RayScene* impl = LightingScene(scene, scenes, o.photo);
        if (impl == nullptr) return;
        if (o.triangle < 0 || o.triangle >= static_cast<int>(impl->scene().mesh.num_triangles())) {
          throw Error(fmt::format("observation {}: triangle {} out of range", i, o.triangle));
        }
        analysed[i] = 1;
        ratio[i] = ObservationMinRatio(*impl, o, (*coverage)[slot[o.region]].alpha, options,
                                       static_cast<uint64_t>(i));
      },
      0, 256);
  std::vector<std::set<int>> photos(coverage->size());
  for (int64_t i = 0; i < count; ++i) {
    if (!analysed[i]) continue;
    const int s = slot[observations[i].region];
    RegionHighlightCoverage& c = (*coverage)[s];
    ++c.observations;
    c.min_tan_theta_h_over_alpha = std::min(c.min_tan_theta_h_over_alpha, ratio[i]);
    if (ratio[i] < options.lobe_tan_factor) {
      ++c.highlight_pixels;
      photos[s].insert(observations[i].photo);
    }
  }
  for (size_t s = 0; s < coverage->size(); ++s) {
    RegionHighlightCoverage& c = (*coverage)[s];
    c.observed = c.highlight_pixels > 0;
    for (int p : photos[s]) {
      c.photos.push_back(scene.photos[p].file.lexically_relative(scene.dir).generic_string());
    }
  }
}

// ---- Suggestions for regions no photo shows. ----

struct SurfacePoint {
  Vector3d p, n, n_geo;  // position; shading and face normals of the triangle's front
};

// `count` points uniform by area over the region's triangles; `area` receives the region area.
std::vector<SurfacePoint> SampleRegion(const recon::Scene& scene, int region, int count,
                                       uint64_t seed, double* area) {
  const recon::TriangleMesh& mesh = scene.mesh;
  std::vector<int> tris;
  std::vector<double> cdf;
  double total = 0;
  for (size_t t = 0; t < mesh.num_triangles(); ++t) {
    if (mesh.triangle_region[t] != region) continue;
    total += mesh.TriangleArea(t);
    tris.push_back(static_cast<int>(t));
    cdf.push_back(total);
  }
  *area = total;
  std::vector<SurfacePoint> points;
  if (!(total > 0)) return points;
  render::Pcg32 rng(seed, 1000003u + static_cast<uint64_t>(region));
  for (int i = 0; i < count; ++i) {
    const double target = rng.UniformDouble() * total;
    size_t k = std::upper_bound(cdf.begin(), cdf.end(), target) - cdf.begin();
    k = std::min(k, cdf.size() - 1);
    const int t = tris[k];
    const Eigen::Vector3d b = render::SampleUniformTriangle(rng.Uniform2D());
    const Eigen::Vector3i& v = mesh.triangles[t];
    SurfacePoint sp;
    sp.n_geo = mesh.FaceNormal(t).cast<double>();
    sp.n = Vector3d::Zero();
    sp.p = Vector3d::Zero();
    for (int j = 0; j < 3; ++j) {
      sp.p += b[j] * mesh.positions[v[j]].cast<double>();
      sp.n += b[j] * mesh.normals[v[j]].cast<double>();
    }
    sp.n = sp.n.squaredNorm() > 0 ? sp.n.normalized() : sp.n_geo;
    points.push_back(sp);
  }
  return points;
}

// A surface point lit by one light: normals turned toward the light, unshadowed directions.
struct LitPoint {
  SurfacePoint s;
  std::vector<LightDir> dirs;
};

std::vector<LitPoint> LightRegion(const render::RayScene& impl, int light,
                                  const std::vector<SurfacePoint>& points,
                                  const HighlightCoverageOptions& options) {
  std::vector<LitPoint> lit;
  render::Pcg32 rng(options.seed, 7777u + static_cast<uint64_t>(light));
  for (const SurfacePoint& sp : points) {
    for (double side : {1.0, -1.0}) {  // surfaces reflect on both sides
      LitPoint lp{{sp.p, side * sp.n, side * sp.n_geo}, {}};
      std::vector<LightDir> dirs;
      SampleLightDirs(impl, light, lp.s.p, lp.s.n_geo, options.light_samples, &rng, &dirs);
      for (const LightDir& d : dirs) {
        if (!Shadowed(impl, lp.s.p, lp.s.n_geo, d)) lp.dirs.push_back(d);
      }
      if (lp.dirs.empty()) continue;
      lit.push_back(std::move(lp));
      break;
    }
  }
  return lit;
}

struct Bounds {
  Vector3d lo = Vector3d::Constant(kInf), hi = Vector3d::Constant(-kInf);
  void Add(const Vector3d& p) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
};

// Everything the scene holds — geometry, cameras, lights — with a margin of 5 % of its size.
Bounds SceneBounds(const recon::Scene& scene) {
  Bounds b;
  for (const Eigen::Vector3f& p : scene.mesh.positions) b.Add(p.cast<double>());
  for (const recon::Camera& c : scene.cameras) b.Add(c.CenterInWorld());
  for (const recon::Light& l : scene.lights) {
    if (l.type == recon::LightType::kPoint || l.type == recon::LightType::kSpot) b.Add(l.position);
    if (l.type == recon::LightType::kSphere) {
      b.Add(l.center - Vector3d::Constant(l.radius));
      b.Add(l.center + Vector3d::Constant(l.radius));
    }
    for (const Eigen::Vector3f& p : l.mesh.positions) b.Add(p.cast<double>());
  }
  const Vector3d margin = Vector3d::Constant(0.05 * (b.hi - b.lo).norm() + 1e-3);
  b.lo -= margin;
  b.hi += margin;
  return b;
}

// Distance along the ray from o (inside the box) to where it leaves the box.
double BoxExit(const Bounds& b, const Vector3d& o, const Vector3d& d) {
  double t = kInf;
  for (int k = 0; k < 3; ++k) {
    if (d[k] > 0) t = std::min(t, (b.hi[k] - o[k]) / d[k]);
    if (d[k] < 0) t = std::min(t, (b.lo[k] - o[k]) / d[k]);
  }
  return std::max(0.0, t);
}

// A camera centre along the mirror direction of the light at lp, `distance` away or shortened
// to stay in front of the first surface hit and inside the scene's bounds.
std::optional<Vector3d> MirrorCamera(const render::RayScene& impl, const LitPoint& lp,
                                     double distance, const Bounds& bounds) {
  Vector3d l = Vector3d::Zero();
  for (const LightDir& d : lp.dirs) l += d.wi;
  l.normalize();
  const Vector3d r = (2 * lp.s.n.dot(l) * lp.s.n - l).normalized();
  if (!(r.dot(lp.s.n_geo) > 0.05)) return std::nullopt;  // grazing or below the surface
  const Vector3d o = lp.s.p + lp.s.n_geo * impl.ray_epsilon();
  double d = std::min(distance, BoxExit(bounds, o, r));
  if (const std::optional<render::RayHit> hit = impl.Intersect(o, r, d))
    d = std::min(d, 0.9 * hit->t);
  if (!(d >= kMinDistanceFraction * distance)) return std::nullopt;
  return lp.s.p + r * d;
}

// Whether a camera at c sees lp's highlight: in front, unoccluded, inside the lobe.
bool SeesHighlight(const render::RayScene& impl, const LitPoint& lp, const Vector3d& c,
                   double alpha, double factor) {
  const Vector3d to = c - lp.s.p;
  const double dist = to.norm();
  if (!(dist > 0)) return false;
  const Vector3d v = to / dist;
  if (!(v.dot(lp.s.n_geo) > 0)) return false;
  bool inside = false;
  for (const LightDir& d : lp.dirs) inside = inside || TanRatio(lp.s.n, d.wi, v, alpha) < factor;
  if (!inside) return false;
  const double eps = impl.ray_epsilon();
  return !impl.Occluded(lp.s.p + lp.s.n_geo * eps, v, dist - std::max(4 * eps, 1e-6 * dist));
}

// Number of lit points whose highlight a camera at c looking at `target` sees in its field;
// zero when it does not see target's own highlight.
int ScoreCamera(const render::RayScene& impl, const std::vector<LitPoint>& lit, size_t target,
                const Vector3d& c, double alpha, double factor) {
  if (!SeesHighlight(impl, lit[target], c, alpha, factor)) return 0;
  const Vector3d axis = (lit[target].s.p - c).normalized();
  const double min_cos = std::cos(kHalfFieldDeg * M_PI / 180.0);
  int count = 0;
  for (const LitPoint& lp : lit) {
    if ((lp.s.p - c).normalized().dot(axis) < min_cos) continue;
    if (SeesHighlight(impl, lp, c, alpha, factor)) ++count;
  }
  return count;
}

std::string LightName(const recon::Light* light) {
  return light != nullptr ? light->name : std::string("the emitting surfaces");
}

std::string SuggestionText(const HighlightSuggestion& s, const std::string& region) {
  return fmt::format(
      "stand at ({:.2f}, {:.2f}, {:.2f}) m looking at ({:.2f}, {:.2f}, {:.2f}) to see {}'s "
      "highlight on {} (lighting {}; about {:.3g} m² of it)",
      s.position.x(), s.position.y(), s.position.z(), s.look_at.x(), s.look_at.y(), s.look_at.z(),
      s.light, region, s.lighting, s.highlight_area_m2);
}

struct SuggestContext {
  const recon::Scene* scene;
  const std::vector<SurfacePoint>* points;
  double region_area = 0;
  double distance = 0;
  Bounds bounds;
  const HighlightCoverageOptions* options;
};

// The best camera for one light of one lighting, or nullopt when no point offers one.
std::optional<HighlightSuggestion> SuggestForLight(const SuggestContext& ctx,
                                                   const render::RayScene& impl, int light,
                                                   const RegionHighlightCoverage& c) {
  const std::vector<LitPoint> lit = LightRegion(impl, light, *ctx.points, *ctx.options);
  std::vector<int> score(lit.size(), 0);
  std::vector<Vector3d> camera(lit.size(), Vector3d::Zero());
  ParallelFor(0, static_cast<int64_t>(lit.size()), [&](int64_t i) {
    const std::optional<Vector3d> cam = MirrorCamera(impl, lit[i], ctx.distance, ctx.bounds);
    if (!cam) return;
    camera[i] = *cam;
    score[i] = ScoreCamera(impl, lit, i, *cam, c.alpha, ctx.options->lobe_tan_factor);
  });
  const auto best = std::max_element(score.begin(), score.end());
  if (best == score.end() || *best == 0) return std::nullopt;
  const size_t i = best - score.begin();
  HighlightSuggestion s;
  s.lighting = ctx.scene->lightings[impl.lighting()].name;
  s.light = LightName(impl.light(light));
  s.position = camera[i];
  s.look_at = lit[i].s.p;
  s.distance_m = (s.position - s.look_at).norm();
  s.highlight_area_m2 = ctx.region_area * *best / static_cast<double>(ctx.points->size());
  s.text = SuggestionText(s, c.name);
  return s;
}

// Median distance from the cameras to the region: over the region's observations, else over
// the cameras' distances to the sampled points' centroid, else a quarter of the scene's size.
double WantedDistance(const recon::Scene& scene, const std::vector<Observation>& observations,
                      int region, const std::vector<SurfacePoint>& points, const Bounds& b) {
  std::vector<Vector3d> centres;
  for (const recon::Photo& p : scene.photos) {
    centres.push_back(p.camera >= 0 && p.camera < static_cast<int>(scene.cameras.size())
                          ? scene.cameras[p.camera].CenterInWorld()
                          : Vector3d::Constant(kInf));
  }
  std::vector<double> d;
  for (const Observation& o : observations) {
    if (o.region != region || o.photo < 0 || o.photo >= static_cast<int>(centres.size())) continue;
    const double x = (centres[o.photo] - o.position.cast<double>()).norm();
    if (std::isfinite(x)) d.push_back(x);
  }
  if (d.empty() && !points.empty()) {
    Vector3d centroid = Vector3d::Zero();
    for (const SurfacePoint& sp : points) centroid += sp.p / static_cast<double>(points.size());
    for (const recon::Camera& cam : scene.cameras)
      d.push_back((cam.CenterInWorld() - centroid).norm());
  }
  if (d.empty()) return 0.25 * (b.hi - b.lo).norm();
  std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
  return d[d.size() / 2];
}

void Suggest(const recon::Scene& scene, const std::vector<Observation>& observations,
             const std::vector<std::unique_ptr<render::RayScene>>& scenes,
             const HighlightCoverageOptions& options, RegionHighlightCoverage* c) {
  double area = 0;
  const std::vector<SurfacePoint> points =
      SampleRegion(scene, c->region, options.candidate_points, options.seed, &area);
  if (points.empty()) return;
  SuggestContext ctx{&scene, &points, area, 0, SceneBounds(scene), &options};
  ctx.distance = WantedDistance(scene, observations, c->region, points, ctx.bounds);
  for (const std::unique_ptr<render::RayScene>& impl : scenes) {
    if (impl == nullptr) continue;
    for (int l = 0; l < impl->num_lights(); ++l) {
      if (auto s = SuggestForLight(ctx, *impl, l, *c)) c->suggestions.push_back(std::move(*s));
    }
  }
  std::stable_sort(c->suggestions.begin(), c->suggestions.end(),
                   [](const HighlightSuggestion& a, const HighlightSuggestion& b) {
                     return a.highlight_area_m2 > b.highlight_area_m2;
                   });
  if (static_cast<int>(c->suggestions.size()) > options.max_suggestions) {
    c->suggestions.resize(options.max_suggestions);
  }
}

Json NumberOrNull(double x) { return std::isfinite(x) ? Json(x) : Json(nullptr); }

Json VectorJson(const Vector3d& v) { return Json::array({v.x(), v.y(), v.z()}); }

}  // namespace

void HighlightCoverageOptions::Validate() const {
  ProblemList p;
  if (!(alpha_assumed > 0) || !std::isfinite(alpha_assumed)) {
    p.Add("highlight_coverage", "alpha_assumed", fmt::format("{}", alpha_assumed), "must be > 0");
  }
  if (!(lobe_tan_factor > 0) || !std::isfinite(lobe_tan_factor)) {
    p.Add("highlight_coverage", "lobe_tan_factor", fmt::format("{}", lobe_tan_factor),
          "must be > 0");
  }
  if (light_samples < 1) {
    p.Add("highlight_coverage", "light_samples", std::to_string(light_samples), "must be >= 1");
  }
  if (candidate_points < 1) {
    p.Add("highlight_coverage", "candidate_points", std::to_string(candidate_points),
          "must be >= 1");
  }
  if (max_suggestions < 0) {
    p.Add("highlight_coverage", "max_suggestions", std::to_string(max_suggestions), "must be >= 0");
  }
  p.ThrowIfAny();
}

std::vector<RegionHighlightCoverage> AnalyseHighlightCoverage(
    const recon::Scene& scene, const std::vector<Observation>& observations,
    const std::vector<std::unique_ptr<render::RayScene>>& lighting_scenes,
    const HighlightCoverageOptions& options) {
  options.Validate();
  std::vector<RegionHighlightCoverage> coverage;
  std::vector<int> slot(scene.materials.size(), -1);
  for (size_t m = 0; m < scene.materials.size(); ++m) {
    const recon::Material& material = scene.materials[m];
    if (!NeedsCoverage(material)) continue;
    slot[m] = static_cast<int>(coverage.size());
    RegionHighlightCoverage c;
    c.region = static_cast<int>(m);
    c.name = material.name;
    c.alpha_known = RoughnessKnown(material);
    c.alpha = LobeAlpha(material, options);
    c.min_tan_theta_h_over_alpha = kInf;
    coverage.push_back(std::move(c));
  }
  if (coverage.empty()) return coverage;
  AnalyseObservations(scene, observations, lighting_scenes, options, slot, &coverage);
  for (RegionHighlightCoverage& c : coverage) {
    if (c.observed) continue;
    Suggest(scene, observations, lighting_scenes, options, &c);
    spdlog::warn(
        "no photo shows the highlight of region {} (its rho_s and alpha cannot be "
        "recovered); {}",
        c.name,
        c.suggestions.empty() ? std::string("no viewpoint found") : c.suggestions.front().text);
  }
  return coverage;
}

Json HighlightCoverageJson(const std::vector<RegionHighlightCoverage>& coverage) {
  Json out = Json::array();
  for (const RegionHighlightCoverage& c : coverage) {
    Json suggestions = Json::array();
    for (const HighlightSuggestion& s : c.suggestions) {
      suggestions.push_back({{"lighting", s.lighting},
                             {"light", s.light},
                             {"position", VectorJson(s.position)},
                             {"look_at", VectorJson(s.look_at)},
                             {"distance_m", s.distance_m},
                             {"highlight_area_m2", s.highlight_area_m2},
                             {"text", s.text}});
    }
    out.push_back({{"region", c.name},
                   {"alpha", c.alpha},
                   {"alpha_known", c.alpha_known},
                   {"observed", c.observed},
                   {"highlight_pixels", c.highlight_pixels},
                   {"observations", c.observations},
                   {"photos", c.photos},
                   {"min_tan_theta_h_over_alpha", NumberOrNull(c.min_tan_theta_h_over_alpha)},
                   {"suggestions", suggestions}});
  }
  return out;
}

}  // namespace igi::solver
