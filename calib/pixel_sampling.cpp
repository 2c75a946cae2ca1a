#include "calib/pixel_sampling.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace igi::calib {
namespace {

// Mean over channels of pixel (x, y), clamped at the borders.
float Grey(const Image& image, int x, int y) {
  x = std::clamp(x, 0, image.width - 1);
  y = std::clamp(y, 0, image.height - 1);
  float sum = 0.0f;
  for (int c = 0; c < image.channels; ++c) sum += image.at(x, y, c);
  return sum / float(image.channels);
}

struct Candidate {
  int64_t index;
  float value;
  float gradient;
};

}  // namespace

int MiddleExposureIndex(const std::vector<double>& exposures_s) {
  std::vector<int> order(exposures_s.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(),
            [&](int a, int b) { return exposures_s[size_t(a)] < exposures_s[size_t(b)]; });
  return order[order.size() / 2];
}

std::vector<int64_t> SelectSamplePixels(const Bracket& bracket, const SamplingOptions& options) {
  const Image& mid = bracket.images[size_t(MiddleExposureIndex(bracket.exposures_s))];
  const int width = mid.width;
  const int height = mid.height;
  const double cells_wanted = 4.0 * std::max(options.samples, 1);
  const int grid_x = std::clamp(int(std::ceil(std::sqrt(cells_wanted * width / height))), 1, width);
  const int grid_y = std::clamp(int(std::ceil(cells_wanted / grid_x)), 1, height);
  std::vector<Candidate> winners;
  for (int gy = 0; gy < grid_y; ++gy) {
    for (int gx = 0; gx < grid_x; ++gx) {
      Candidate best{-1, 0.0f, 1e30f};
      for (int y = gy * height / grid_y; y < (gy + 1) * height / grid_y; ++y) {
        for (int x = gx * width / grid_x; x < (gx + 1) * width / grid_x; ++x) {
          bool usable = true;
          for (int c = 0; c < mid.channels; ++c) {
            const float v = mid.at(x, y, c);
            usable = usable && v > options.black && v < options.saturated;
          }
          if (!usable) continue;
          const float gradient = std::abs(Grey(mid, x + 1, y) - Grey(mid, x - 1, y)) +
                                 std::abs(Grey(mid, x, y + 1) - Grey(mid, x, y - 1));
          if (gradient < best.gradient) {
            best = {int64_t(y) * width + x, Grey(mid, x, y), gradient};
          }
        }
      }
      if (best.index >= 0) winners.push_back(best);
    }
  }
  // Bin by value, lowest gradient first in each bin, then take round-robin over the bins.
  const int num_bins = std::clamp(options.samples / 4, 1, 64);
  std::vector<std::vector<Candidate>> bins(static_cast<size_t>(num_bins));
  const double span = options.saturated - options.black;
  for (const Candidate& c : winners) {
    const int bin = std::clamp(int((c.value - options.black) / span * num_bins), 0, num_bins - 1);
    bins[size_t(bin)].push_back(c);
  }
  for (auto& bin : bins) {
    std::sort(bin.begin(), bin.end(),
              [](const Candidate& a, const Candidate& b) { return a.gradient < b.gradient; });
  }
  std::vector<int64_t> chosen;
  for (size_t round = 0; int(chosen.size()) < options.samples; ++round) {
    bool any = false;
    for (const auto& bin : bins) {
      if (round < bin.size() && int(chosen.size()) < options.samples) {
        chosen.push_back(bin[round].index);
        any = true;
      }
    }
    if (!any) break;
  }
  std::sort(chosen.begin(), chosen.end());
  return chosen;
}

}  // namespace igi::calib
