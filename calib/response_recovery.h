#pragma once
// Recovers a camera's response curve g(z) = ln(E * t) from an exposure bracket.
//
// - "debevec": Debevec & Malik (SIGGRAPH 1997): weighted least squares over sampled pixels,
//   hat weights, a smoothness term lambda * w(z) * g''(z), g(levels / 2) = 0; solved with
//   Eigen's sparse QR. 16-bit input is binned into `levels` (default 1024) and each equation
//   interpolates g between the two nearest levels, so no precision is thrown away.
// - "robertson": Robertson, Borman & Stevenson (1999/2003): alternating maximum-likelihood
//   estimates of the radiances and of the inverse response, over a regular subsample of pixels.
//
// Both return g non-decreasing (a running maximum removes the wiggles of levels with no data).
// Too few usable pixels is an InputError naming the images and the rule.

#include <string>
#include <vector>

#include "calib/bracket.h"
#include "calib/response_curve.h"

namespace igi::calib {

struct ResponseOptions {
  std::string method = "debevec";  // "debevec" or "robertson"
  double lambda = 10.0;            // smoothness weight (Debevec's lambda; same scale as OpenCV)
  int levels = 0;                  // levels of g; 0 = 256 for 8-bit input, 1024 for 16-bit
  int samples = 0;                 // sampled pixels (debevec); 0 = max(100, 3 levels / (P-1))
  double black = 0.02;             // normalised value at or below which a value is unusable
  double saturated = 0.98;         // normalised value at or above which a value is unusable
  // robertson: weight of a second-difference penalty on ln I(z) applied at every iteration
  // (0 = none, Robertson's original). A bracket with one constant exposure ratio leaves
  // components of ln I that are periodic in ln exposure undetermined; ~10..30 damps them.
  double robertson_smoothing = 0.0;
  int max_iterations = 50;           // robertson
  double tolerance = 1e-5;           // robertson: stop when g changes less (RMS, ln units)
  int max_robertson_pixels = 60000;  // robertson: pixels used (a regular subsample)

  // Throws InputError "option: VALUE: RULE" on a bad value.
  void Validate() const;
};

struct ResponseSummary {
  ResponseCurve curve;
  int samples = 0;     // pixels used
  int equations = 0;   // independent data equations (per channel, the smallest)
  int iterations = 0;  // robertson
  bool converged = true;
  std::vector<double> rms_residual;  // per channel, ln units, over usable data equations
};

ResponseSummary RecoverResponse(const Bracket& bracket, const ResponseOptions& options);

}  // namespace igi::calib
