// igi-diagnose (docs/diagnose.md): find, name and model what the simulation leaves out. Thin
// main: flags → DiagnoseOptions, load the scene, diagnose, write diagnosis.json, report.html and
// the improved scene.json.
#include <CLI/CLI.hpp>
#include <filesystem>
#include <iostream>

#include "recon/scene.h"
#include "solver/diagnose/diagnose.h"
#include "solver/diagnose/diagnose_flags.h"
#include "tools/common/cli.h"
#include "tools/common/error.h"

namespace fs = std::filesystem;

int main(int argc, char** argv) {
  CLI::App app{
      "igi-diagnose: locate where the simulation and the photos differ, name the "
      "physics left out, model it, refit and keep it only if held-out pixels improve",
      "igi-diagnose"};
  igi::CommonFlags common;
  igi::AddCommonFlags(app, &common, true);
  std::string scene_path, out_dir;
  igi::diagnose::DiagnoseOptions flags;
  app.add_option("scene", scene_path, "scene.json (unknown materials are solved first)")
      ->required();
  app.add_option("--out", out_dir,
                 "output folder (diagnosis.json, scene.json, report.html, steps/)")
      ->required();
  igi::diagnose::AddDiagnoseFlags(app, &flags);
  return igi::RunMain(app, common, argc, argv, [&]() {
    const igi::diagnose::DiagnoseOptions o =
        igi::diagnose::FinishDiagnoseFlags(flags, common.threads, !common.quiet);
    igi::RejectOutputInSceneFolder(out_dir, scene_path);
    const igi::recon::Scene scene = igi::recon::LoadScene(scene_path);
    if (scene.photos.empty()) {
      throw igi::InputError(igi::DescribeProblem(scene.file.string(), "photos", "[]",
                                                 "needs at least one photo to compare with"));
    }
    const igi::diagnose::DiagnosisSummary s = igi::diagnose::Diagnose(scene, o, out_dir);
    igi::diagnose::WriteDiagnosisOutputs(s, o, out_dir);
    if (!common.quiet) {
      std::cout << "baseline residual " << s.baseline_residual << " (held out "
                << s.baseline_held_out << ")\n";
      for (const igi::diagnose::DiagnosisStep& d : s.steps) {
        std::cout << (d.kept ? "  + " : "  - ") << d.candidate.effect << ": " << d.verdict << "\n";
      }
      std::cout << "final residual " << s.final_residual << " (held out " << s.final_held_out
                << "), noise floor estimate " << s.noise_floor << "\n";
    }
    return 0;
  });
}
