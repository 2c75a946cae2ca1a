// igi-solve: inverse global illumination (docs/solve.md). Thin main: flags → SolveOptions,
// load the scene, solve, write DIR/scene.json, albedo maps, report.json and report.html.
#include <CLI/CLI.hpp>
#include <filesystem>
#include <iostream>

#include "recon/scene.h"
#include "solver/inverse/solve.h"
#include "solver/inverse/solve_flags.h"
#include "tools/common/cli.h"
#include "tools/common/error.h"

namespace fs = std::filesystem;

int main(int argc, char** argv) {
  CLI::App app{
      "igi-solve: recover per-region Ward parameters and albedo maps from calibrated "
      "photos (Yu et al. 1999, then a joint refinement with the path tracer)",
      "igi-solve"};
  igi::CommonFlags common;
  igi::AddCommonFlags(app, &common, true);
  std::string scene_path, out_dir;
  igi::solver::SolveFlags flags;
  app.add_option("scene", scene_path, "scene.json (materials with missing values are solved)")
      ->required();
  app.add_option("--out", out_dir, "output folder (scene.json, albedo/, report.json, report.html)")
      ->required();
  igi::solver::AddSolveFlags(app, &flags);
  return igi::RunMain(app, common, argc, argv, [&]() {
    const igi::solver::SolveOptions o =
        igi::solver::FinishSolveFlags(flags, common.threads, !common.quiet);
    igi::RejectOutputInSceneFolder(out_dir, scene_path);
    igi::recon::SceneLoadOptions lo;
    const igi::recon::Scene scene = igi::recon::LoadScene(scene_path, lo);
    const igi::solver::SolveSummary summary = igi::solver::Solve(scene, o, out_dir);
    igi::solver::WriteSolveOutputs(summary, o, out_dir);
    std::vector<std::string> failed;
    for (const igi::solver::RegionSolution& r : summary.regions) {
      if (r.status == igi::solver::RegionStatus::kUnobserved) {
        failed.push_back(igi::DescribeProblem(
            scene.file.string(), "materials." + r.name, "unknown values",
            r.RhoDFromBouncedLight()
                ? "no photo sees the region: rho_d fitted to the light it bounces onto the seen "
                  "regions (report.json bounced_light_fit), no gloss"
                : "no photo sees the region: placeholders written"));
      }
    }
    if (!common.quiet) {
      std::cout << "solved " << summary.regions.size() << " regions from " << summary.observations
                << " observations in " << summary.seconds_total << " s: paper "
                << summary.stage1_render_residual << ", refined " << summary.stage2_render_residual
                << " relative RMS; wrote " << out_dir << "\n";
    }
    if (!failed.empty()) throw igi::PartialError(failed);
    return 0;
  });
}
