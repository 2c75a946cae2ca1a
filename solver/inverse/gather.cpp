#include "solver/inverse/gather.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <numeric>

#include "solver/render/brdf.h"
#include "solver/render/ray_scene.h"
#include "solver/render/sampling.h"
#include "tools/common/parallel.h"
#include "tools/common/progress.h"

namespace igi::solver {
namespace {

struct PointSamples {
  GatherPoint point;
  std::vector<DirectSample> direct;
  std::vector<IndirectSample> indirect;
  std::vector<SpecularBounce> bounces;
  uint64_t rays = 0;
};

// The frame in which the solver evaluates a region's lobe (SolverState::LocalFrame).
render::Frame ShadingFrame(const recon::Material& m, const Eigen::Vector3d& n) {
  if (recon::IsAnisotropic(m.brdf) && m.tangent)
    return render::Frame::FromNormalTangent(n, *m.tangent);
  return render::Frame::FromNormal(n);
}

// One direction about the mirror of wo (local frame), drawn from a mixture of a cosine lobe and
// Ward lobes of roughness lobe_alpha and lobe_alpha/4 in equal shares, with the mixture's
// density: an unbiased one-sample estimate of any lobe's integral (HemisphereDirections' mixture).
bool SampleBounce(const Eigen::Vector3d& wo, double lobe_alpha, render::Pcg32& rng,
                  Eigen::Vector3d* wi, double* weight) {
  render::BrdfParams broad, narrow;
  broad.model = narrow.model = recon::BrdfModel::kWard;
  broad.rho_s = narrow.rho_s = Eigen::Vector3d::Ones();
  broad.alpha = lobe_alpha;
  narrow.alpha = 0.25 * lobe_alpha;
  const double pick = rng.UniformDouble();
  const Eigen::Vector2d u = rng.Uniform2D();
  if (pick < 1.0 / 3) {
    *wi = render::SampleCosineHemisphere(u);
  } else {
    const render::BrdfSample bs = render::SampleBrdf(pick < 2.0 / 3 ? broad : narrow, wo, 0.5, u);
    if (!bs.Valid()) return false;
    *wi = bs.wi;
  }
  if (!(wi->z() > 0)) return false;
  const double pdf = (render::CosineHemispherePdf(wi->z()) + render::BrdfPdf(broad, wo, *wi) +
                      render::BrdfPdf(narrow, wo, *wi)) /
                     3.0;
  if (!(pdf > 0)) return false;
  *weight = wi->z() / pdf;
  return true;
}

// The specular bounce at `hit` of an indirect ray along `dir`; false where none can be drawn.
bool TraceBounce(const render::RayScene& scene, const PatchSet& patches,
                 const render::SurfaceHit& hit, const Eigen::Vector3d& dir, double lobe_alpha,
                 render::Pcg32& rng, PointSamples* out) {
  const render::Frame frame = ShadingFrame(scene.scene().materials[hit.region], hit.n_s);
  const Eigen::Vector3d wo = frame.ToLocal(-dir);
  if (!(wo.z() > 0)) return false;
  Eigen::Vector3d wi;
  double weight = 0;
  if (!SampleBounce(wo, lobe_alpha, rng, &wi, &weight)) return false;
  const Eigen::Vector3d wi_world = frame.ToWorld(wi);
  if (!(wi_world.dot(hit.n_geo) > 0)) return false;
  SpecularBounce b;
  b.wo = wo.cast<float>();
  b.wi = wi.cast<float>();
  b.weight = static_cast<float>(weight);
  ++out->rays;
  const std::optional<render::SurfaceHit> next =
      scene.TraceSurface(hit.position + hit.n_geo * scene.ray_epsilon(), wi_world);
  if (next && recon::IsReflective(scene.scene().materials[next->region].brdf)) {
    b.patch = patches.PatchOf(next->triangle, next->b1, next->b2);
  }
  out->bounces.push_back(b);
  return true;
}

// The ambient light of docs/scene-format.md (uniform radiance L from every direction, never
// occluded): its irradiance is exactly πL. It is kept as k stratified cosine-weighted directions
// about the shading normal, each carrying πL/k, so that the irradiance is exact (no light samples,
// no rays) and the glossy fits still see the directions it arrives from.
void GatherAmbient(const Eigen::Vector3d& radiance, const GatherQuery& q, int k, render::Pcg32& rng,
                   PointSamples* out) {
  const render::Frame frame = render::Frame::FromNormal(q.n_s);
  const int side = std::max(1, static_cast<int>(std::sqrt(double(k))));
  k = side * side;
  for (int s = 0; s < k; ++s) {
    const Eigen::Vector2d u(((s % side) + rng.UniformDouble()) / side,
                            ((s / side) + rng.UniformDouble()) / side);
    DirectSample d;
    d.wi = frame.ToWorld(render::SampleCosineHemisphere(u)).cast<float>();
    d.value = (radiance * (std::numbers::pi / k)).cast<float>();
    out->point.e_direct += d.value;
    out->direct.push_back(d);
  }
}

// A multiplier coprime with k: sample s's pixel stratum is (s·m) mod k, decorrelated from its
// stratum on the light.
int CoprimeStride(int k) {
  for (int m : {7, 5, 11, 13, 3}) {
    if (std::gcd(m, k) == 1) return m;
  }
  return 1;
}

// The pixel point (u, v) of sample s of k: stratified over a side×side grid for the first side²
// samples (in a shuffled order), random after.
Eigen::Vector2d PixelStratum(int s, int k, render::Pcg32& rng) {
  const int side = std::max(1, static_cast<int>(std::sqrt(double(k))));
  Eigen::Vector2d u = rng.Uniform2D();
  if (s < side * side) {
    const int cell = int((int64_t(s) * CoprimeStride(side * side)) % (side * side));
    u = Eigen::Vector2d(((cell % side) + u.x()) / side, ((cell / side) + u.y()) / side);
  }
  return u;
}

void GatherDirect(const render::RayScene& scene, const GatherQuery& q, int light_samples,
                  int footprint_samples, render::Pcg32& rng, PointSamples* out) {
  const double eps = scene.ray_epsilon();
  const bool footprint = q.footprint.has_value();
  for (int l = 0; l < scene.num_lights(); ++l) {
    const recon::LightType type = scene.light_type(l);
    if (type == recon::LightType::kAmbient) {
      GatherAmbient(scene.light(l)->radiance, q, 4 * light_samples, rng, out);
      continue;
    }
    const bool delta = type == recon::LightType::kPoint || type == recon::LightType::kSpot ||
                       type == recon::LightType::kDirectional;
    const int k = delta ? (footprint ? std::max(1, footprint_samples) : 1) : light_samples;
    const int side = std::max(1, static_cast<int>(std::sqrt(double(k))));
    for (int s = 0; s < k; ++s) {
      // Stratified over a side×side grid for the first side² samples, random after.
      Eigen::Vector3d u(rng.UniformDouble(), rng.UniformDouble(), rng.UniformDouble());
      if (s < side * side) {
        u.x() = ((s % side) + u.x()) / side;
        u.y() = ((s / side) + u.y()) / side;
      }
      Eigen::Vector3d position = q.position;
      if (footprint) {
        const Eigen::Vector2d px = PixelStratum(s, k, rng);
        position = q.FootprintPoint(px.x(), px.y());
      }
      const render::LightSample ls = scene.SampleLight(l, position, u);
      if (!(ls.pdf > 0) || !(ls.value.maxCoeff() > 0)) continue;
      const double cos_geo = ls.wi.dot(q.n_geo), cos_s = ls.wi.dot(q.n_s);
      if (!(cos_geo > 0) || !(cos_s > 0)) continue;
      const double distance = std::isfinite(ls.distance)
                                  ? ls.distance - std::max(4 * eps, 1e-6 * ls.distance)
                                  : ls.distance;
      ++out->rays;
      if (scene.Occluded(position + q.n_geo * eps, ls.wi, distance, l)) continue;
      DirectSample d;
      d.wi = ls.wi.cast<float>();
      d.value = (ls.value * (cos_s / (ls.pdf * k))).cast<float>();
      out->point.e_direct += d.value;
      out->direct.push_back(d);
    }
  }
}

}  // namespace

Eigen::Vector3f GatherDirectAt(const render::RayScene& scene, const GatherQuery& query,
                               int light_samples, int footprint_samples, render::Pcg32& rng,
                               std::vector<DirectSample>* samples) {
  PointSamples ps;
  GatherDirect(scene, query, light_samples, footprint_samples, rng, &ps);
  samples->insert(samples->end(), ps.direct.begin(), ps.direct.end());
  return ps.point.e_direct;
}

namespace {

void GatherIndirect(const render::RayScene& scene, const PatchSet& patches, const GatherQuery& q,
                    const GatherOptions& options, render::Pcg32& rng, PointSamples* out) {
  const double eps = scene.ray_epsilon();
  for (const WeightedDirection& d :
       HemisphereDirections(q, options.indirect_rays, options.lobe_alpha, rng)) {
    IndirectSample is;
    is.wi = d.wi.cast<float>();
    is.weight = static_cast<float>(d.weight);
    ++out->rays;
    const std::optional<render::SurfaceHit> hit =
        scene.TraceSurface(q.position + q.n_geo * eps, d.wi);
    if (hit && recon::IsReflective(scene.scene().materials[hit->region].brdf)) {
      is.patch = patches.PatchOf(hit->triangle, hit->b1, hit->b2);
      if (options.specular_bounces &&
          recon::HasSpecularLobe(scene.scene().materials[hit->region].brdf) &&
          TraceBounce(scene, patches, *hit, d.wi, options.lobe_alpha, rng, out)) {
        is.bounce = static_cast<int>(out->bounces.size()) - 1;  // local; rebased in Gather()
      }
    }
    out->indirect.push_back(is);
  }
}

}  // namespace

Eigen::Vector3d GatherQuery::FootprintPoint(double u, double v) const {
  if (!footprint) return position;
  const Footprint& f = *footprint;
  const Eigen::Vector3d d = f.ray00 + u * f.ray_du + v * f.ray_dv;
  const double den = n_geo.dot(d);
  if (!(std::abs(den) > 1e-12 * d.norm())) return position;
  const double t = n_geo.dot(position - f.eye) / den;
  if (!(t > 0) || !std::isfinite(t)) return position;
  return f.eye + t * d;
}

std::vector<WeightedDirection> HemisphereDirections(const GatherQuery& q, int n, double lobe_alpha,
                                                    render::Pcg32& rng) {
  // A mixture of three strategies with fixed shares (cosine, a broad Ward lobe of roughness
  // lobe_alpha and a narrow one of a quarter of it, both about the view's mirror direction);
  // each direction is weighted with the mixture's density (the balance heuristic), so the
  // estimate is unbiased for any BRDF while sharp lobes still get samples.
  std::vector<WeightedDirection> out;
  if (n <= 0) return out;
  const render::Frame frame = render::Frame::FromNormal(q.n_s);
  const bool lobe = q.lobe && q.view.squaredNorm() > 0;
  render::BrdfParams broad, narrow;
  broad.model = narrow.model = recon::BrdfModel::kWard;
  broad.rho_s = narrow.rho_s = Eigen::Vector3d::Ones();
  broad.alpha = lobe_alpha;
  narrow.alpha = 0.25 * lobe_alpha;
  const Eigen::Vector3d wo = lobe ? frame.ToLocal(q.view) : Eigen::Vector3d::UnitZ();
  const int n_cos = lobe ? std::max(1, n / 3) : n;
  const int n_broad = lobe ? (n - n_cos + 1) / 2 : 0;
  const double p_cos = double(n_cos) / n, p_broad = double(n_broad) / n;
  const double p_narrow = 1.0 - p_cos - p_broad;
  const int side = std::max(1, static_cast<int>(std::sqrt(double(n_cos))));
  out.reserve(n);
  for (int s = 0; s < n; ++s) {
    Eigen::Vector2d u = rng.Uniform2D();
    Eigen::Vector3d wi_local;
    if (s < n_cos) {
      if (s < side * side) {
        u = Eigen::Vector2d(((s % side) + u.x()) / side, ((s / side) + u.y()) / side);
      }
      wi_local = render::SampleCosineHemisphere(u);
    } else {
      const render::BrdfSample bs =
          render::SampleBrdf(s < n_cos + n_broad ? broad : narrow, wo, 0.5, u);
      if (!bs.Valid()) continue;
      wi_local = bs.wi;
    }
    if (!(wi_local.z() > 0)) continue;
    double pdf = p_cos * render::CosineHemispherePdf(wi_local.z());
    if (lobe)
      pdf += p_broad * render::BrdfPdf(broad, wo, wi_local) +
             p_narrow * render::BrdfPdf(narrow, wo, wi_local);
    const Eigen::Vector3d wi = frame.ToWorld(wi_local);
    if (!(wi.dot(q.n_geo) > 0) || !(pdf > 0)) continue;
    out.push_back({wi, wi_local.z() / (pdf * n)});
  }
  return out;
}

GatherSet Gather(const render::RayScene& scene, const PatchSet& patches,
                 const std::vector<GatherQuery>& queries, const GatherOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  const int64_t n = static_cast<int64_t>(queries.size());
  constexpr int64_t kChunk = 256;
  const int64_t chunks = (n + kChunk - 1) / kChunk;
  std::vector<std::vector<PointSamples>> results(chunks);
  Progress progress(options.progress_label, chunks, 2.0,
                    !options.progress_label.empty() && ProgressAllowed());
  ParallelFor(
      0, chunks,
      [&](int64_t c) {
        std::vector<PointSamples>& chunk = results[c];
        for (int64_t i = c * kChunk; i < std::min(n, (c + 1) * kChunk); ++i) {
          render::Pcg32 rng = render::PixelSampleRng(options.seed, uint64_t(i), 0x5eed);
          PointSamples ps;
          GatherDirect(scene, queries[i], options.light_samples, options.footprint_samples, rng,
                       &ps);
          GatherIndirect(scene, patches, queries[i], options, rng, &ps);
          chunk.push_back(std::move(ps));
        }
        progress.Add(1);
      },
      options.num_threads);
  progress.Finish();
  // The records are moved into one array each, reserved at their final size so that the peak
  // holds them once besides the chunks (growing by doubling would hold up to three copies).
  GatherSet set;
  set.points.reserve(n);
  size_t direct = 0, indirect = 0, bounces = 0;
  for (const auto& chunk : results) {
    for (const PointSamples& ps : chunk) {
      direct += ps.direct.size(), indirect += ps.indirect.size(), bounces += ps.bounces.size();
    }
  }
  set.direct.reserve(direct);
  set.indirect.reserve(indirect);
  set.bounces.reserve(bounces);
  for (auto& chunk : results) {
    for (PointSamples& ps : chunk) {
      GatherPoint p = ps.point;
      p.direct_begin = int64_t(set.direct.size());
      set.direct.insert(set.direct.end(), ps.direct.begin(), ps.direct.end());
      p.direct_end = int64_t(set.direct.size());
      p.indirect_begin = int64_t(set.indirect.size());
      const int bounce_base = static_cast<int>(set.bounces.size());
      for (IndirectSample& is : ps.indirect) {
        if (is.bounce >= 0) is.bounce += bounce_base;
      }
      set.bounces.insert(set.bounces.end(), ps.bounces.begin(), ps.bounces.end());
      set.indirect.insert(set.indirect.end(), ps.indirect.begin(), ps.indirect.end());
      p.indirect_end = int64_t(set.indirect.size());
      set.points.push_back(p);
      set.rays += ps.rays;
    }
    std::vector<PointSamples>().swap(chunk);
  }
  set.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return set;
}

}  // namespace igi::solver
