#pragma once
// How converged igi-diagnose's re-renders must be for the photos' own noise to be what its tests
// read. Every held-out test compares squared errors between models rendered with the same paths;
// a render's Monte Carlo variance adds to every pixel's error and so to the standard errors the
// verdicts divide by, and a small effect (a light 10-30 % off in places) drowns in renders whose
// noise is larger than the photos'. Small captures can afford many paths per pixel: the renders'
// paths are chosen from the noise of the photos, not fixed.

#include <vector>

#include "solver/diagnose/diagnose_options.h"
#include "solver/diagnose/pixel_records.h"
#include "tools/common/json.h"

namespace igi::diagnose {

// The noise of photos and renders over the valid pixels, as shares of the photos' mean square
// (the scale of the residuals igi-diagnose reports).
struct RenderNoise {
  double white = 0;   // the white part of the residual: half the mean square of differences
                      // of horizontally adjacent pixels (photo noise plus render noise)
  double render = 0;  // the renders' variance (SimulatePhotos' estimate) at `spp_measured`
  double photo = 0;   // white − render: the photos' own noise (at least 1 % of white)
  int spp_measured = 0;
  int spp = 0;  // the paths per pixel chosen
};

// Measures RenderNoise on `photos` against `sim` (rendered at `spp` paths per pixel) and chooses
// the paths per pixel at which the renders' variance is at most `share` of the photos' noise
// (variance falls as 1/spp), within [spp, spp_max].
RenderNoise ChooseSpp(const PhotoSet& photos, const Simulation& sim, int spp, int spp_max,
                      double share);

// The most paths per pixel the re-renders may take (DiagnoseOptions::spp_max): with −1, the
// paths a capture of analysis_megapixels takes at spp, spread over the pixels of `photos` (the
// capture as analysed), at least spp.
int MaxSpp(const DiagnoseOptions& o, const PhotoSet& photos);

Json RenderNoiseJson(const RenderNoise& n, double share);

}  // namespace igi::diagnose
