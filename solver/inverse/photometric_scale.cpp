#include "solver/inverse/photometric_scale.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <tuple>

#include "solver/inverse/solve_internal.h"
#include "solver/render/sampling.h"
#include "tools/common/error.h"

namespace igi::solver {
namespace {

using ScaleSample = PhotoScaleSample;

bool IsReference(const MaterialState& m) {
  if (!m.reflective || m.NeedsFit() || m.observations == 0) return false;
  return !recon::HasSpecularLobe(m.params.model) || !(m.params.rho_s.maxCoeff() > 0);
}

// k over `samples` (P − b = k·a) as the ratio of sums Σ(P − b)/Σa, with its standard error
// from the groups' residual sums (a group's samples share one surface patch: their errors are
// not independent); `keep` selects groups. Not least squares: `a` carries the reference's albedo
// looked up at each sample, and where the reference is textured a small misregistration makes
// that lookup noisy; least squares with a noisy regressor shrinks k toward 0 (measured on
// igi-run --demo's textured matte box: -15 %), the ratio of sums does not.
std::pair<double, double> FitScale(const std::vector<ScaleSample>& samples,
                                   const std::vector<char>& keep) {
  double num = 0, den = 0;
  int n = 0;
  for (const ScaleSample& s : samples) {
    if (!keep[s.group]) continue;
    num += s.p - s.b;
    den += s.a;
    ++n;
  }
  if (!(den > 0) || n < 2) return {std::nan(""), 0.0};
  const double k = num / den;
  std::vector<double> group_residual(keep.size(), 0.0);
  for (const ScaleSample& s : samples) {
    if (keep[s.group]) group_residual[s.group] += s.p - s.b - k * s.a;
  }
  double rss = 0;
  int groups = 0;
  for (size_t g = 0; g < keep.size(); ++g) {
    if (keep[g] && group_residual[g] != 0) rss += group_residual[g] * group_residual[g], ++groups;
  }
  if (groups < 2) return {k, 0.0};
  return {k, std::sqrt(rss * groups / (groups - 1)) / den};
}

}  // namespace

// k with outlying patches left out: each patch's own ratio of sums k_g, and patches whose k_g is
// beyond 4 robust standard deviations (weighted by their Σa) of the others' are dropped; counts
// the samples dropped. Patches, not samples: on a textured reference the albedo is looked up at
// one point (and a little off it where the registration is), while the photo's pixel averages
// the texture over its footprint; the lookup is right on average but its errors are skewed where
// the texture has features finer than a pixel (small dark grains on a light ground: mostly a
// little too light, now and then far too dark), and rejecting single samples by their residual
// removed only one tail and biased k (igi-run --demo's matte box: −3.4 %, with 1.5 % of the
// samples dropped, every one of them a photo brighter than its model, mostly on the darkest
// lookups; on the truth's poses at 160 × 120 nothing was dropped). Within a patch these errors
// average out, while what the model gets wrong over a whole patch (a shadow
// misplaced, a reflection off a neighbour) is still rejected. Only patches of at least
// kMinGroupSamples samples are judged: fewer do not average the grains out (igi-synth's
// 160 × 120 photos put one or two observations on a patch of its textured box, and judging those
// moved k by 4 % on the truth's poses); their weight in the sums is small.
std::pair<double, double> RobustPhotoScale(const std::vector<PhotoScaleSample>& samples,
                                           int* rejected) {
  constexpr int kMinGroupSamples = 24;  // 8 observations × 3 channels
  int num_groups = 0;
  for (const ScaleSample& s : samples) num_groups = std::max(num_groups, s.group + 1);
  std::vector<char> keep(num_groups, 1);
  auto [k, sigma] = FitScale(samples, keep);
  *rejected = 0;
  if (!std::isfinite(k)) return {k, sigma};
  std::vector<double> num(num_groups, 0.0), den(num_groups, 0.0);
  std::vector<int> count(num_groups, 0);
  for (const ScaleSample& s : samples) {
    num[s.group] += s.p - s.b, den[s.group] += s.a, ++count[s.group];
  }
  auto judged = [&](int g) { return count[g] >= kMinGroupSamples && den[g] > 0; };
  // Weighted median absolute deviation of the judged groups' k_g − k (weights Σa).
  std::vector<std::pair<double, double>> dev;  // (|k_g − k|, weight)
  double total = 0;
  for (int g = 0; g < num_groups; ++g) {
    if (!judged(g)) continue;
    dev.emplace_back(std::abs(num[g] / den[g] - k), den[g]);
    total += den[g];
  }
  if (dev.size() < 3) return {k, sigma};
  std::sort(dev.begin(), dev.end());
  double acc = 0, mad = dev.back().first;
  for (const auto& [d, w] : dev) {
    acc += w;
    if (acc >= 0.5 * total) {
      mad = d;
      break;
    }
  }
  const double limit = 4 * 1.4826 * mad;
  for (int g = 0; g < num_groups; ++g) {
    if (judged(g) && std::abs(num[g] / den[g] - k) > limit) keep[g] = 0;
  }
  for (const ScaleSample& s : samples) *rejected += keep[s.group] ? 0 : 1;
  return FitScale(samples, keep);
}

namespace {

// The reference samples of the current gathering: per observation and channel of a reference
// region with direct light on it.
std::vector<ScaleSample> ReferenceSamples(const SolverState& s, int channel, double* direct_share) {
  std::vector<ScaleSample> out;
  double share = 0;
  for (size_t i = 0; i < s.obs.size(); ++i) {
    const Observation& o = s.obs[i];
    if (!IsReference(s.materials[o.region])) continue;
    const Eigen::Vector3d rho = s.materials.KnownAlbedo(s.scene.mesh, o);
    const double e_direct = s.light.e_direct[i][channel];
    const double e_indirect = s.light.e[i][channel] - e_direct;
    if (!(rho[channel] > 0) || !(e_direct > 0)) continue;
    out.push_back({o.radiance[channel], rho[channel] / render::kPi * e_direct,
                   rho[channel] / render::kPi * e_indirect, o.patch});
    share += e_direct / std::max(1e-300, e_direct + e_indirect);
  }
  if (direct_share && !out.empty()) *direct_share = share / out.size();
  return out;
}

void DivideObservedRadiance(SolverState* s, double k) {
  for (Observation& o : s->obs) o.radiance = (o.radiance.cast<double>() / k).cast<float>();
}

}  // namespace

std::vector<std::string> PhotoScaleReferenceRegions(const SolverState& s) {
  std::vector<std::string> names;
  for (size_t r = 0; r < s.materials.size(); ++r) {
    if (IsReference(s.materials[r])) names.push_back(s.scene.materials[r].name);
  }
  if (names.empty()) {
    throw InputError(DescribeProblem(
        s.scene.file.string(), "materials", "no observed region of known diffuse reflectance",
        "--photo-scale solve needs a reference: a region some photo sees whose rho_d is given "
        "and that has no specular lobe (or rho_s 0)"));
  }
  return names;
}

namespace {

// One estimate of k from the current state (after a stage-1 run): the measured factor, its
// standard error and the per-channel factors.
struct ScaleMeasurement {
  double k = 1, sigma = 0;
  Eigen::Vector3d rgb = Eigen::Vector3d::Ones();
  int samples = 0, rejected = 0;
};

ScaleMeasurement MeasureScale(const SolverState& s, PhotoScaleEstimate* est) {
  std::vector<ScaleSample> all;
  ScaleMeasurement m;
  for (int c = 0; c < 3; ++c) {
    const std::vector<ScaleSample> ch = ReferenceSamples(s, c, &est->direct_share);
    int rejected_c = 0;
    m.rgb[c] = RobustPhotoScale(ch, &rejected_c).first;
    all.insert(all.end(), ch.begin(), ch.end());
  }
  std::tie(m.k, m.sigma) = RobustPhotoScale(all, &m.rejected);
  m.samples = int(all.size()) - m.rejected;
  if (!std::isfinite(m.k) || !(m.k > 0)) {
    throw InputError(DescribeProblem(
        s.scene.file.string(), "materials", fmt::format("{} reference samples", all.size()),
        "--photo-scale solve: the reference regions get too little direct light to measure "
        "the photos' scale"));
  }
  return m;
}

// Divides the photos by `step` and scales the fitted reflectances with them (a warm start for
// the next stage-1 run).
void ApplyScale(SolverState* s, double step) {
  DivideObservedRadiance(s, step);
  for (MaterialState& m : s->materials) {
    if (m.unknown_rho_d) {
      m.params.rho_d /= step;
      for (Eigen::Vector3d& v : m.patch_rho_d) v /= step;
    }
    if (m.unknown_rho_s) m.params.rho_s /= step;
  }
}

// Regions with an unknown albedo that no photo sees keep a placeholder, which radiates in the
// scene's units whatever the photos' scale is. In the photo-scale loop the placeholder is the
// area-weighted mean albedo of the observed regions whose albedo is solved, so that it follows
// the photos' units; then the patches' radiance and the light at the observations are redone.
void FollowPhotoUnits(SolverState* s) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double area = 0;
  std::vector<double> region_area(s->materials.size(), 0.0);
  for (size_t r = 0; r < s->materials.size(); ++r) {
    for (int q : s->materials.region_patches[r]) region_area[r] += s->patches.area[q];
    const MaterialState& m = s->materials[r];
    if (!m.reflective || !m.unknown_rho_d || m.observations == 0) continue;
    sum += region_area[r] * m.params.rho_d;
    area += region_area[r];
  }
  if (area > 0) {
    for (MaterialState& m : s->materials) {
      if (m.reflective && m.unknown_rho_d && m.observations == 0) m.params.rho_d = sum / area;
    }
  }
  UpdateIrradiance(s->Stage(), s->materials, &s->light);
}

}  // namespace

