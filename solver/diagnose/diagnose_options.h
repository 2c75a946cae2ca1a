#pragma once
// Options of igi-diagnose (docs/diagnose.md).

#include <cstdint>

#include "solver/inverse/solve_options.h"

namespace igi::diagnose {

struct DiagnoseOptions {
  int spp = 32;  // paths per pixel of the re-renders
  // When above spp: the re-renders' paths per pixel are chosen, within [spp, spp_max], so that
  // their Monte Carlo variance is at most render_noise_share of the photos' own noise, measured
  // on the baseline (render_noise.h). 0: fixed at spp. −1 (auto): up to the paths a capture of
  // analysis_megapixels takes at spp, spread over the pixels analysed (a smaller capture affords
  // more paths per pixel at the same cost; a capture analysed at that size keeps spp).
  int spp_max = -1;
  double render_noise_share = 0.25;
  int pixel_stride = 2;  // every Nth pixel of each photo is a residual sample
  int max_steps = 4;     // effects modelled at most
  // Photos over this many megapixels are analysed as the means of pixel blocks that bring them
  // within it (solver/diagnose/analysis_capture.h); 0 = at full size.
  double analysis_megapixels = 0.5;
  // Held-out pixels: square blocks, left out of every fit (the solver's and the effects').
  double holdout_fraction = 0.25;
  int holdout_block_px = 16;
  // A step is kept when its held-out residual² falls by at least this share AND by at least
  // `min_z` standard errors (estimated over the held-out blocks).
  double min_gain = 0.02;
  double min_z = 2.5;
  // A candidate is refitted (the real test above) when its predicted held-out gain reaches
  // candidate_min_gain (a share) and candidate_min_z (standard errors); at most `max_tries`
  // candidates per step, best predicted first (the two best of different effects are both
  // refitted, further ones only while none passes: RankForTrials). The predictions come from
  // direct-light records and can fall far short of the refit's gain where a region's reflected
  // room dominates or the re-solve's albedos follow the change, so the thresholds are low and
  // several tries are allowed; each try costs a re-solve and a partial re-render (measured:
  // docs/diagnose.md).
  double candidate_min_gain = 0.005;
  // The same for missing_geometry's trial before the maps: a rejected trial there keeps the
  // object out of every later round, so it waits for a larger predicted share.
  double missing_geometry_min_gain = 0.01;
  double candidate_min_z = 1.5;
  int max_tries = 5;
  int light_samples = 8;  // per extended light, for the direct-light features
  // Seed of the re-renders (the same for every model, so that their differences are not Monte
  // Carlo noise) and of the pixel records' light samples.
  uint64_t seed = 1;
  // Worker threads; 0 = the process default.
  int num_threads = 0;
  // Progress bars on stderr (only when it is a terminal).
  bool show_progress = true;
  // Used when materials are unknown (refits re-solve them). Every pixel is an observation: an
  // albedo map's texel is the pixel footprint times the stride, and at igi-solve's default of 2
  // the maps cannot follow a texture the photos resolve.
  solver::SolveOptions solve = [] {
    solver::SolveOptions s;
    s.pixel_stride = 1;
    return s;
  }();

  void Validate() const;
};

}  // namespace igi::diagnose
