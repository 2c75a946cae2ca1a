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
      // Debevec & Malik's hat over the levels (+1, as OpenCV's triangleWeights).
      t.weight[size_t(q)] = float((std::min(q, levels - 1 - q) + 1) / (0.5 * levels));
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

namespace {

// The per-pixel merge over lookup tables; one instance is shared by all threads (read only).
class MergeKernel {
 public:
  MergeKernel(const std::vector<Image>& images, const std::vector<double>& exposures_s,
              const calib::ResponseCurve& response, const MergeOptions& options)
      : options_(options),
        levels_(1 << options.bits),
        channels_(images[0].channels),
        scale_(float(levels_ - 1)),
        hat_(options.weighting == "hat") {
    for (int c = 0; c < channels_; ++c) {
      tables_.push_back(
          BuildTables(response, response.num_channels() == 1 ? 0 : c, levels_, options));
    }
    shortest_ = size_t(std::min_element(exposures_s.begin(), exposures_s.end()) -
                       exposures_s.begin());
    longest_ = size_t(std::max_element(exposures_s.begin(), exposures_s.end()) -
                      exposures_s.begin());
    for (size_t j = 0; j < images.size(); ++j) {
      t_.push_back(float(exposures_s[j]));
      ln_t_.push_back(float(std::log(exposures_s[j])));
      src_.push_back(images[j].pixels.data());
    }
  }

  // Merges pixel `pixel` into `out` (channels_ values); returns bit 1 = saturated, 2 = black.
  int Pixel(size_t pixel, float* out) const {
    constexpr int kMaxChannels = 8;
    float num[kMaxChannels] = {}, den[kMaxChannels] = {};
    const size_t base = pixel * size_t(channels_);
    const size_t p = src_.size();
    for (size_t j = 0; j < p; ++j) {
      float w_shared = 0.0f;
      int q[kMaxChannels];
      for (int c = 0; c < channels_; ++c) {
        q[c] = Level(src_[j][base + size_t(c)]);
        w_shared += tables_[size_t(c)].weight[size_t(q[c])];
      }
      w_shared /= float(channels_);
      for (int c = 0; c < channels_; ++c) {
        const ChannelTables& tab = tables_[size_t(c)];
        const float w = options_.shared_weights ? w_shared : tab.weight[size_t(q[c])];
        if (hat_) {
          num[c] += w * (tab.ln[size_t(q[c])] - ln_t_[j]);
          den[c] += w;
        } else {
          num[c] += w * t_[j] * tab.lin[size_t(q[c])];
          den[c] += w * t_[j] * t_[j];
        }
      }
    }
    int flags = 0;
    for (int c = 0; c < channels_; ++c) {
      if (den[c] > 0.0f) {
        out[c] = hat_ ? std::exp(num[c] / den[c]) : num[c] / den[c];
        continue;
      }
      // No usable value: saturated (judged on the shortest exposure) or black everywhere.
      const int q_short = Level(src_[shortest_][base + size_t(c)]);
      const bool saturated = double(q_short) / (levels_ - 1) >= options_.saturated;
      const size_t j = saturated ? shortest_ : longest_;
      out[c] = tables_[size_t(c)].lin[size_t(Level(src_[j][base + size_t(c)]))] / t_[j];
      flags |= saturated ? 1 : 2;
    }
    return flags;
  }

 private:
  int Level(float v) const { return std::clamp(int(v * scale_ + 0.5f), 0, levels_ - 1); }

  const MergeOptions& options_;
  int levels_;
  int channels_;
  float scale_;
  bool hat_;
  std::vector<ChannelTables> tables_;
  size_t shortest_ = 0, longest_ = 0;
  std::vector<float> t_, ln_t_;
  std::vector<const float*> src_;
};

}  // namespace

MergeResult MergeBracket(const std::vector<Image>& images, const std::vector<double>& exposures_s,
                         const calib::ResponseCurve& response, const MergeOptions& options) {
  options.Validate();
  CheckInputs(images, exposures_s, response);
  if (images[0].channels > 8) {
    throw InputError(DescribeProblem("bracket", "channels", fmt::format("{}", images[0].channels),
                                     "at most 8 channels"));
  }
  const auto start = std::chrono::steady_clock::now();
  const int width = images[0].width, height = images[0].height, channels = images[0].channels;
  const MergeKernel kernel(images, exposures_s, response, options);
  MergeResult result;
  result.radiance = Image(width, height, channels);
  result.mask = Image(width, height, 1, 1.0f);
  std::atomic<int64_t> saturated{0}, black{0};
  ParallelForRange(
      0, height,
      [&](int64_t y0, int64_t y1) {
        int64_t row_saturated = 0, row_black = 0;
        for (size_t pixel = size_t(y0) * width; pixel < size_t(y1) * width; ++pixel) {
          const int flags = kernel.Pixel(pixel, &result.radiance.pixels[pixel * channels]);
          if (flags != 0) result.mask.pixels[pixel] = 0.0f;
          row_saturated += flags & 1;
          row_black += (flags >> 1) & 1;
        }
        saturated += row_saturated;
        black += row_black;
      },
      options.num_threads, 8);
  result.saturated_pixels = saturated;
  result.black_pixels = black;
  result.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  spdlog::debug("merge: {}x{}x{}, {} images, {} weights, {:.3f} s", width, height, channels,
                images.size(), options.weighting, result.seconds);
  return result;
}

}  // namespace igi::hdr
