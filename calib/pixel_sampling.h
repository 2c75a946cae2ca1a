#pragma once
// Chooses the pixels whose values across a bracket feed Debevec–Malik's least squares.
//
// Good samples are (1) well spread over the image: at most one per cell of a grid with about
// four cells per wanted sample, (2) unsaturated and not black in the bracket's middle exposure,
// (3) in flat areas: in each cell the pixel with the lowest local gradient (so a small
// misalignment or blur changes its value little), and (4) spread over the intensity range: the
// cell winners are binned by their middle-exposure value and taken round-robin from the bins.

#include <cstdint>
#include <vector>

#include "calib/bracket.h"

namespace igi::calib {

struct SamplingOptions {
  int samples = 100;        // pixels wanted (fewer come back when the image has fewer good ones)
  double black = 0.02;      // normalised value at or below which a pixel counts as black
  double saturated = 0.98;  // normalised value at or above which a pixel counts as saturated
};

// Pixel indices (y * width + x), sorted. Deterministic.
std::vector<int64_t> SelectSamplePixels(const Bracket& bracket, const SamplingOptions& options);

// Index of the image with the median exposure time.
int MiddleExposureIndex(const std::vector<double>& exposures_s);

}  // namespace igi::calib
