// The paper's stage as functions of the solve's data (solver/inverse/paper_stage.h).
#include "solver/inverse/paper_stage.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>

#include "solver/inverse/observation_grid.h"
#include "tools/common/parallel.h"

namespace igi::solver {

namespace {

// The fewest observations a smoothing radius should hold where the observations were drawn.
constexpr double kSmoothingNeighbours = 32;
// How far the draw may widen the radius: at most this factor.
constexpr double kMostDrawWidening = 4;

}  // namespace

// Per observation, where the draw thinned the observations: the distance within which
// kSmoothingNeighbours observations of its region under its lighting lie (normals within ~25°,
// itself included), held within [radius, kMostDrawWidening·radius]. `radius` itself where nothing
// was drawn.
std::vector<float> DrawnSmoothingRadii(const StageData& d, size_t num_regions, double radius) {
  const ObservationSet& obs = d.obs;
  std::vector<float> out(obs.size(), float(radius));
  if (!obs.draw.census) return out;
  const double widest = kMostDrawWidening * radius;
  const int reach = int(std::ceil(kMostDrawWidening));
  const size_t k = size_t(kSmoothingNeighbours) - 1;
  // Cells of the radius: where `radius` holds enough (the densely drawn), one cell around.
  const ObservationGrid grid(d.scene, obs, std::vector<char>(num_regions, 1), radius);
  ParallelFor(
      0, int64_t(obs.size()),
      [&](int64_t i) {
        const Observation& o = obs[i];
        const Eigen::Vector3d p = o.position.cast<double>(), n = o.normal.cast<double>();
        const int l = d.scene.photos[o.photo].lighting;
        std::vector<double> d2;
        auto within = [&](double r, int cells) {
          d2.clear();
          grid.ForEachNear(
              l, o.region, p,
              [&](int j) {
                if (obs[j].normal.cast<double>().dot(n) < 0.9) return;
                const double dist2 = (obs[j].position.cast<double>() - p).squaredNorm();
                if (dist2 <= r * r) d2.push_back(dist2);
              },
              cells);
          return d2.size() > k;
        };
        if (within(radius, 1)) return;  // `radius` holds them
        if (!within(widest, reach)) {
          out[i] = float(widest);
          return;
        }
        std::nth_element(d2.begin(), d2.begin() + k, d2.end());
        out[i] = float(std::clamp(std::sqrt(d2[k]), radius, widest));
      },
      d.options.num_threads);
  return out;
}

// Each observation's smoothing radius. Without adaptive smoothing, its drawn radius (`radius`,
// widened where the observations were drawn: DrawnSmoothingRadii). With it, Ward's
// irradiance-cache radius: the harmonic mean distance R = N / Σ 1/d_k of its N indirect rays'
// hits (a ray that meets no patch counts as infinitely far; d at least half a patch), times
// smoothing_accuracy, within [1/4, 2] × its drawn radius. It grows beyond that radius only where
// the surface is flat: the irradiance also changes with the normal, and on a curved surface (the
// observation's triangle has vertex normals more than 0.01 rad apart) a wider mean biases it
// (igi-synth's sphere: ρd −2.7 % → −3.2 % when it grew there too).
std::vector<float> SmoothingRadii(const StageData& d, const LightModel& light, size_t num_regions) {
  const double radius =
      d.options.smoothing_radius_m > 0 ? d.options.smoothing_radius_m : d.scene_scale_m / 96;
  std::vector<float> radii = DrawnSmoothingRadii(d, num_regions, radius);
  if (!(d.options.smoothing_accuracy > 0)) return radii;
  const ObservationSet& obs = d.obs;
  const double min_d = 0.5 * d.patch_size_m;
  const recon::TriangleMesh& mesh = d.scene.mesh;
  auto curved = [&](int t) {
    if (!mesh.has_normals()) return false;
    const Eigen::Vector3i& v = mesh.triangles[t];
    const Eigen::Vector3f &a = mesh.normals[v[0]], &b = mesh.normals[v[1]], &c = mesh.normals[v[2]];
    return std::min({a.dot(b), b.dot(c), a.dot(c)}) < 0.99995f;  // 0.01 rad apart
  };
  for (const LightingState& st : light.lightings) {
    if (!st.active) continue;
    for (int i : st.obs) {
      const GatherPoint& gp = st.gather.points[light.point[i]];
      const int n = int(gp.indirect_end - gp.indirect_begin);
      const double base = radii[i];
      if (n <= 0) continue;
      double inv = 0;
      for (int64_t k = gp.indirect_begin; k < gp.indirect_end; ++k) {
        const IndirectSample& s = st.gather.indirect[k];
        if (s.patch < 0) continue;
        const double dist = double((d.patches.center[s.patch] - obs[i].position).norm());
        inv += 1.0 / std::max(dist, min_d);
      }
      const double most = curved(obs[i].triangle) ? base : 2 * base;
      const double r = inv > 0 ? d.options.smoothing_accuracy * n / inv : most;
      radii[i] = float(std::clamp(r, 0.25 * base, most));
    }
  }
  return radii;
}

void SmoothStageIrradiance(const StageData& d, size_t num_regions, LightModel* light) {
  if (light->smoothing_radius.size() != d.obs.size()) {
    light->smoothing_radius = SmoothingRadii(d, *light, num_regions);
  }
  SmoothIrradiance(d.obs, d.options.num_threads, light);
}

void UpdateIrradiance(const StageData& d, const MaterialEstimate& materials, LightModel* light) {
  const int threads = d.options.num_threads;
  for (LightingState& st : light->lightings) {
    if (st.active)
      UpdatePatchRadiance(d.obs, d.patches, materials, light->t, light->t0, threads, &st);
  }
  IncidentFromPatches(d.obs, d.patches, materials, threads, light);
  SmoothStageIrradiance(d, materials.size(), light);
}

void UpdateSpecularTerms(const StageData& d, const MaterialEstimate& materials, LightModel* light) {
  light->t = SpecularTerms(d.obs, materials, light->incident, d.options.num_threads, &light->t0);
}

// A region that no photo sees still lights the ones they show: its patches send ρd·E/π, and the
// observations' irradiance is linear in its ρd (per channel; through the patches' radiance, the
// gather's weights and the smoothing, all linear). From the current ρ0 and one evaluation at ρ1
// each observation's E = a + b·ρ. The evidence: the seen regions without a specular lobe (a
// glossy region's reflection of the unseen one would also change with ρ), each with one albedo
// (or its given one) even where the fit gives it one per patch: with a wrong ρ the bounced
// light's pattern is what makes a plain wall look textured (igi-diagnose's solves, every pixel,
// found every wall per-patch with the ceiling at 0.5). With each region's ρd profiled out (closed
// form, ρd = πΣLE/ΣE²) and its own residual variance (a textured region's large residual makes it
// count for little), −2 × the log-likelihood Σ_r n_r·log RSS_r(ρ) is a function of ρ alone,
// scanned over [0.02, 0.98]: the spatial pattern of
// a region's bounced light differs from its direct light's, which is what fixes ρ. The fit is
// kept when its minimum lies inside the range and its uncertainty (from the curvature) is under
// 10 % of the value in every channel; otherwise the region keeps its placeholder.
double FitUnobservedAlbedos(const StageData& d, MaterialEstimate* estimate, LightModel* light) {
  const ObservationSet& obs = d.obs;
  MaterialEstimate& materials = *estimate;
  double largest = 0;
  for (size_t u = 0; u < materials.size(); ++u) {
    MaterialState& mu = materials[u];
    if (!mu.reflective || !mu.unknown_rho_d || mu.observations > 0) continue;
    const Eigen::Vector3d rho0 = mu.params.rho_d;
    const std::vector<Eigen::Vector3d> e0 = light->e;
    const Eigen::Vector3d rho1 =
        (rho0.array() < 0.5).select(rho0.array() + 0.3, rho0.array() - 0.3);
    mu.params.rho_d = rho1;
    UpdateIrradiance(d, materials, light);
    const std::vector<Eigen::Vector3d> e1 = light->e;
    // Evidence: per region, the sums of its observations' L² , L·a, L·b, a², a·b, b².
    struct Sums {
      Eigen::Vector3d ll = Eigen::Vector3d::Zero(), la = ll, lb = ll, aa = ll, ab = ll, bb = ll;
      int n = 0;
    };
    std::vector<Sums> sums(materials.size());
    for (size_t i = 0; i < obs.size(); ++i) {
      const Observation& o = obs[i];
      const MaterialState& m = materials[o.region];
      if (!m.reflective || m.observations == 0 || m.known_map) continue;
      if (recon::HasSpecularLobe(m.params.model)) continue;
      if (m.unknown_rho_d && !m.last_fit.fitted) continue;
      const Eigen::Vector3d radiance = o.radiance.cast<double>();
      if (!(radiance.sum() > 0)) continue;
      const Eigen::Vector3d l = render::kPi * radiance;
      const Eigen::Vector3d b = (e1[i] - e0[i]).cwiseQuotient(rho1 - rho0);
      const Eigen::Vector3d a = e0[i] - b.cwiseProduct(rho0);
      if (!l.allFinite() || !a.allFinite() || !b.allFinite()) continue;
      // A region whose ρd is given: its residual l − ρd·E is linear in ρ, ρd folded in.
      const Eigen::Vector3d k = m.unknown_rho_d ? Eigen::Vector3d::Ones() : m.params.rho_d;
      Sums& s = sums[o.region];
      s.ll += l.cwiseProduct(l);
      s.la += l.cwiseProduct(k.cwiseProduct(a));
      s.lb += l.cwiseProduct(k.cwiseProduct(b));
      s.aa += (k.cwiseProduct(a)).cwiseProduct(k.cwiseProduct(a));
      s.ab += (k.cwiseProduct(a)).cwiseProduct(k.cwiseProduct(b));
      s.bb += (k.cwiseProduct(b)).cwiseProduct(k.cwiseProduct(b));
      ++s.n;
    }
    int n = 0, regions = 0;
    for (size_t r = 0; r < sums.size(); ++r) {
      n += sums[r].n;
      regions += sums[r].n > 0 && materials[r].unknown_rho_d;
    }
    // −2 × the profile log-likelihood, each region with its own residual variance: regions whose
    // model fits worse (an unmodelled texture) count for less.
    auto cost = [&](int c, double rho) {
      double total = 0;
      for (size_t r = 0; r < sums.size(); ++r) {
        const Sums& s = sums[r];
        if (s.n == 0) continue;
        const double le = s.la[c] + rho * s.lb[c];
        const double ee = s.aa[c] + 2 * rho * s.ab[c] + rho * rho * s.bb[c];
        const double rss = materials[r].unknown_rho_d ? (ee > 0 ? s.ll[c] - le * le / ee : s.ll[c])
                                                      : s.ll[c] - 2 * le + ee;
        total += s.n * std::log(std::max(rss, 1e-12 * s.ll[c]));
      }
      return total;
    };
    Eigen::Vector3d fitted = rho0, sigma = Eigen::Vector3d::Constant(NAN);
    bool ok = n > 50 * (regions + 1);
    for (int c = 0; c < 3 && n > 0; ++c) {
      constexpr double lo = 0.02, hi = 0.98, step = 0.001;
      double best = lo, best_cost = cost(c, lo);
      for (double rho = lo + step; rho <= hi + 1e-9; rho += step) {
        const double v = cost(c, rho);
        if (v < best_cost) best = rho, best_cost = v;
      }
      const double h = 0.01;
      const double curvature = (cost(c, best + h) - 2 * best_cost + cost(c, best - h)) / (h * h);
      sigma[c] = curvature > 0 ? std::sqrt(2 / curvature) / best : NAN;
      ok = ok && best > lo + step && best < hi - step && std::isfinite(sigma[c]) && sigma[c] < 0.1;
      fitted[c] = best;
    }
    mu.params.rho_d = ok ? fitted : rho0;
    mu.bounce_fit_sigma = ok ? sigma : Eigen::Vector3d::Constant(NAN);
    spdlog::info(
        "region {} (no photo sees it): rho_d from the light it bounces {:.3f} {:.3f} {:.3f} "
        "(relative sigma {:.3f} {:.3f} {:.3f}){}",
        d.scene.materials[u].name, fitted[0], fitted[1], fitted[2], sigma[0], sigma[1], sigma[2],
        ok ? "" : ": not determined, kept");
    for (int c = 0; c < 3; ++c) {
      largest = std::max(largest, RelativeChange(mu.params.rho_d[c], rho0[c], 0.05));
    }
    UpdateIrradiance(d, materials, light);
  }
  return largest;
}

void RunPaperStage(const StageData& d, MaterialEstimate* estimate, LightModel* light,
                   SolveSummary* out) {
  const SolveOptions& options = d.options;
  MaterialEstimate& materials = *estimate;
  SolveSummary& summary = *out;
  light->t.assign(d.obs.size(), Eigen::Vector3d::Zero());
  light->t0.assign(d.obs.size(), Eigen::Vector3d::Zero());
  summary.converged = false;
  for (int it = 1; it <= options.max_iterations; ++it) {
    UpdateIrradiance(d, materials, light);
    const double unobserved_change = it > 1 ? FitUnobservedAlbedos(d, estimate, light) : 0.0;
    const double change = std::max(FitRegions(d, *light, 1, it, estimate, out), unobserved_change);
    UpdateSpecularTerms(d, materials, light);
    summary.stage1_iterations = it;
    if (it > 1 && change < options.tolerance) {
      summary.converged = true;
      summary.message =
          fmt::format("converged: largest relative change {:.2e} < {}", change, options.tolerance);
      break;
    }
  }
  if (!summary.converged) {
    summary.message = fmt::format(
        "not converged after {} iterations (largest relative change "
        "{:.2e}, tolerance {})",
        options.max_iterations, summary.history.back().max_change, options.tolerance);
    spdlog::warn(
        "the paper's stage {}: its parameters are written as they stand (report.json "
        "converged false)",
        summary.message);
  }
  summary.stage1_model_residual = summary.history.empty() ? 0 : summary.history.back().relative_rms;
  light->e_stage1 = light->e;
  for (size_t r = 0; r < materials.size(); ++r) {
    summary.regions[r].stage1 = summary.regions[r].stage2 = materials[r].last_fit;
    materials[r].stage1_albedo_varies = materials[r].last_fit.albedo_varies;
  }
}

}  // namespace igi::solver
