#include "solver/diagnose/diagnose_memory.h"

#include <fmt/format.h>

#include <algorithm>

#include "solver/diagnose/analysis_capture.h"
#include "solver/diagnose/pixel_records.h"
#include "solver/inverse/solve_memory.h"
#include "tools/common/error.h"
#include "tools/common/image.h"
#include "tools/common/memory.h"

namespace igi::diagnose {
namespace {

// Bytes per analysed pixel: a photo (RGB float) and its usable pixels (float); a model's
// re-render, its variance and its raw variance (RGB float each).
constexpr double kPhotoBytes = 16, kStateBytes = 36;

}  // namespace

DiagnoseMemoryPlan PlanDiagnoseMemory(const recon::Scene& scene, const DiagnoseOptions& options) {
  DiagnoseMemoryPlan plan;
  plan.budget_bytes = solver::SolveMemoryBudgetBytes(options.solve);
  for (const recon::Photo& p : scene.photos) {
    const recon::Camera& cam = scene.cameras[p.camera];
    const int f = ReductionFactor(cam.width, cam.height, options.analysis_megapixels);
    plan.pixels += double(cam.width / f) * double(cam.height / f);
  }
  // The photos twice (a step's masked copy beside them), the current model's re-render and up
  // to max_tries trials' plus one being rendered, and the records of the current model.
  const double stride = std::max(1, options.pixel_stride);
  const double states = options.max_tries + 2;
  plan.held_bytes = plan.pixels * (2 * kPhotoBytes + states * kStateBytes +
                                   double(sizeof(PixelRecord)) / (stride * stride));
  plan.solve_budget_bytes = plan.budget_bytes - plan.held_bytes;
  if (plan.solve_budget_bytes < 0.25 * plan.budget_bytes) {
    throw InputError(DescribeProblem(
        scene.file.string(), "--memory-budget", fmt::format("{:.2f} GiB", plan.budget_bytes / kGiB),
        fmt::format("igi-diagnose holds {:.2f} GiB for {:.1f} M analysed pixels (photos, "
                    "{:.0f} model re-renders, residual records) and its solves need room "
                    "beside it: raise the budget or lower --analysis-megapixels",
                    plan.held_bytes / kGiB, plan.pixels / 1e6, states)));
  }
  return plan;
}

Json DiagnoseMemoryJson(const DiagnoseMemoryPlan& plan, uint64_t peak_bytes) {
  return {{"budget_bytes", plan.budget_bytes},
          {"analysed_pixels", plan.pixels},
          {"held_estimate_bytes", plan.held_bytes},
          {"solve_budget_bytes", plan.solve_budget_bytes},
          {"peak_bytes", double(peak_bytes)}};
}

}  // namespace igi::diagnose
