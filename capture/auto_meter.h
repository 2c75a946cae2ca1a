#pragma once
// --auto: meters the scene through the camera and chooses a bracket that covers
// its highlights and shadows with a chosen spacing in stops.
//
// The shortest exposure is the longest one that keeps the highlight percentile
// at or below `highlight_target` of full scale (so nothing that matters clips);
// the longest exposure is the shortest one that lifts the shadow percentile to
// `shadow_target` of full scale (so the dark parts get well-exposed levels).
// Between them the exposures step by `stop_spacing` stops. The search is
// iterative (predict from a linear response, measure, correct), so it also
// converges on cameras whose levels are not proportional to exposure. Exposures
// stay inside the camera's range; when the range cannot reach a target the
// report says so.

#include <functional>
#include <string>
#include <vector>

#include "capture/camera.h"

namespace igi::capture {

struct AutoMeterOptions {
  double stop_spacing = 2.0;           // stops between neighbouring exposures, > 0
  double highlight_percentile = 99.5;  // % of pixels at or below the "highlights" level
  double shadow_percentile = 2.0;      // % of pixels at or below the "shadows" level
  double highlight_target = 0.85;      // fraction of full scale the highlights may reach
  double shadow_target = 0.2;          // fraction of full scale the shadows must reach
  double max_exposure_us = 2e6;        // never meter or plan longer than this (µs)
  int max_brackets = 16;               // at most this many exposures
  int max_iterations = 12;             // metering frames per end of the range

  void Validate() const;
};

// The highlight and shadow levels of one metering frame, as fractions of full
// scale.
struct MeterReading {
  double highlight = 0.0;
  double shadow = 0.0;
};

// Reads a frame's percentiles (all channels pooled).
MeterReading ReadMeter(const Frame& frame, const AutoMeterOptions& options);

struct AutoMeterReport {
  std::vector<double> exposures_us;  // the chosen bracket, shortest first
  double shortest_us = 0.0;
  double longest_us = 0.0;
  bool highlights_covered = false;  // the shortest exposure keeps highlights under the target
  bool shadows_covered = false;     // the longest exposure lifts shadows to the target
  int frames_metered = 0;
  std::vector<std::string> notes;  // why a target was not reached
};

// `measure(exposure_us)` sets the exposure and returns the reading of a settled
// frame; the camera's exposure range is [min_us, max_us]; metering starts at
// `start_us`.
AutoMeterReport ChooseExposures(const std::function<MeterReading(double)>& measure, double min_us,
                                double max_us, double start_us, const AutoMeterOptions& options);

}  // namespace igi::capture
