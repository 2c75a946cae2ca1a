#pragma once
// Internal to igi_solver: igi-solve's memory, estimated before anything large is allocated
// (STYLE.md §8), so that the observations can be drawn to fit a budget
// (SolveOptions::memory_budget, solver/inverse/observation_draw.h) or the solve refused with one
// line.
//
// What grows with the observations is, per observation: the observation itself and the solver's
// per-observation arrays, its gathered light (a record per direct sample and per hemisphere ray,
// and the specular bounces), and on regions with a lobe the incident light in its local frame
// (stage 1's gather, then stage 2's path-traced directions). The fitted observations of a region
// with a lobe carry four times stage 2's directions, and their fit's lobe table. What does not: the
// process and the scene, the Embree scene of each lighting, the patches' gathered light, the
// report's images (at most kReportPixels per photo), and the one photo being read.

#include <vector>

#include "recon/scene.h"
#include "solver/inverse/solve_options.h"

namespace igi::solver {

struct SolveMemoryEstimate {
  double budget_bytes = 0;  // the budget it was planned against
  double fixed_bytes = 0;   // independent of the observations, the photo being read excepted
  double photo_bytes = 0;   // the largest photo while it is read, linearised and collected
  // Per observation, on a region without and with a lobe.
  double observation_bytes = 0, lobe_observation_bytes = 0;
  // Per fitted observation of a region with a lobe, on top of lobe_observation_bytes.
  double fitted_lobe_bytes = 0;
  // Bytes for `observations` observations of which `lobe` on regions with a lobe and
  // `fitted_lobe` fitted there.
  double BytesFor(double observations, double lobe, double fitted_lobe) const {
    return fixed_bytes + photo_bytes + observation_bytes * (observations - lobe) +
           lobe_observation_bytes * lobe + fitted_lobe_bytes * fitted_lobe;
  }
};

// The estimate for `scene` under `options` with `patches` patches.
SolveMemoryEstimate EstimateSolveMemory(const recon::Scene& scene, const SolveOptions& options,
                                        int patches);

// The memory budget `options` set, in bytes (memory_budget GiB, or DefaultMemoryBudgetBytes()).
double SolveMemoryBudgetBytes(const SolveOptions& options);

}  // namespace igi::solver
