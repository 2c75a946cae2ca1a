#include "capture/auto_meter.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "tools/common/error.h"

namespace igi::capture {
namespace {

// Largest change of exposure per metering step (a factor): keeps a wild
// prediction from a nearly black or clipped frame from overshooting the
// camera's range in one jump.
constexpr double kMaxStep = 16.0;
// A level this close to full scale counts as clipped: its true value is
// unknown.
constexpr double kClipped = 0.98;

double Clamp(double value, double lo, double hi) { return std::min(std::max(value, lo), hi); }

// The longest exposure whose highlights stay at or under the target: predicts
// from the last reading, and bisects (in stops) between the longest exposure
// known to be fine and the shortest known to be too bright once both are known.
double FindShortest(const std::function<MeterReading(double)>& measure, double lo, double hi,
                    double start, const AutoMeterOptions& options, AutoMeterReport* report) {
  double exposure = Clamp(start, lo, hi);
  double fine = 0.0;                                            // longest exposure under the target
  double too_bright = std::numeric_limits<double>::infinity();  // shortest one over it
  for (int i = 0; i < options.max_iterations; ++i) {
    const double level = measure(exposure).highlight;
    ++report->frames_metered;
    if (level <= options.highlight_target) {
      fine = std::max(fine, exposure);
      if (level >= options.highlight_target * 0.84) break;  // within a quarter stop
    } else {
      too_bright = std::min(too_bright, exposure);
    }
    double factor = kMaxStep;
    if (level >= kClipped) {
      factor = 1.0 / kMaxStep;
    } else if (level > 0.0) {
      // Aim at the middle of the accepted band [0.84, 1] x target.
      factor = Clamp(0.92 * options.highlight_target / level, 1.0 / kMaxStep, kMaxStep);
    }
    double next = Clamp(exposure * factor, lo, hi);
    if (fine > 0 && std::isfinite(too_bright)) {
      if (too_bright / fine < std::exp2(0.25)) break;
      if (next <= fine || next >= too_bright) next = std::sqrt(fine * too_bright);
    }
    if (next == exposure) break;  // pinned at a camera limit
    exposure = next;
  }
  if (fine > 0) {
    report->highlights_covered = true;
    return fine;
  }
  report->notes.push_back(
      fmt::format("highlights clip even at the shortest exposure tried ({:g} "
                  "us, camera minimum {:g} us)",
                  exposure, lo));
  return exposure;
}

// The shortest exposure (from `shortest` up) whose shadows reach the target.
double FindLongest(const std::function<MeterReading(double)>& measure, double shortest, double hi,
                   const AutoMeterOptions& options, AutoMeterReport* report) {
  double exposure = shortest;
  for (int i = 0; i < options.max_iterations; ++i) {
    const MeterReading reading = measure(exposure);
    ++report->frames_metered;
    if (reading.shadow >= options.shadow_target) {
      report->shadows_covered = true;
      return exposure;
    }
    if (exposure >= hi) break;
    const double factor = reading.shadow > 0
                              ? Clamp(options.shadow_target / reading.shadow, 1.05, kMaxStep)
                              : kMaxStep;
    exposure = std::min(exposure * factor, hi);
  }
  report->notes.push_back(
      fmt::format("shadows stay under {:g} of full scale up to {:g} us (the "
                  "longest allowed)",
                  options.shadow_target, exposure));
  return exposure;
}

}  // namespace

void AutoMeterOptions::Validate() const {
  ProblemList problems;
  if (!(stop_spacing > 0))
    problems.Add("", "--stop-spacing", fmt::format("{}", stop_spacing), "must be > 0");
  if (!(highlight_percentile > 0 && highlight_percentile <= 100)) {
    problems.Add("", "highlight_percentile", fmt::format("{}", highlight_percentile),
                 "must be in (0, 100]");
  }
  if (!(shadow_percentile >= 0 && shadow_percentile < highlight_percentile)) {
    problems.Add("", "shadow_percentile", fmt::format("{}", shadow_percentile),
                 "must be in [0, highlight_percentile)");
  }
  if (!(highlight_target > 0 && highlight_target < 1)) {
    problems.Add("", "highlight_target", fmt::format("{}", highlight_target), "must be in (0, 1)");
  }
  if (!(shadow_target > 0 && shadow_target < highlight_target)) {
    problems.Add("", "shadow_target", fmt::format("{}", shadow_target),
                 "must be in (0, highlight_target)");
  }
  if (!(max_exposure_us > 0)) {
    problems.Add("", "--max-exposure-us", fmt::format("{}", max_exposure_us), "must be > 0");
  }
  if (max_brackets < 1)
    problems.Add("", "max_brackets", std::to_string(max_brackets), "must be >= 1");
  if (max_iterations < 1) {
    problems.Add("", "max_iterations", std::to_string(max_iterations), "must be >= 1");
  }
  problems.ThrowIfAny();
}

MeterReading ReadMeter(const Frame& frame, const AutoMeterOptions& options) {
  std::vector<uint16_t> levels = frame.Levels();
  MeterReading reading;
  if (levels.empty()) return reading;
  const double full_scale = double((1 << frame.format.significant_bits) - 1);
  auto percentile = [&](double percent) {
    const size_t k = std::min(levels.size() - 1, size_t(percent / 100.0 * double(levels.size())));
    std::nth_element(levels.begin(), levels.begin() + std::ptrdiff_t(k), levels.end());
    return double(levels[k]) / full_scale;
  };
  reading.highlight = percentile(options.highlight_percentile);
  reading.shadow = percentile(options.shadow_percentile);
  return reading;
}

AutoMeterReport ChooseExposures(const std::function<MeterReading(double)>& measure, double min_us,
                                double max_us, double start_us, const AutoMeterOptions& options) {
  options.Validate();
  const double hi = std::min(max_us, options.max_exposure_us);
  const double lo = std::min(min_us, hi);
  AutoMeterReport report;
  report.shortest_us = FindShortest(measure, lo, hi, start_us, options, &report);
  report.longest_us = FindLongest(measure, report.shortest_us, hi, options, &report);
  const double stops = std::log2(report.longest_us / report.shortest_us);
  int count = 1 + int(std::ceil(stops / options.stop_spacing - 1e-9));
  if (count > options.max_brackets) {
    report.notes.push_back(fmt::format("the range needs {} exposures; kept the first {}", count,
                                       options.max_brackets));
    count = options.max_brackets;
  }
  for (int i = 0; i < count; ++i) {
    const double exposure = report.shortest_us * std::exp2(options.stop_spacing * i);
    report.exposures_us.push_back(std::min(exposure, hi));
  }
  // The last step may overshoot the camera's limit: keep the exposures
  // distinct.
  report.exposures_us.erase(std::unique(report.exposures_us.begin(), report.exposures_us.end()),
                            report.exposures_us.end());
  return report;
}

}  // namespace igi::capture
