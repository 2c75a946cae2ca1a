// The solver's iterations (stage 1: the paper's image-based model; stage 2: the path tracer),
// the residual renders and the albedo maps. See solver/solve.h.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <Eigen/LU>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <filesystem>

#include "solver/albedo_map.h"
#include "solver/fit_inputs.h"
#include "solver/observation_grid.h"
#include "solver/render.h"
#include "solver/solve_internal.h"
#include "solver/surface_hit.h"
#include "tools/common/parallel.h"
#include "tools/common/progress.h"

namespace igi {
namespace {

Eigen::Vector3d FaceNormalToward(const TriangleMesh& mesh, int triangle, const Eigen::Vector3d& v) {
  const Eigen::Vector3d fn = mesh.FaceNormal(triangle).cast<double>();
  return fn.dot(v) >= 0 ? fn : -fn;
}

uint64_t Mix(uint64_t a, uint64_t b) {
  uint64_t x = a * 0x9e3779b97f4a7c15ULL ^ (b + 0x632be59bd9b4e019ULL + (a << 6) + (a >> 2));
  x ^= x >> 31;
  x *= 0xbf58476d1ce4e5b9ULL;
  return x ^ (x >> 29);
}

Json ParamsJson(const MaterialState& m) {
  Json j;
  j["rho_d"] = {m.params.rho_d[0], m.params.rho_d[1], m.params.rho_d[2]};
  if (HasSpecularLobe(m.params.model)) {
    j["rho_s"] = {m.params.rho_s[0], m.params.rho_s[1], m.params.rho_s[2]};
    if (IsAnisotropic(m.params.model)) {
      j["alpha_x"] = m.params.alpha_x;
      j["alpha_y"] = m.params.alpha_y;
    } else {
      j["alpha"] = m.params.alpha;
    }
  }
  return j;
}

double RelChange(double a, double b, double floor) {
  return std::abs(a - b) / std::max(std::abs(b), floor);
}

}  // namespace

void SolverState::IncidentFromRenderer(const Scene& model, uint64_t round) {
  const auto start = std::chrono::steady_clock::now();
  std::vector<std::unique_ptr<Renderer>> renderers(scene.lightings.size());
  for (size_t l = 0; l < scene.lightings.size(); ++l) {
    if (light.lightings[l].active) renderers[l] = std::make_unique<Renderer>(model, int(l));
  }
  std::atomic<uint64_t> rays{0};
  // The joint update also needs the derivatives of each region's fitted light with respect to
  // every region's parameters (the same paths: the light itself does not change), summed over
  // the region's fit observations (JointSums). They are summed per chunk of observations (a
  // partition that depends on the count only) and the chunks added in order, so the sums do
  // not depend on the threads.
  const bool joint = IsJointUpdate(options.refine_update);
  const size_t num_regions = materials.size();
  const size_t row = num_regions * Renderer::kDerivativeKinds;
  // At most 64 chunks (each holds regions² × kinds sums), of at least 256 observations.
  const int64_t num_obs = int64_t(obs.size());
  const int64_t num_chunks = std::clamp<int64_t>((num_obs + 255) / 256, 1, 64);
  const int64_t chunk_size = (num_obs + num_chunks - 1) / num_chunks;
  std::vector<JointSums> chunk_sums(joint ? num_chunks : 0);
  const bool final_round = int(round) >= options.refine_iterations;
  Progress progress(fmt::format("igi-solve: path tracing, round {}", round), num_chunks, 2.0,
                    options.show_progress && ProgressAllowed());
  ParallelFor(
      0, num_chunks,
      [&](int64_t chunk) {
        JointSums* sums = joint ? &chunk_sums[chunk] : nullptr;
        if (sums != nullptr) sums->Resize(num_regions);
        std::vector<Eigen::Vector3d> dl, d_e(row), d_t(row);
        const int64_t end = std::min(num_obs, (chunk + 1) * chunk_size);
        for (int64_t i = chunk * chunk_size; i < end; ++i) {
          const Observation& o = obs[i];
          const int l = scene.photos[o.photo].lighting;
          const LightingState& st = light.lightings[l];
          const GatherPoint& gp = st.gather.points[light.point[i]];
          const MaterialState& m = materials[o.region];
          const bool glossy = HasSpecularLobe(m.params.model);
          const Frame frame = materials.LocalFrame(o.region, o.normal.cast<double>());
          GatherQuery q;
          q.position = o.position.cast<double>();
          q.view = o.view.cast<double>();
          q.n_geo = FaceNormalToward(scene.mesh, o.triangle, q.view);
          q.n_s = o.normal.cast<double>();
          q.lobe = glossy;
          Pcg32 rng = PixelSampleRng(Mix(options.seed, round), uint64_t(i), 0x2e7);
          // Glossy observations that the fits use get four times the rays: noise in the
          // specular term T would bias ρs low (regression dilution).
          // The last round's: more where a region has few observations (FinalRoundRays), so that
          // its written values are no noisier than a large region's.
          const int base = final_round ? FinalRoundRays(options.refine_final_rays, m.observations)
                                       : options.refine_rays;
          const int n = base * (glossy && obs.in_fit[i] ? 4 : 1);
          std::vector<IncidentLocal> inc;
          if (glossy) inc = DirectIncident(st, gp, frame, n);
          const double eps = lighting_scenes[l]->ray_epsilon;
          const bool summed = sums != nullptr && obs.in_fit[i];
          const Eigen::Vector3d wo = frame.ToLocal(q.view);
          // The lobe's weight of an incident direction (ComputeSpecularTerms' T = Σ S·W·v).
          const double ax = WidenedAlpha(m.params.AlphaX(), o.lobe_blur2);
          const double ay = WidenedAlpha(m.params.AlphaY(), o.lobe_blur2);
          auto lobe_weight = [&](const Eigen::Vector3d& wi_local) {
            const double w = SpecularWeight(m.params.model, ax, ay, m.params.ior, wo, wi_local);
            return w > 0 ? w : 0.0;
          };
          Eigen::Vector3d t = Eigen::Vector3d::Zero();
          if (summed && glossy) {
            for (const IncidentLocal& in : inc) {
              t += lobe_weight(in.Wi().cast<double>()) * in.Value().cast<double>();
            }
          }
          if (summed) {
            std::fill(d_e.begin(), d_e.end(), Eigen::Vector3d::Zero());
            std::fill(d_t.begin(), d_t.end(), Eigen::Vector3d::Zero());
          }
          Eigen::Vector3d e = Eigen::Vector3d::Zero();
          int k = 0;
          for (const WeightedDirection& d : HemisphereDirections(q, n, 0.2, rng)) {
            const Eigen::Vector3d origin = q.position + q.n_geo * eps;
            const uint64_t seed = Mix(Mix(options.seed, round), i * 4096 + k++);
            const Eigen::Vector3d li =
                summed ? renderers[l]->ReflectedRadiance(origin, d.wi, 1, seed, &dl)
                       : renderers[l]->ReflectedRadiance(origin, d.wi, 1, seed);
            e += d.weight * li;
            const Eigen::Vector3d wi_local = frame.ToLocal(d.wi);
            const double w_lobe = glossy ? lobe_weight(wi_local) : 0.0;
            if (summed) {
              for (size_t j = 0; j < row; ++j) d_e[j] += d.weight * dl[j];
              if (w_lobe > 0) {
                for (size_t j = 0; j < row; ++j) d_t[j] += (w_lobe * d.weight) * dl[j];
              }
              t += (w_lobe * d.weight) * li;
            }
            if (glossy) inc.push_back({wi_local.cast<float>(), (d.weight * li).cast<float>()});
          }
          if (summed) sums->Add(o.region, d_e, d_t, t);
          rays += k;
          light.e_direct[i] = gp.e_direct.cast<double>();
          light.e_indirect[i] = e;
          light.incident[i] = std::move(inc);
        }
        progress.Add(1);
      },
      options.num_threads);
  progress.Finish();
  light.joint_sums = JointSums();
  if (joint) {
    light.joint_sums.Resize(num_regions);
    for (const JointSums& c : chunk_sums) light.joint_sums.Add(c);
  }
  summary.seconds_rays +=
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  summary.rays += rays.load();
}

void SolverState::SmoothIrradiance() {
  const double radius =
      options.smoothing_radius_m > 0 ? options.smoothing_radius_m : summary.scene_scale_m / 96;
  if (light.smoothing_radius.size() != obs.size()) ComputeSmoothingRadii(radius);
  igi::SmoothIrradiance(obs, options.num_threads, &light);
}

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
std::vector<float> SolverState::DrawnSmoothingRadii(double radius) const {
  std::vector<float> out(obs.size(), float(radius));
  if (!obs.draw.census) return out;
  const double widest = kMostDrawWidening * radius;
  const int reach = int(std::ceil(kMostDrawWidening));
  const size_t k = size_t(kSmoothingNeighbours) - 1;
  // Cells of the radius: where `radius` holds enough (the densely drawn), one cell around.
  const ObservationGrid grid(scene, obs, std::vector<char>(materials.size(), 1), radius);
  ParallelFor(
      0, int64_t(obs.size()),
      [&](int64_t i) {
        const Observation& o = obs[i];
        const Eigen::Vector3d p = o.position.cast<double>(), n = o.normal.cast<double>();
        const int l = scene.photos[o.photo].lighting;
        std::vector<double> d2;
        auto within = [&](double r, int cells) {
          d2.clear();
          grid.ForEachNear(
              l, o.region, p,
              [&](int j) {
                if (obs[j].normal.cast<double>().dot(n) < 0.9) return;
                const double d = (obs[j].position.cast<double>() - p).squaredNorm();
                if (d <= r * r) d2.push_back(d);
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
      options.num_threads);
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
void SolverState::ComputeSmoothingRadii(double radius) {
  light.smoothing_radius = DrawnSmoothingRadii(radius);
  if (!(options.smoothing_accuracy > 0)) return;
  const double min_d = 0.5 * summary.patch_size_m;
  const TriangleMesh& mesh = scene.mesh;
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
      const double base = light.smoothing_radius[i];
      if (n <= 0) continue;
      double inv = 0;
      for (int64_t d = gp.indirect_begin; d < gp.indirect_end; ++d) {
        const IndirectSample& s = st.gather.indirect[d];
        if (s.patch < 0) continue;
        const double dist = double((patches.center[s.patch] - obs[i].position).norm());
        inv += 1.0 / std::max(dist, min_d);
      }
      const double most = curved(obs[i].triangle) ? base : 2 * base;
      const double r = inv > 0 ? options.smoothing_accuracy * n / inv : most;
      light.smoothing_radius[i] = float(std::clamp(r, 0.25 * base, most));
    }
  }
}

// Stage 2 renders the light at the current parameters p0, and a region's refit is about
// ρ̂d_r = πΣL/ΣE and ρ̂s_r ∝ 1/ΣT over its observations (E its irradiance, T its specular term).
// Had region j's parameter q (ρd, ρs or α) been scaled by (1 + Δ_jq), its observations would have
// gathered ΣE·(1 + Σ_jq G_r,jq·Δ_jq), G_r,jq = ΣD_r,jq/ΣE (D the derivative of the rendered
// irradiance with respect to ln of that scale: JointSums), and ΣT·(1 + Σ_jq H_r,jq·Δ_jq) likewise
// with the derivatives of T; the refits would be ρ̂d_r/(1 + G_r·Δ) and ρ̂s_r/(1 + H_r·Δ). The joint
// update is the fixed point (1 + Δ_u)(1 + C_u·Δ) = p̂_u/p0_u for every unknown ρd and ρs u at
// once (C_u the row G or H), per channel, by Newton's method (a few iterations of an n × n system,
// n the unknowns). α is a shape, not a level, so a region's own refit stands; its change enters
// the others' light as a known Δ. With C = 0 it is the independent refit. The new values are held
// within a factor 2 of p0. "joint_albedo": ρd only (no ρs unknown, no α change).
JointUpdate SolverState::JointParams(const std::vector<int>& regions,
                                     const std::vector<RegionFitResult>& fits) const {
  constexpr int kD = Renderer::kLnRhoD, kS = Renderer::kLnRhoS, kA = Renderer::kLnAlpha;
  const size_t num_regions = materials.size();
  const Eigen::Vector3d none = Eigen::Vector3d::Constant(NAN);
  JointUpdate out;
  out.rho_d.assign(regions.size(), none);
  out.rho_s.assign(regions.size(), none);
  out.feedback.assign(regions.size(), none);
  const JointSums& js = light.joint_sums;
  if (js.regions != num_regions) return out;
  const bool lobes = options.refine_update == "joint";
  // The unknowns (entry of `regions`, kind), and the known α changes (ln of the ratio).
  struct Unknown {
    int k;
    int kind;
  };
  std::vector<Unknown> unknowns;
  std::vector<double> ln_alpha(num_regions, 0.0);
  for (size_t k = 0; k < regions.size(); ++k) {
    const MaterialState& m = materials[regions[k]];
    const RegionFitResult& f = fits[k];
    if (!f.fitted) continue;
    if (m.unknown_rho_d && m.params.rho_d.allFinite() && f.rho_d.allFinite()) {
      unknowns.push_back({int(k), kD});
    }
    if (!lobes || !HasSpecularLobe(m.params.model) || m.no_highlight) continue;
    if (m.unknown_rho_s && m.params.rho_s.allFinite() && f.rho_s.allFinite()) {
      unknowns.push_back({int(k), kS});
    }
    if (m.unknown_alpha && m.params.AlphaX() > 0 && m.params.AlphaY() > 0 && f.alpha_x > 0) {
      BrdfParams fitted = m.params;
      fitted.alpha = f.alpha, fitted.alpha_x = f.alpha_x, fitted.alpha_y = f.alpha_y;
      const double lx = std::log(fitted.AlphaX() / m.params.AlphaX());
      const double ly = std::log(fitted.AlphaY() / m.params.AlphaY());
      if (std::isfinite(lx) && std::isfinite(ly)) ln_alpha[regions[k]] = 0.5 * (lx + ly);
    }
  }
  const int n = int(unknowns.size());
  if (n == 0) return out;
  // ΣE per fitted region over its fit observations (the fits' E: smoothed, direct included).
  std::vector<Eigen::Vector3d> sum_e(num_regions, Eigen::Vector3d::Zero());
  for (size_t i = 0; i < obs.size(); ++i) {
    if (obs.in_fit[i]) sum_e[obs[i].region] += light.e[i];
  }
  for (int c = 0; c < 3; ++c) {
    Eigen::MatrixXd g = Eigen::MatrixXd::Zero(n, n);
    Eigen::VectorXd target = Eigen::VectorXd::Ones(n), known = Eigen::VectorXd::Zero(n);
    Eigen::VectorXd albedo_feedback = Eigen::VectorXd::Zero(n);
    std::vector<bool> usable(n, false);
    for (int u = 0; u < n; ++u) {
      const int k = unknowns[u].k, r = regions[k];
      const MaterialState& m = materials[r];
      const bool diffuse = unknowns[u].kind == kD;
      const double p0 = diffuse ? m.params.rho_d[c] : m.params.rho_s[c];
      const double p1 = diffuse ? fits[k].rho_d[c] : fits[k].rho_s[c];
      const std::vector<Eigen::Vector3d>& d = diffuse ? js.d_e : js.d_t;
      const double level = diffuse ? sum_e[r][c] : js.t[r][c];
      if (!(p0 > 0) || !(level > 0)) continue;  // Δ = 0 for it; its own refit stands
      usable[u] = true;
      target[u] = p1 / p0;
      for (int v = 0; v < n; ++v) {
        g(u, v) = js.E(d, r, regions[unknowns[v].k], unknowns[v].kind)[c] / level;
        if (unknowns[v].kind == kD) albedo_feedback[u] += g(u, v);
      }
      for (size_t j = 0; j < num_regions; ++j) {
        if (ln_alpha[j] != 0) known[u] += js.E(d, r, int(j), kA)[c] / level * ln_alpha[j];
      }
    }
    Eigen::VectorXd delta = Eigen::VectorXd::Zero(n);
    bool ok = true;
    for (int it = 0; it < 10 && ok; ++it) {
      const Eigen::VectorXd gd = g * delta + known;
      Eigen::VectorXd residual(n);
      Eigen::MatrixXd jac(n, n);
      for (int u = 0; u < n; ++u) {
        residual[u] = (1 + delta[u]) * (1 + gd[u]) - target[u];
        jac.row(u) = (1 + delta[u]) * g.row(u);
        jac(u, u) += 1 + gd[u];
      }
      const Eigen::VectorXd step = jac.partialPivLu().solve(-residual);
      ok = step.allFinite();
      if (ok) delta += step;
      if (ok && step.lpNorm<Eigen::Infinity>() < 1e-12) break;
    }
    for (int u = 0; u < n; ++u) {
      if (!ok || !usable[u]) continue;
      const int k = unknowns[u].k;
      const MaterialState& m = materials[regions[k]];
      const double scale = std::clamp(1 + delta[u], 0.5, 2.0);
      if (unknowns[u].kind == kD) {
        out.rho_d[k][c] = m.params.rho_d[c] * scale;
        out.feedback[k][c] = albedo_feedback[u];
      } else {
        out.rho_s[k][c] = m.params.rho_s[c] * scale;
      }
    }
  }
  // A grey lobe stays grey: the channels' mean.
  if (options.specular_colour == "grey") {
    for (Eigen::Vector3d& v : out.rho_s) {
      if (v.allFinite()) v.setConstant(v.mean());
    }
  }
  return out;
}

double SolverState::FitAll(int stage, int iteration) {
  const auto start = std::chrono::steady_clock::now();
  HeldOutAlbedos(obs, light.e, light.t, scene.mesh, summary.texel_size_m, &materials);
  std::vector<int> regions;
  std::vector<RegionFitInput> inputs =
      FitInputs(scene, patches, obs, light, materials, stage, options.specular_colour == "grey",
                options.held_out_albedo, &regions);
  std::vector<RegionFitResult> results(regions.size());
  for (size_t k = 0; k < regions.size(); ++k) {
    Eigen::Vector3d e = Eigen::Vector3d::Zero(), l = e;
    for (const FitSample& fs : inputs[k].samples) e += fs.irradiance, l += fs.observed;
    const double n = std::max<size_t>(1, inputs[k].samples.size());
    spdlog::debug(
        "  {}: {} samples, mean irradiance ({:.4g}, {:.4g}, {:.4g}), mean radiance "
        "({:.4g}, {:.4g}, {:.4g})",
        inputs[k].name, inputs[k].samples.size(), e[0] / n, e[1] / n, e[2] / n, l[0] / n, l[1] / n,
        l[2] / n);
  }
  ParallelFor(
      0, int64_t(regions.size()), [&](int64_t k) { results[k] = FitRegion(inputs[k], {}); },
      options.num_threads, 1);
  double change = 0, num = 0, den = 0;
  SolveIteration record;
  record.stage = stage;
  record.iteration = iteration;
  const bool joint = stage == 2 && IsJointUpdate(options.refine_update);
  const JointUpdate ju = joint ? JointParams(regions, results) : JointUpdate();
  const std::vector<Eigen::Vector3d>& joint_rho = ju.rho_d;
  const std::vector<Eigen::Vector3d>& feedback = ju.feedback;
  if (stage == 2) {
    record.albedo_update = options.refine_update;
    record.albedo_step = options.refine_albedo_step;
  }
  for (size_t k = 0; k < regions.size(); ++k) {
    MaterialState& m = materials[regions[k]];
    const RegionFitResult& f = results[k];
    if (!f.fitted) continue;
    const BrdfParams old = m.params;
    if (m.unknown_rho_d) {
      // The refinement gathers all indirect light from the model, whose albedos then feed back
      // on themselves: a full step can overshoot (too bright a model darkens the next albedos);
      // --refine-albedo-step moves them only part of the way.
      const double step = stage == 2 ? options.refine_albedo_step : 1.0;
      auto blend = [&](const Eigen::Vector3d& from, const Eigen::Vector3d& to) {
        return step < 1.0 && from.allFinite() && to.allFinite()
                   ? Eigen::Vector3d(from + step * (to - from))
                   : to;
      };
      if (joint) {
        // The region's mean from the joint solution; its patches and texels keep their ratios
        // to the region's own refit (the detail), scaled to that mean.
        Eigen::Vector3d target = f.rho_d;
        for (int c = 0; c < 3; ++c) {
          if (std::isfinite(joint_rho[k][c])) target[c] = joint_rho[k][c];
        }
        m.params.rho_d = blend(old.rho_d, target);
        m.map_scale.setOnes();
        for (int c = 0; c < 3; ++c) {
          if (f.rho_d[c] > 0) m.map_scale[c] = m.params.rho_d[c] / f.rho_d[c];
        }
        for (size_t s = 0; s < m.patch_rho_d.size(); ++s) {
          m.patch_rho_d[s] = f.albedo_model == "per_patch" && f.slot_count[s] > 0
                                 ? Eigen::Vector3d(f.slot_rho_d[s].cwiseProduct(m.map_scale))
                                 : Eigen::Vector3d::Constant(NAN);
        }
      } else {
        m.params.rho_d = blend(old.rho_d, f.rho_d);
        for (size_t s = 0; s < m.patch_rho_d.size(); ++s) {
          const Eigen::Vector3d before =
              m.patch_rho_d[s].allFinite() ? m.patch_rho_d[s] : old.rho_d;
          m.patch_rho_d[s] = f.albedo_model == "per_patch" && f.slot_count[s] > 0
                                 ? blend(before, f.slot_rho_d[s])
                                 : Eigen::Vector3d::Constant(NAN);
        }
      }
      change = std::max(change, RelChange(m.params.rho_d.mean(), old.rho_d.mean(), 0.01));
    }
    if (m.unknown_rho_s) {
      m.params.rho_s = f.rho_s;
      if (joint && ju.rho_s[k].allFinite()) m.params.rho_s = ju.rho_s[k];
      change = std::max(change, RelChange(m.params.rho_s.mean(), old.rho_s.mean(), 0.01));
    }
    if (m.unknown_alpha) {
      m.params.alpha = f.alpha;
      m.params.alpha_x = f.alpha_x;
      m.params.alpha_y = f.alpha_y;
      change = std::max(change, RelChange(m.params.AlphaX(), old.AlphaX(), 0.005));
      change = std::max(change, RelChange(m.params.AlphaY(), old.AlphaY(), 0.005));
    }
    m.last_fit = f;
    if (m.unknown_rho_s) m.last_fit.rho_s = m.params.rho_s;
    if (m.unknown_rho_d) {
      m.last_fit.rho_d = m.params.rho_d;
      for (size_t s = 0; s < m.patch_rho_d.size() && s < m.last_fit.slot_rho_d.size(); ++s) {
        if (m.patch_rho_d[s].allFinite()) m.last_fit.slot_rho_d[s] = m.patch_rho_d[s];
      }
    }
    Json& pj = record.params[scene.materials[regions[k]].name];
    pj = ParamsJson(m);
    if (stage == 2 && m.unknown_rho_d) {
      pj["rho_d_independent"] = {f.rho_d[0], f.rho_d[1], f.rho_d[2]};
      if (joint && joint_rho[k].allFinite()) {
        pj["rho_d_joint"] = {joint_rho[k][0], joint_rho[k][1], joint_rho[k][2]};
        pj["feedback"] = {feedback[k][0], feedback[k][1], feedback[k][2]};
      }
    }
    if (joint && m.unknown_rho_s && ju.rho_s[k].allFinite()) {
      pj["rho_s_independent"] = {f.rho_s[0], f.rho_s[1], f.rho_s[2]};
      pj["rho_s_joint"] = {ju.rho_s[k][0], ju.rho_s[k][1], ju.rho_s[k][2]};
    }
    num += f.relative_rms * f.relative_rms * f.samples;
    den += f.samples;
  }
  record.relative_rms = den > 0 ? std::sqrt(num / den) : 0.0;
  record.max_change = change;
  summary.history.push_back(record);
  summary.seconds_fit +=
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  spdlog::info("stage {} iteration {}: relative rms {:.4f}, largest change {:.2e}", stage,
               iteration, record.relative_rms, change);
  return change;
}

void SolverState::UpdateIrradiance() {
  for (LightingState& st : light.lightings) {
    if (st.active) UpdatePatchRadiance(obs, patches, materials, light.t, options.num_threads, &st);
  }
  IncidentFromPatches(obs, patches, materials, options.num_threads, &light);
  SmoothIrradiance();
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
double SolverState::FitUnobservedAlbedos() {
  double largest = 0;
  for (size_t u = 0; u < materials.size(); ++u) {
    MaterialState& mu = materials[u];
    if (!mu.reflective || !mu.unknown_rho_d || mu.observations > 0) continue;
    const Eigen::Vector3d rho0 = mu.params.rho_d;
    const std::vector<Eigen::Vector3d> e0 = light.e;
    const Eigen::Vector3d rho1 =
        (rho0.array() < 0.5).select(rho0.array() + 0.3, rho0.array() - 0.3);
    mu.params.rho_d = rho1;
    UpdateIrradiance();
    const std::vector<Eigen::Vector3d> e1 = light.e;
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
      if (HasSpecularLobe(m.params.model)) continue;
      if (m.unknown_rho_d && !m.last_fit.fitted) continue;
      const Eigen::Vector3d radiance = o.radiance.cast<double>();
      if (!(radiance.sum() > 0)) continue;
      const Eigen::Vector3d l = kPi * radiance;
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
        scene.materials[u].name, fitted[0], fitted[1], fitted[2], sigma[0], sigma[1], sigma[2],
        ok ? "" : ": not determined, kept");
    for (int c = 0; c < 3; ++c) {
      largest = std::max(largest, RelChange(mu.params.rho_d[c], rho0[c], 0.05));
    }
    UpdateIrradiance();
  }
  return largest;
}

void SolverState::RunStage1() {
  light.t.assign(obs.size(), Eigen::Vector3d::Zero());
  summary.converged = false;
  for (int it = 1; it <= options.max_iterations; ++it) {
    UpdateIrradiance();
    const double unobserved_change = it > 1 ? FitUnobservedAlbedos() : 0.0;
    const double change = std::max(FitAll(1, it), unobserved_change);
    ComputeSpecularTerms();
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
  light.e_stage1 = light.e;
  for (size_t r = 0; r < materials.size(); ++r) {
    summary.regions[r].stage1 = summary.regions[r].stage2 = materials[r].last_fit;
    materials[r].stage1_albedo_varies = materials[r].last_fit.albedo_varies;
  }
}

}  // namespace igi
