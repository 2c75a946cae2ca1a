#include "hdr/merge.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "tools/common/error.h"
#include "tools/common/parallel.h"

namespace igi::hdr {
namespace {

// Lookup tables of one channel, indexed by the quantised level q in [0, 2^bits).
struct ChannelTables {
  std::vector<float> lin;     // I(q) = exp(g(q)), response units
  std::vector<float> ln;      // g(q)
  std::vector<float> weight;  // 0 where unusable
};

ChannelTables BuildTables(const calib::ResponseCurve& response, int curve, int levels,
                          const MergeOptions& options) {
  ChannelTables t;
  t.lin.resize(size_t(levels));
  t.ln.resize(size_t(levels));
  t.weight.resize(size_t(levels));
  const double top = response.LnExposure(curve, 1.0);
  std::vector<double> normalised(static_cast<size_t>(levels));
  for (int q = 0; q < levels; ++q) {
    const double g = response.LnExposure(curve, double(q) / (levels - 1));
    t.ln[size_t(q)] = float(g);
    t.lin[size_t(q)] = float(std::exp(g));
    normalised[size_t(q)] = std::exp(g - top);
  }
  for (int q = 0; q < levels; ++q) {
    const double v = double(q) / (levels - 1);
    if (v <= options.black || v >= options.saturated) continue;
    if (options.weighting == "hat") {
      t.weight[size_t(q)] = float(std::min(v - options.black, options.saturated - v));
      continue;
    }
    const double slope =
        0.5 * (normalised[size_t(std::min(q + 1, levels - 1))] - normalised[size_t(q - 1)]);
    const double variance = options.shot_noise * normalised[size_t(q)] +
                            options.read_noise * options.read_noise + slope * slope / 12.0;
    t.weight[size_t(q)] = float(1.0 / variance);
  }
  return t;
}

void CheckInputs(const std::vector<Image>& images, const std::vector<double>& exposures_s,
                 const calib::ResponseCurve& response) {
  if (images.size() < 1 || images.size() != exposures_s.size()) {
    throw InputError(DescribeProblem("bracket", "images", fmt::format("{}", images.size()),
                                     fmt::format("need one exposure time per image ({} given)",
                                                 exposures_s.size())));
  }
  for (size_t j = 1; j < images.size(); ++j) {
    if (images[j].width != images[0].width || images[j].height != images[0].height ||
        images[j].channels != images[0].channels) {
      throw InputError(DescribeProblem(fmt::format("image {}", j), "size",
                                       fmt::format("{}x{}", images[j].width, images[j].height),
                                       "every image must have the size of the first"));
    }
  }
  if (response.num_channels() != 1 && response.num_channels() != images[0].channels) {
    throw InputError(DescribeProblem(
        "response", "channels", fmt::format("{}", response.num_channels()),
        fmt::format("must be 1 or the images' channel count ({})", images[0].channels)));
  }
}

}  // namespace

void MergeOptions::Validate() const {
  ProblemList problems;
  if (weighting != "noise" && weighting != "hat") {
    problems.Add("--weighting", "", weighting, "must be noise or hat");
  }
  if (!(black >= 0.0 && black < saturated && saturated <= 1.0)) {
    problems.Add("--black/--saturated", "", fmt::format("{}/{}", black, saturated),
                 "need 0 <= black < saturated <= 1");
  }
  if (!(shot_noise >= 0.0) || !(read_noise > 0.0)) {
    problems.Add("--shot-noise/--read-noise", "", fmt::format("{}/{}", shot_noise, read_noise),
                 "need shot noise >= 0 and read noise > 0");
  }
  if (bits != 8 && bits != 16) problems.Add("bits", "", fmt::format("{}", bits), "must be 8 or 16");
  problems.ThrowIfAny();
}

MergeResult MergeBracket(const std::vector<Image>& images, const std::vector<double>& exposures_s,
                         const calib::ResponseCurve& response, const MergeOptions& options) {
  options.Validate();
  CheckInputs(images, exposures_s, response);
  const auto start = std::chrono::steady_clock::now();
  const int width = images[0].width, height = images[0].height, channels = images[0].channels;
  const int levels = 1 << options.bits;
  std::vector<ChannelTables> tables;
  for (int c = 0; c < channels; ++c) {
    tables.push_back(BuildTables(response, response.num_channels() == 1 ? 0 : c, levels, options));
  }
  const size_t p = images.size();
  const size_t shortest = size_t(std::min_element(exposures_s.begin(), exposures_s.end()) -
                                 exposures_s.begin());
  const size_t longest = size_t(std::max_element(exposures_s.begin(), exposures_s.end()) -
                                exposures_s.begin());
  std::vector<float> t(p), t2(p), ln_t(p);
  std::vector<const float*> src(p);
  for (size_t j = 0; j < p; ++j) {
    t[j] = float(exposures_s[j]);
    t2[j] = t[j] * t[j];
    ln_t[j] = float(std::log(exposures_s[j]));
    src[j] = images[j].pixels.data();
  }
  MergeResult result;
  result.radiance = Image(width, height, channels);
  result.mask = Image(width, height, 1, 1.0f);
  std::atomic<int64_t> saturated{0}, black{0};
  const float scale = float(levels - 1);
  const bool hat = options.weighting == "hat";
  ParallelForRange(
      0, height,
      [&](int64_t y0, int64_t y1) {
        int64_t row_saturated = 0, row_black = 0;
        for (int64_t y = y0; y < y1; ++y) {
          for (int x = 0; x < width; ++x) {
            const size_t pixel = size_t(y) * width + x;
            bool flagged_saturated = false, flagged_black = false;
            for (int c = 0; c < channels; ++c) {
              const size_t i = pixel * channels + c;
              const ChannelTables& tab = tables[size_t(c)];
              float num = 0.0f, den = 0.0f;
              for (size_t j = 0; j < p; ++j) {
                const int q = std::clamp(int(src[j][i] * scale + 0.5f), 0, levels - 1);
                const float w = tab.weight[size_t(q)];
                if (hat) {
                  num += w * (tab.ln[size_t(q)] - ln_t[j]);
                  den += w;
                } else {
                  num += w * t[j] * tab.lin[size_t(q)];
                  den += w * t2[j];
                }
              }
              float value;
              if (den > 0.0f) {
                value = hat ? std::exp(num / den) : num / den;
              } else {
                const int q_short = std::clamp(int(src[shortest][i] * scale + 0.5f), 0, levels - 1);
                const bool is_saturated = double(q_short) / (levels - 1) >= options.saturated;
                const size_t j = is_saturated ? shortest : longest;
                const int q = std::clamp(int(src[j][i] * scale + 0.5f), 0, levels - 1);
                value = tab.lin[size_t(q)] / t[j];
                flagged_saturated |= is_saturated;
                flagged_black |= !is_saturated;
              }
              result.radiance.pixels[i] = value;
            }
            if (flagged_saturated || flagged_black) result.mask.pixels[pixel] = 0.0f;
            row_saturated += flagged_saturated ? 1 : 0;
            row_black += flagged_black ? 1 : 0;
          }
        }
        saturated += row_saturated;
        black += row_black;
      },
      options.num_threads, 8);
  result.saturated_pixels = saturated;
  result.black_pixels = black;
  result.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  spdlog::debug("merge: {}x{}x{}, {} images, {} weights, {:.3f} s", width, height, channels, p,
                options.weighting, result.seconds);
  return result;
}

}  // namespace igi::hdr
