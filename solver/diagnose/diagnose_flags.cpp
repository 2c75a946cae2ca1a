#include "solver/diagnose/diagnose_flags.h"

namespace igi::diagnose {

void AddDiagnoseFlags(CLI::App& app, DiagnoseOptions* options) {
  DiagnoseOptions& o = *options;
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
}

DiagnoseOptions FinishDiagnoseFlags(const DiagnoseOptions& options, int threads,
                                    bool show_progress) {
  DiagnoseOptions o = options;
  o.num_threads = threads;
  o.show_progress = show_progress;
  o.Validate();
  return o;
}

}  // namespace igi::diagnose
