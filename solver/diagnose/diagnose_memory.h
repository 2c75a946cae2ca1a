#pragma once
// igi-diagnose's memory, planned before anything is read or written (STYLE.md §8).
//
// What a diagnosis holds grows with the pixels it analyses (the photos at the analysis size,
// solver/diagnose/analysis_capture.h): the photos and their usable pixels, the current model's
// re-render with its Monte Carlo variance, each trial's re-render of a round (at most
// DiagnoseOptions::max_tries, held until the round is settled, plus one being rendered), the
// residual records at the pixel stride, and a step's masked copy of the photos. Its solves run
// beside all that: they get the memory budget less what the diagnosis holds, and draw their
// observations to it (solver/inverse/solve_memory.h) or refuse with one line.

#include <cstdint>

#include "recon/scene.h"
#include "solver/diagnose/diagnose_options.h"
#include "tools/common/json.h"

namespace igi::diagnose {

struct DiagnoseMemoryPlan {
  double budget_bytes = 0;        // --memory-budget (or the machine's memory less a margin)
  double pixels = 0;              // analysed pixels, all photos
  double held_bytes = 0;          // what the diagnosis holds at most beside its solves
  double solve_budget_bytes = 0;  // the budget each of its solves is given
};

// The plan for diagnosing `scene` under `options` (its photos analysed at
// options.analysis_megapixels). Throws InputError (exit 2) when what the diagnosis holds leaves
// less than a quarter of the budget to its solves: the line names the bytes it holds, the
// budget, and the flag that lowers the need.
DiagnoseMemoryPlan PlanDiagnoseMemory(const recon::Scene& scene, const DiagnoseOptions& options);

Json DiagnoseMemoryJson(const DiagnoseMemoryPlan& plan, uint64_t peak_bytes);

}  // namespace igi::diagnose
