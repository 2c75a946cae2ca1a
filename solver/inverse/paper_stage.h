#pragma once
// Internal to igi_solver: the paper's stage (Yu et al. 1999: the light at each observation from
// the photographed patches, and the fits, alternated) as functions of the solve's data — the
// observation set, the light model (its gather already done: solver/inverse/light_model.h) and the
// material estimate — and the options. The smoothing radii and the irradiance update are also
// the refinement's (solver/inverse/refine_stage.h).

#include <vector>

#include "solver/inverse/fit_stage.h"
#include "solver/inverse/light_model.h"
#include "solver/inverse/material_estimate.h"
#include "solver/inverse/solve.h"

namespace igi::solver {

// Per observation, where the draw thinned the observations (obs.draw.census): the distance
// within which 32 observations of its region under its lighting lie (normals within ~25°, itself
// included), held within [radius, 4·radius]. `radius` itself where nothing was drawn.
std::vector<float> DrawnSmoothingRadii(const StageData& d, size_t num_regions, double radius);

// Each observation's smoothing radius: its drawn radius (DrawnSmoothingRadii of the options' or
// the automatic radius, the scene's length scale / 96) and, with --smoothing-accuracy > 0, Ward's
// irradiance-cache radius from stage 1's gather (the harmonic mean distance of its indirect
// rays' hits times the accuracy) within [1/4, 2] × the drawn radius (at most 1 × on a curved
// triangle).
std::vector<float> SmoothingRadii(const StageData& d, const LightModel& light, size_t num_regions);

// light->e from light->e_direct and light->e_indirect (SmoothIrradiance), the smoothing radii
// computed first where there are none yet.
void SmoothStageIrradiance(const StageData& d, size_t num_regions, LightModel* light);

// Every active lighting's patch radiances from the current materials and specular terms, the
// observations' indirect irradiance gathered from them, and its smoothing (light->e).
void UpdateIrradiance(const StageData& d, const MaterialEstimate& materials, LightModel* light);

// light->t and light->t0 at the current materials (SpecularTerms in solver/inverse/light_model.h).
void UpdateSpecularTerms(const StageData& d, const MaterialEstimate& materials, LightModel* light);

// The ρd of the reflective regions of unknown ρd that no photo sees, from the light they bounce
// onto the regions the photos show: each a profile-likelihood scan over [0.02, 0.98], kept when
// its minimum is inside and its relative uncertainty under 10 % in every channel (else the
// region keeps its value). Leaves light->e at the new values. Returns the largest relative change.
double FitUnobservedAlbedos(const StageData& d, MaterialEstimate* materials, LightModel* light);

// The paper's stage: up to --max-iterations rounds of UpdateIrradiance, FitUnobservedAlbedos
// (from the second), FitRegions(stage 1) and UpdateSpecularTerms, until the largest relative
// change is under --tolerance. Writes summary's stage-1 fields (iterations, converged, message,
// model residual, each region's stage1 and stage2 fit), light->e_stage1 and each region's
// stage1_albedo_varies.
void RunPaperStage(const StageData& d, MaterialEstimate* materials, LightModel* light,
                   SolveSummary* summary);

}  // namespace igi::solver
