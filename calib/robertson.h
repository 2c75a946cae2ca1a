#pragma once
// Robertson, Borman & Stevenson, "Estimation-theoretic approach to dynamic range enhancement
// using multiple exposures" (J. Electronic Imaging 2003): alternates the maximum-likelihood
// radiance of each pixel given the inverse response I(z), and I(z) given the radiances, with
// Gaussian-shaped certainty weights. Works on levels (16-bit input is binned into `levels`).
// Use RecoverResponse (calib/response_recovery.h) with method "robertson".

#include "calib/bracket.h"
#include "calib/response_recovery.h"

namespace igi::calib {

ResponseSummary RecoverRobertson(const Bracket& bracket, const ResponseOptions& options,
                                 int levels);

}  // namespace igi::calib
