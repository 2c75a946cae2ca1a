#pragma once
// Internal to igi_solver: what the region fits (solver/inverse/region_fit.h) are given, from the
// solve's data: each fitted region's knowns and hints from the material estimate, and one sample
// per fit observation with its irradiance and incident light from the light model.

#include <vector>

#include "recon/scene.h"
#include "solver/inverse/light_model.h"
#include "solver/inverse/material_estimate.h"
#include "solver/inverse/observation_set.h"
#include "solver/inverse/patches.h"
#include "solver/inverse/region_fit.h"
#include "solver/inverse/solve_options.h"

namespace igi::solver {

// The inputs of the regions with an unknown that some photo sees (their indices in *regions,
// ascending), one per region. A sample per fit observation (obs.in_fit) of such a region: its
// radiance, its irradiance (light.e), the given albedo where ρd is known, its patch's slot, its
// held-out albedo and lobe (materials.held_*, where HeldOutAlbedos filled them), its view in the
// local frame and its incident samples, read in place (`light` must outlive the inputs). Stage 2
// (`stage`) keeps stage 1's decision whether the albedo varies (with options.uniform_albedo it
// never does); a region fitted before starts its α search there. The options' specular colour and
// held-out albedo go to every input.
std::vector<RegionFitInput> FitInputs(const recon::Scene& scene, const PatchSet& patches,
                                      const ObservationSet& obs, const LightModel& light,
                                      const MaterialEstimate& materials, int stage,
                                      const SolveOptions& options, std::vector<int>* regions);

}  // namespace igi::solver
