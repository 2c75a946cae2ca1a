// One fit of every region with an unknown, and stage 2's joint update (solver/inverse/fit_stage.h).
#include "solver/inverse/fit_stage.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <Eigen/LU>
#include <chrono>

#include "solver/inverse/fit_inputs.h"
#include "tools/common/parallel.h"

namespace igi::solver {
namespace {

Json ParamsJson(const MaterialState& m) {
  Json j;
  j["rho_d"] = {m.params.rho_d[0], m.params.rho_d[1], m.params.rho_d[2]};
  if (recon::HasSigma(m.params.diffuse)) j["sigma"] = m.params.sigma;
  if (recon::HasSpecularLobe(m.params.model)) {
    j["rho_s"] = {m.params.rho_s[0], m.params.rho_s[1], m.params.rho_s[2]};
    if (recon::IsAnisotropic(m.params.model)) {
      j["alpha_x"] = m.params.alpha_x;
      j["alpha_y"] = m.params.alpha_y;
    } else {
      j["alpha"] = m.params.alpha;
    }
  }
  return j;
}

}  // namespace

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
JointUpdate JointParams(const StageData& d, const MaterialEstimate& materials,
                        const LightModel& light, const std::vector<int>& regions,
                        const std::vector<RegionFitResult>& fits) {
  const ObservationSet& obs = d.obs;
  constexpr int kD = render::Renderer::kLnRhoD, kS = render::Renderer::kLnRhoS,
                kA = render::Renderer::kLnAlpha;
  const size_t num_regions = materials.size();
  const Eigen::Vector3d none = Eigen::Vector3d::Constant(NAN);
  JointUpdate out;
  out.rho_d.assign(regions.size(), none);
  out.rho_s.assign(regions.size(), none);
  out.feedback.assign(regions.size(), none);
  const JointSums& js = light.joint_sums;
  if (js.regions != num_regions) return out;
  const bool lobes = d.options.refine_update == RefineUpdate::kJoint;
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
    if (!lobes || !recon::HasSpecularLobe(m.params.model) || m.no_highlight) continue;
    if (m.unknown_rho_s && m.params.rho_s.allFinite() && f.rho_s.allFinite()) {
      unknowns.push_back({int(k), kS});
    }
    if (m.unknown_alpha && m.params.AlphaX() > 0 && m.params.AlphaY() > 0 && f.alpha_x > 0) {
      render::BrdfParams fitted = m.params;
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
      const std::vector<Eigen::Vector3d>& derivative = diffuse ? js.d_e : js.d_t;
      const double level = diffuse ? sum_e[r][c] : js.t[r][c];
      if (!(p0 > 0) || !(level > 0)) continue;  // Δ = 0 for it; its own refit stands
      usable[u] = true;
      target[u] = p1 / p0;
      for (int v = 0; v < n; ++v) {
        g(u, v) = js.E(derivative, r, regions[unknowns[v].k], unknowns[v].kind)[c] / level;
        if (unknowns[v].kind == kD) albedo_feedback[u] += g(u, v);
      }
      for (size_t j = 0; j < num_regions; ++j) {
        if (ln_alpha[j] != 0) known[u] += js.E(derivative, r, int(j), kA)[c] / level * ln_alpha[j];
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
  if (d.options.specular_colour == SpecularColour::kGrey) {
    for (Eigen::Vector3d& v : out.rho_s) {
      if (v.allFinite()) v.setConstant(v.mean());
    }
  }
  return out;
}

double FitRegions(const StageData& d, const LightModel& light, int stage, int iteration,
                  MaterialEstimate* estimate, SolveSummary* summary) {
  const ObservationSet& obs = d.obs;
  const SolveOptions& options = d.options;
  MaterialEstimate& materials = *estimate;
  const auto start = std::chrono::steady_clock::now();
  HeldOutAlbedos(obs, light.e, light.t, light.t0, d.scene.mesh, d.texel_size_m, &materials);
  std::vector<int> regions;
  std::vector<RegionFitInput> inputs =
      FitInputs(d.scene, d.patches, obs, light, materials, stage, options, &regions);
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
  const JointUpdate ju = joint ? JointParams(d, materials, light, regions, results) : JointUpdate();
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
    const render::BrdfParams old = m.params;
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
          m.patch_rho_d[s] = f.albedo_model == AlbedoModel::kPerPatch && f.slot_count[s] > 0
                                 ? Eigen::Vector3d(f.slot_rho_d[s].cwiseProduct(m.map_scale))
                                 : Eigen::Vector3d::Constant(NAN);
        }
      } else {
        m.params.rho_d = blend(old.rho_d, f.rho_d);
        for (size_t s = 0; s < m.patch_rho_d.size(); ++s) {
          const Eigen::Vector3d before =
              m.patch_rho_d[s].allFinite() ? m.patch_rho_d[s] : old.rho_d;
          m.patch_rho_d[s] = f.albedo_model == AlbedoModel::kPerPatch && f.slot_count[s] > 0
                                 ? blend(before, f.slot_rho_d[s])
                                 : Eigen::Vector3d::Constant(NAN);
        }
      }
      change = std::max(change, RelativeChange(m.params.rho_d.mean(), old.rho_d.mean(), 0.01));
    }
    if (m.unknown_rho_s) {
      m.params.rho_s = f.rho_s;
      if (joint && ju.rho_s[k].allFinite()) m.params.rho_s = ju.rho_s[k];
      change = std::max(change, RelativeChange(m.params.rho_s.mean(), old.rho_s.mean(), 0.01));
    }
    if (m.unknown_alpha) {
      m.params.alpha = f.alpha;
      m.params.alpha_x = f.alpha_x;
      m.params.alpha_y = f.alpha_y;
      change = std::max(change, RelativeChange(m.params.AlphaX(), old.AlphaX(), 0.005));
      change = std::max(change, RelativeChange(m.params.AlphaY(), old.AlphaY(), 0.005));
    }
    if (m.unknown_sigma) {
      m.params.sigma = f.sigma;
      change = std::max(change, RelativeChange(m.params.sigma, old.sigma, 0.05));
    }
    m.last_fit = f;
    if (m.unknown_rho_s) m.last_fit.rho_s = m.params.rho_s;
    if (m.unknown_rho_d) {
      m.last_fit.rho_d = m.params.rho_d;
      for (size_t s = 0; s < m.patch_rho_d.size() && s < m.last_fit.slot_rho_d.size(); ++s) {
        if (m.patch_rho_d[s].allFinite()) m.last_fit.slot_rho_d[s] = m.patch_rho_d[s];
      }
    }
    Json& pj = record.params[d.scene.materials[regions[k]].name];
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
  summary->history.push_back(record);
  summary->seconds_fit +=
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  spdlog::info("stage {} iteration {}: relative rms {:.4f}, largest change {:.2e}", stage,
               iteration, record.relative_rms, change);
  return change;
}

}  // namespace igi::solver
