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
// Debevec's lambda is chosen automatically by default (ResponseOptions::lambda = kLambdaAuto):
// for each lambda of kAutoLambdas in increasing order, the samples are split into two halves
// (alternately), each half gives a curve, and half the RMS difference of the two curves over the
// levels with data (weighted by their data, offset removed) estimates the noise of the full
// curve. The smallest lambda whose noise is at most kAutoLambdaNoise (0.15 % RMS in exposure),
// or within kAutoLambdaSlack of the least noise on the grid when no lambda reaches that, wins:
// the least smoothing bias among curves that are as reproducible as the data allow.
// (Cross-validation of the data residual cannot do this: on a bracket with one constant exposure
// ratio, ripples of g periodic in ln exposure with that period barely change any residual, yet they
// bias the radiance by percents; the split-half curves show them because each half's noise excites
// them differently.) When no lambda reaches the target, the data set the bound. The chosen lambda
// is in the summary. Measured on the synthetic 5-image x4 brackets (tests/calib): lambda 10
// leaves 2.7-5.4 % errors, auto <= 1 %.
//
// Values at or below the black level (by default each channel's black floor, see
// DetectBlackFloor) or at or above the saturation level take no part in either fit.
//
// Both return g non-decreasing (running extrema outward from the middle level flatten the
// wiggles of levels with no data).
// Too few usable pixels is an InputError naming the images and the rule.

#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "calib/bracket.h"
#include "calib/response_curve.h"

namespace igi::calib {

inline constexpr double kLambdaAuto = -1.0;
// ResponseOptions::black: each channel's black floor (DetectBlackFloor), at least kMinBlack.
inline constexpr double kBlackAuto = -1.0;
inline constexpr double kMinBlack = 0.02;
inline constexpr std::array<double, 5> kAutoLambdas = {3, 10, 30, 100, 300};
inline constexpr double kAutoLambdaNoise = 0.0015;  // ln units (0.15 % RMS)
inline constexpr double kAutoLambdaSlack = 1.25;

// "auto" -> kLambdaAuto, else a number >= 0. Throws InputError "--lambda: TEXT: RULE".
double ParseLambda(const std::string& text);
// "auto" -> kBlackAuto, else a number in [0, 1). Throws InputError "--black: TEXT: RULE".
double ParseBlack(const std::string& text);

// The recovery method (see the top of this file): kDebevec, Debevec & Malik's least squares;
// kRobertson, Robertson et al.'s maximum likelihood.
enum class ResponseRecoveryMethod { kDebevec, kRobertson };
// "debevec", "robertson" (the --method flag's spelling and the ResponseCurve::method it writes).
std::string_view ResponseRecoveryMethodName(ResponseRecoveryMethod method);
std::optional<ResponseRecoveryMethod> ResponseRecoveryMethodFromName(std::string_view name);

struct ResponseOptions {
  // kDebevec (default) or kRobertson.
  ResponseRecoveryMethod method = ResponseRecoveryMethod::kDebevec;
  // Smoothness weight (Debevec's lambda; same scale as OpenCV's, whose default is 10), or
  // kLambdaAuto: chosen per channel (see above).
  double lambda = kLambdaAuto;
  int levels = 0;  // levels of g; 0 = 256 for 8-bit input, 1024 for 16-bit
  // Sampled pixels (debevec); 0 = min(4000, max(1000, 3 levels / (P-1))). Many samples cost
  // little (each adds a P x P block) and average the noise that ripples the curve.
  int samples = 0;
  // Normalised value at or below which a value is unusable (it takes no part in the fit), or
  // kBlackAuto: per channel, max(kMinBlack, DetectBlackFloor).
  double black = kBlackAuto;
  double saturated = 0.98;  // normalised value at or above which a value is unusable
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
  int samples = 0;             // pixels used
  int equations = 0;           // independent data equations (per channel, the smallest)
  int iterations = 0;          // robertson
  std::vector<double> lambda;  // debevec: per channel, the lambda used (chosen when auto)
  bool converged = true;
  std::vector<double> rms_residual;  // per channel, ln units, over usable data equations
  std::vector<double> black;         // per channel, the black level used (normalised)
};

// The black floor of one channel of a bracket: the value that the pixels receiving (almost) no
// light pile up at, above true black, as a scanned film's base or a camera's black pedestal. It
// is read from the shortest exposure, where most of a scene is dark: the most common of its
// values in (kMinBlack, 0.25], if more than 10 % of the pixels lie within two levels (of 255) of
// it and the pile is narrow: the count falls below a tenth of the mode's within four levels
// above it and is below a tenth three levels below it (a broad mode is dark scene content, and a
// mode at the window's lower edge the tail of values falling from true black). The floor is the top
// of the pile, the first value above the mode held by fewer than a tenth as many pixels. Values at
// the floor carry no exposure (every time darker than the floor's gives the same value) and noise;
// counted as data with Debevec's hat weight they bend the curve's toe. Returns 0 when there is no
// pile (a bracket whose darkest photo is not mostly dark, or whose dark pixels are at true black).
double DetectBlackFloor(const Bracket& bracket, int channel);

ResponseSummary RecoverResponse(const Bracket& bracket, const ResponseOptions& options);

}  // namespace igi::calib