// Each round measures log k on the current photos and divides them by a step toward it. The
// measured log k responds to a step with a gain g (1 would make one step exact; it is larger
// because the unseen patches' albedos and the fits move with the photos, which makes plain
// steps overshoot and alternate): g is re-estimated from the last step and the step taken is
// log k / g.
PhotoScaleEstimate RunStage1WithPhotoScale(SolverState* s) {
  PhotoScaleEstimate est;
  est.reference_regions = PhotoScaleReferenceRegions(*s);
  constexpr int kMaxRounds = 6;
  constexpr double kTolerance = 2e-3;  // relative change of k: well under its standard error
  // The rounds run the paper's stage with at most kRoundIterations iterations (warm-started:
  // the fits follow the photos); the last one runs it in full.
  constexpr int kRoundIterations = 3;
  const int full_iterations = s->options.max_iterations;
  s->options.max_iterations = std::min(full_iterations, kRoundIterations);
  s->RunStage1();
  double gain = 1, last_log_k = 0, last_step = 0;
  for (int round = 1; round <= kMaxRounds; ++round) {
    FollowPhotoUnits(s);
    const ScaleMeasurement m = MeasureScale(*s, &est);
    const double log_k = std::log(m.k);
    if (round > 1 && std::abs(last_step) > 1e-6) {
      gain = std::clamp((last_log_k - log_k) / last_step, 0.5, 3.0);
    }
    est.rgb = m.rgb * est.scale;
    est.sigma = m.sigma / m.k * est.scale;  // relative error at the current total
    est.samples = m.samples;
    est.rejected = m.rejected;
    est.rounds = round;
    if (std::abs(log_k) < kTolerance) {  // the photos as they are now are kept
      spdlog::info("photo scale: {:.5f} ± {:.5f} after {} rounds", est.scale, est.sigma, round);
      break;
    }
    const double step = log_k / gain;
    ApplyScale(s, std::exp(step));
    est.scale *= std::exp(step);
    spdlog::info("photo scale round {}: measured x{:.5f}, gain {:.2f}, step x{:.5f} (total {:.5f})",
                 round, m.k, gain, std::exp(step), est.scale);
    last_log_k = log_k;
    last_step = step;
    s->RunStage1();
  }
  s->options.max_iterations = full_iterations;
  s->RunStage1();
  return est;
}

}  // namespace igi::solver
