#pragma once
// Internal to igi_solver: the refinement's light (stage 2, beyond the paper): the light arriving
// at every observation path-traced through the model as it stands, as a function of the solve's
// data.

#include <cstdint>
#include <vector>

#include "recon/scene.h"
#include "solver/inverse/fit_stage.h"
#include "solver/inverse/light_model.h"
#include "solver/inverse/material_estimate.h"

namespace igi::solver {

// What one RenderIncident cost.
struct RenderCost {
  uint64_t rays = 0;
  double seconds = 0;
};

// Per observation, the irradiance (light->e_direct from its gather point, light->e_indirect
// path-traced through `model` from --refine-rays directions about its normal, more in the last
// round: FinalRoundRays) and, on glossy regions, its incident samples (light->incident: the
// gather's direct samples and the traced directions; four times the rays for fit observations).
// For the joint update also light->joint_sums: the derivatives of each region's fitted light
// with respect to every region's parameters, summed in a partition of the observations that
// depends on their count only, so that the sums do not depend on the threads.
// `ray_epsilon` per lighting (the offset of a ray's origin from the surface); `round` seeds the
// paths (0 < round ≤ --refine-iterations).
RenderCost RenderIncident(const StageData& d, const recon::Scene& model,
                          const std::vector<double>& ray_epsilon, const MaterialEstimate& materials,
                          uint64_t round, LightModel* light);

}  // namespace igi::solver
