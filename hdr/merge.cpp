#include "hdr/merge.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>

#include "tools/common/enum_names.h"
#include "tools/common/error.h"
#include "tools/common/parallel.h"
#include "tools/common/progress.h"

namespace igi::hdr {
namespace {

// Lookup tables of one channel, indexed by the quantised level q in [0, 2^bits).
struct ChannelTables {
  std::vector<float> lin;     // I(q) = exp(g(q)), response units
  std::vector<float> ln;      // g(q)
  std::vector<float> weight;  // 0 where unusable
  // {w * x, w} with x = I(q) (noise) or g(q) (hat): one load per sample in the hot loop.
  std::vector<std::array<float, 2>> weighted;
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
    if (options.weighting == MergeWeighting::kHat) {
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
  t.weighted.resize(size_t(levels));
  const bool hat = options.weighting == MergeWeighting::kHat;
  for (size_t q = 0; q < size_t(levels); ++q) {
    t.weighted[q] = {t.weight[q] * (hat ? t.ln[q] : t.lin[q]), t.weight[q]};
  }
  return t;
}

void CheckInputs(const std::vector<Image>& images, const std::vector<double>& exposures_s,
                 const calib::ResponseCurve& response) {
  if (images.size() < 1 || images.size() != exposures_s.size()) {
    throw InputError(DescribeProblem(
        "bracket", "images", fmt::format("{}", images.size()),
        fmt::format("need one exposure time per image ({} given)", exposures_s.size())));
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

constexpr EnumNames<MergeWeighting, 2> kMergeWeightingNames{
    {{MergeWeighting::kNoise, "noise"}, {MergeWeighting::kHat, "hat"}}};

std::string_view MergeWeightingName(MergeWeighting weighting) {
  return kMergeWeightingNames.Name(weighting);
}
std::optional<MergeWeighting> MergeWeightingFromName(std::string_view name) {
  return kMergeWeightingNames.FromName(name);
}

void MergeOptions::Validate() const {
  ProblemList problems;
  if (!MergeWeightingFromName(MergeWeightingName(weighting))) {
    problems.Add("--weighting", "", std::to_string(int(weighting)), "must be noise or hat");
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
// `src[j]` points at the values of exposure j that the value indices below address.
class MergeKernel {
 public:
  MergeKernel(int channels, const std::vector<double>& exposures_s,
              const calib::ResponseCurve& response, const MergeOptions& options)
      : options_(options),
        levels_(1 << options.bits),
        channels_(channels),
        scale_(float(levels_ - 1)),
        hat_(options.weighting == MergeWeighting::kHat) {
    for (int c = 0; c < channels_; ++c) {
      tables_.push_back(
          BuildTables(response, response.num_channels() == 1 ? 0 : c, levels_, options));
    }
    shortest_ =
        size_t(std::min_element(exposures_s.begin(), exposures_s.end()) - exposures_s.begin());
    longest_ =
        size_t(std::max_element(exposures_s.begin(), exposures_s.end()) - exposures_s.begin());
    for (size_t j = 0; j < exposures_s.size(); ++j) {
      const float t = float(exposures_s[j]);
      t_.push_back(t);
      a_.push_back(hat_ ? 1.0f : t);
      b_.push_back(hat_ ? -float(std::log(exposures_s[j])) : 0.0f);
      c_.push_back(hat_ ? 1.0f : t * t);
    }
  }

  size_t exposures() const { return t_.size(); }
  int channels() const { return channels_; }
  bool shared_weights() const { return options_.shared_weights; }
  int num_threads() const { return options_.num_threads; }

  // Merges pixel `pixel` into `out` (channels_ values); returns bit 1 = saturated, 2 = black.
  // Every sample adds a_j * (w x) + b_j * w to the numerator and c_j * w to the denominator:
  // noise a = t, b = 0, c = t^2 (then E = num / den); hat a = 1, b = -ln t, c = 1
  // (then E = exp(num / den)). kChannels = 0: any count (runtime).
  template <int kChannels>
  int Pixel(const float* const* src, size_t pixel, float* out) const {
    constexpr int kMaxChannels = 8;
    const int channels = kChannels > 0 ? kChannels : channels_;
    float num[kMaxChannels] = {}, den[kMaxChannels] = {};
    const size_t base = pixel * size_t(channels);
    const size_t p = t_.size();
    if (options_.shared_weights) {
      SharedWeightSums(src, base, num, den);
    } else {
      for (size_t j = 0; j < p; ++j) {
        const float* values = src[j] + base;
        for (int c = 0; c < channels; ++c) {
          const std::array<float, 2>& wx = tables_[size_t(c)].weighted[size_t(Level(values[c]))];
          num[c] += a_[j] * wx[0] + b_[j] * wx[1];
          den[c] += c_[j] * wx[1];
        }
      }
    }
    int flags = 0;
    for (int c = 0; c < channels; ++c) {
      if (den[c] > 0.0f) {
        out[c] = hat_ ? std::exp(num[c] / den[c]) : num[c] / den[c];
        continue;
      }
      // No usable value: saturated (judged on the shortest exposure) or black everywhere.
      const int q_short = Level(src[shortest_][base + size_t(c)]);
      const bool saturated = double(q_short) / (levels_ - 1) >= options_.saturated;
      const size_t j = saturated ? shortest_ : longest_;
      out[c] = tables_[size_t(c)].lin[size_t(Level(src[j][base + size_t(c)]))] / t_[j];
      flags |= saturated ? 1 : 2;
    }
    return flags;
  }

  // Merges `count` consecutive values (whole pixels) starting at value index `begin`, image by
  // image so that each image is read as one sequential stream. `num`/`den` are scratch of size
  // `count`. Fills out[begin .. begin + count) and returns per-pixel flags in `flags`.
  void Span(const float* const* src, size_t begin, size_t count, float* num, float* den, float* out,
            uint8_t* flags) const {
    std::fill(num, num + count, 0.0f);
    std::fill(den, den + count, 0.0f);
    const size_t channels = size_t(channels_);
    for (size_t j = 0; j < t_.size(); ++j) {
      if (channels == 3) {
        Accumulate<3>(src[j], j, begin, count, num, den);
      } else if (channels == 1) {
        Accumulate<1>(src[j], j, begin, count, num, den);
      } else {
        Accumulate<0>(src[j], j, begin, count, num, den);
      }
    }
    for (size_t i = 0; i < count; i += channels) {
      uint8_t f = 0;
      for (size_t k = 0; k < channels; ++k) {
        const size_t v = i + k;
        if (den[v] > 0.0f) {
          out[begin + v] = hat_ ? std::exp(num[v] / den[v]) : num[v] / den[v];
          continue;
        }
        const int q_short = Level(src[shortest_][begin + v]);
        const bool saturated = double(q_short) / (levels_ - 1) >= options_.saturated;
        const size_t j = saturated ? shortest_ : longest_;
        out[begin + v] = tables_[k].lin[size_t(Level(src[j][begin + v]))] / t_[j];
        f |= saturated ? 1 : 2;
      }
      flags[i / channels] = f;
    }
  }

 private:
  // Adds image j's samples (at `image`) of values [begin, begin + count) to num and den (the hot
  // loop).
  template <int kChannels>
  void Accumulate(const float* image, size_t j, size_t begin, size_t count, float* num,
                  float* den) const {
    const size_t channels = kChannels > 0 ? size_t(kChannels) : size_t(channels_);
    constexpr int kMaxChannels = 8;
    const std::array<float, 2>* tab[kMaxChannels];
    for (size_t k = 0; k < channels; ++k) tab[k] = tables_[k].weighted.data();
    const float* src = image + begin;
    const float a = a_[j], b = b_[j], c = c_[j];
    const int top = levels_ - 1;
    for (size_t i = 0; i < count; i += channels) {
      for (size_t k = 0; k < channels; ++k) {
        const int q = std::min(std::max(int(src[i + k] * scale_ + 0.5f), 0), top);
        const std::array<float, 2> wx = tab[k][q];
        num[i + k] += a * wx[0] + b * wx[1];
        den[i + k] += c * wx[1];
      }
    }
  }

  // The sums with one weight per sample shared by the channels (their mean), as MergeDebevec.
  void SharedWeightSums(const float* const* src, size_t base, float* num, float* den) const {
    for (size_t j = 0; j < t_.size(); ++j) {
      float w = 0.0f;
      for (int c = 0; c < channels_; ++c) {
        w += tables_[size_t(c)].weight[size_t(Level(src[j][base + size_t(c)]))];
      }
      w /= float(channels_);
      for (int c = 0; c < channels_; ++c) {
        const ChannelTables& tab = tables_[size_t(c)];
        const size_t q = size_t(Level(src[j][base + size_t(c)]));
        num[c] += a_[j] * w * (hat_ ? tab.ln[q] : tab.lin[q]) + b_[j] * w;
        den[c] += c_[j] * w;
      }
    }
  }

  int Level(float v) const { return std::clamp(int(v * scale_ + 0.5f), 0, levels_ - 1); }

  const MergeOptions options_;
  int levels_;
  int channels_;
  float scale_;
  bool hat_;
  std::vector<ChannelTables> tables_;
  size_t shortest_ = 0, longest_ = 0;
  std::vector<float> t_, a_, b_, c_;
};

}  // namespace

struct BandMerger::Impl {
  MergeKernel kernel;
};

BandMerger::BandMerger(int channels, const std::vector<double>& exposures_s,
                       const calib::ResponseCurve& response, const MergeOptions& options) {
  options.Validate();
  if (channels < 1 || channels > 8) {
    throw InputError(DescribeProblem("bracket", "channels", fmt::format("{}", channels),
                                     "need 1 to 8 channels"));
  }
  if (exposures_s.empty()) {
    throw InputError(DescribeProblem("bracket", "images", "0", "need at least one exposure"));
  }
  if (response.num_channels() != 1 && response.num_channels() != channels) {
    throw InputError(
        DescribeProblem("response", "channels", fmt::format("{}", response.num_channels()),
                        fmt::format("must be 1 or the images' channel count ({})", channels)));
  }
  impl_ = std::make_unique<Impl>(Impl{MergeKernel(channels, exposures_s, response, options)});
}

BandMerger::~BandMerger() = default;

int BandMerger::channels() const { return impl_->kernel.channels(); }

BandMerger::Counts BandMerger::Merge(const std::vector<const float*>& bands, int width, int rows,
                                     float* radiance, float* mask, Progress* progress) const {
  const MergeKernel& kernel = impl_->kernel;
  if (bands.size() != kernel.exposures()) {
    throw InputError(DescribeProblem("bracket", "images", fmt::format("{}", bands.size()),
                                     fmt::format("need {} exposures", kernel.exposures())));
  }
  const int channels = kernel.channels();
  const bool shared_weights = impl_->kernel.shared_weights();
  std::atomic<int64_t> saturated{0}, black{0};
  ParallelForRange(
      0, rows,
      [&](int64_t y0, int64_t y1) {
        int64_t row_saturated = 0, row_black = 0;
        const size_t row_values = size_t(width) * channels;
        std::vector<float> num(row_values), den(row_values);
        std::vector<uint8_t> flags(static_cast<size_t>(width));
        for (int64_t y = y0; y < y1; ++y) {
          const size_t first_pixel = size_t(y) * width;
          if (shared_weights) {
            for (int x = 0; x < width; ++x) {
              flags[size_t(x)] = uint8_t(kernel.Pixel<0>(bands.data(), first_pixel + x,
                                                         &radiance[(first_pixel + x) * channels]));
            }
          } else {
            kernel.Span(bands.data(), first_pixel * channels, row_values, num.data(), den.data(),
                        radiance, flags.data());
          }
          for (int x = 0; x < width; ++x) {
            mask[first_pixel + x] = flags[size_t(x)] != 0 ? 0.0f : 1.0f;
            row_saturated += flags[size_t(x)] & 1;
            row_black += (flags[size_t(x)] >> 1) & 1;
          }
        }
        saturated += row_saturated;
        black += row_black;
        if (progress != nullptr) progress->Add(y1 - y0);
      },
      impl_->kernel.num_threads(), 8);
  return {saturated, black};
}

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
  const BandMerger merger(channels, exposures_s, response, options);
  std::vector<const float*> src;
  for (const Image& image : images) src.push_back(image.pixels.data());
  MergeResult result;
  result.radiance = Image(width, height, channels);
  result.mask = Image(width, height, 1);
  Progress progress("merge rows", height);  // on a terminal, for merges longer than ~2 s
  const BandMerger::Counts counts = merger.Merge(src, width, height, result.radiance.pixels.data(),
                                                 result.mask.pixels.data(), &progress);
  progress.Finish();
  result.saturated_pixels = counts.saturated_pixels;
  result.black_pixels = counts.black_pixels;
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  spdlog::debug("merge: {}x{}x{}, {} images, {} weights, {:.3f} s", width, height, channels,
                images.size(), MergeWeightingName(options.weighting), result.seconds);
  return result;
}

}  // namespace igi::hdr
