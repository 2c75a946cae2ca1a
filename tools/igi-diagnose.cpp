// igi-diagnose (docs/diagnose.md): find, name and model what the simulation leaves out. Thin
// main: flags → DiagnoseOptions, load the scene, diagnose, write diagnosis.json, report.html and
// the improved scene.json.
#include <CLI/CLI.hpp>
#include <filesystem>
#include <iostream>

#include "recon/scene.h"
#include "solver/diagnose/diagnose.h"
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
  igi::diagnose::DiagnoseOptions o;
  app.add_option("scene", scene_path, "scene.json (unknown materials are solved first)")
      ->required();
  app.add_option("--out", out_dir,
                 "output folder (diagnosis.json, scene.json, report.html, steps/)")
      ->required();
  app.add_option("--spp", o.spp, "paths per pixel of the re-renders")->capture_default_str();
  app.add_option("--spp-max", o.spp_max,
                 "when above --spp: the paths per pixel are chosen within [--spp, this] from the "
                 "photos' noise; -1 = up to the paths --analysis-megapixels of photos take at "
                 "--spp, spread over the pixels analysed; 0 = fixed at --spp")
      ->capture_default_str();
  app.add_option("--render-noise-share", o.render_noise_share,
                 "the renders' variance the chosen paths allow, as a share of the photos' noise")
      ->capture_default_str();
  app.add_option("--analysis-megapixels", o.analysis_megapixels,
                 "larger photos are analysed as the means of pixel blocks that bring them within "
                 "this size (0 = full size)")
      ->capture_default_str();
  app.add_option("--pixel-stride", o.pixel_stride, "residual samples: every Nth pixel")
      ->capture_default_str();
  app.add_option("--max-steps", o.max_steps, "effects modelled at most")->capture_default_str();
  app.add_option("--holdout-fraction", o.holdout_fraction, "share of pixel blocks held out")
      ->capture_default_str();
  app.add_option("--holdout-block-px", o.holdout_block_px, "held-out block size, pixels")
      ->capture_default_str();
  app.add_option("--min-gain", o.min_gain, "held-out residual² reduction a step must reach")
      ->capture_default_str();
  app.add_option("--min-z", o.min_z, "standard errors the held-out gain must reach")
      ->capture_default_str();
  app.add_option("--light-samples", o.light_samples, "light samples per extended light")
      ->capture_default_str();
  app.add_option("--solve-stride", o.solve.pixel_stride, "igi-solve --pixel-stride")
      ->capture_default_str();
  app.add_option("--memory-budget", o.solve.memory_budget,
                 "memory budget, GiB (0 = the machine's memory less a margin): the photos and "
                 "re-renders at the analysis size are planned first, its solves get the rest")
      ->capture_default_str();
  app.add_option("--max-observations", o.solve.max_observations,
                 "igi-solve --max-observations for its solves (0 = as the memory budget allows)")
      ->capture_default_str();
  app.add_option("--solve-iterations", o.solve.max_iterations, "igi-solve --max-iterations")
      ->capture_default_str();
  app.add_option("--refine-iterations", o.solve.refine_iterations, "igi-solve --refine-iterations")
      ->capture_default_str();
  app.add_option("--seed", o.seed, "random seed")->capture_default_str();
  return igi::RunMain(app, common, argc, argv, [&]() {
    o.num_threads = common.threads;
    o.show_progress = !common.quiet;
    o.Validate();
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
