#pragma once
// Test helper (header only, shared by tests/calib and tests/hdr): Debevec's Memorial Church
// bracket (../shared/data/real/memorial: 16 8-bit photos, 1 stop apart, with their shutter times),
// loaded both as igi's Bracket and as the BGR matrices and float times OpenCV's photo module takes,
// and the measure of a response's consistency on it.

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "calib/bracket.h"

namespace igi::testing {

struct MemorialBracket {
  calib::Bracket bracket;      // normalised levels, RGB
  std::vector<cv::Mat> mats;   // the same photos as 8-bit BGR
  std::vector<float> times_s;  // exposure times, as OpenCV takes them
};

inline MemorialBracket LoadMemorial() {
  const std::string dir = std::string(IGI_SHARED_DATA_DIR) + "/real/memorial/";
  MemorialBracket m;
  std::vector<std::filesystem::path> paths;
  for (int i = 61; i <= 76; ++i) {
    paths.push_back(dir + "memorial00" + std::to_string(i) + ".png");
    m.mats.push_back(cv::imread(paths.back().string(), cv::IMREAD_COLOR));
  }
  calib::ExposureSource source;
  source.file = dir + "shutter_times.txt";
  m.bracket = calib::LoadBracket(paths, source);
  m.times_s.assign(m.bracket.exposures_s.begin(), m.bracket.exposures_s.end());
  return m;
}

// The spread of a bracket's exposures through a response: every well-exposed value (levels
// 25..230 of 255) of a pixel, linearised by `ln_exposure(channel, level)` (the curve g) and divided
// by its exposure time, estimates ln E; the median over pixels (every second row and column),
// channels and exposures of |ln E_j - mean ln E| over the pixel's well-exposed values (at least
// two). A right response gives every exposure the same radiance: 0 but for noise.
inline double ExposureSpread(const MemorialBracket& m,
                             const std::function<double(int channel, int level)>& ln_exposure) {
  std::vector<float> deviations;
  const size_t n = m.mats.size();
  std::vector<double> ln_e(n);
  for (int y = 0; y < m.mats[0].rows; y += 2) {
    for (int x = 0; x < m.mats[0].cols; x += 2) {
      for (int c = 0; c < 3; ++c) {
        double sum = 0.0;
        int count = 0;
        for (size_t j = 0; j < n; ++j) {
          const int level = m.mats[j].at<cv::Vec3b>(y, x)[2 - c];
          ln_e[j] = NAN;
          if (level < 25 || level > 230) continue;
          ln_e[j] = ln_exposure(c, level) - std::log(m.bracket.exposures_s[j]);
          sum += ln_e[j];
          ++count;
        }
        if (count < 2) continue;
        for (size_t j = 0; j < n; ++j) {
          if (!std::isnan(ln_e[j])) deviations.push_back(float(std::abs(ln_e[j] - sum / count)));
        }
      }
    }
  }
  std::nth_element(deviations.begin(), deviations.begin() + long(deviations.size() / 2),
                   deviations.end());
  return deviations[deviations.size() / 2];
}

}  // namespace igi::testing
