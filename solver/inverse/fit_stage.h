#pragma once
// Internal to igi_solver: one fit of every region with an unknown, as a function of the solve's
// data — the observation set, the light model at the observations and the material estimate —
// and the options. Stage 1 (the paper's image-based model) and stage 2 (the path tracer's
// refinement) both call it; stage 2's joint update is JointParams.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <vector>

#include "recon/scene.h"
#include "solver/inverse/light_model.h"
#include "solver/inverse/material_estimate.h"
#include "solver/inverse/observation_set.h"
#include "solver/inverse/patches.h"
#include "solver/inverse/region_fit.h"
#include "solver/inverse/solve.h"
#include "solver/inverse/solve_options.h"

namespace igi::solver {

// What the stages read besides the estimate they update; every reference outlives the call.
struct StageData {
  const recon::Scene& scene;
  const SolveOptions& options;
  const ObservationSet& obs;
  const PatchSet& patches;
  double scene_scale_m = 0;  // the scene's length scale (SolveSummary::scene_scale_m)
  double patch_size_m = 0;   // the patches' edge (SolveSummary::patch_size_m)
  double texel_size_m = 0;   // the held-out albedos' texel (SolveSummary::texel_size_m)
};

// |a − b| / max(|b|, floor): a parameter's relative change, with a floor for values near 0.
inline double RelativeChange(double a, double b, double floor) {
  return std::abs(a - b) / std::max(std::abs(b), floor);
}

// The joint update's result per fitted region (NaN where the region's own refit stands):
// its albedo, its ρs, and per channel the relative change of its fitted light per unit relative
// change of every region's albedo ("feedback").
struct JointUpdate {
  std::vector<Eigen::Vector3d> rho_d, rho_s, feedback;
};

// The joint update of `regions` (ascending) from their own refits `fits` (one each): the
// fixed point p_r = fit_r(light(p)) of every unknown ρd (and, for --refine-update joint, ρs) with
// the light linearised by light.joint_sums, per channel, by Newton's method; each value held
// within a factor 2 of the current one. Empty results (all NaN) without joint sums.
JointUpdate JointParams(const StageData& d, const MaterialEstimate& materials,
                        const LightModel& light, const std::vector<int>& regions,
                        const std::vector<RegionFitResult>& fits);

// Fits every region with an unknown that some photo sees (solver/inverse/region_fit.h) from its fit
// samples (FitInputs) and writes the new values into *materials: stage 1 takes each region's
// refit; stage 2 moves the albedos --refine-albedo-step of the way to the refit (joint: to
// JointParams's). Appends the iteration's record to summary->history and its time to
// summary->seconds_fit. Returns the largest relative parameter change.
double FitRegions(const StageData& d, const LightModel& light, int stage, int iteration,
                  MaterialEstimate* materials, SolveSummary* summary);

}  // namespace igi::solver
