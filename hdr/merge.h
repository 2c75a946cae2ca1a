#pragma once
// Merges an exposure bracket into a linear radiance map.
//
// Each value z of image j (exposure t_j) gives a radiance estimate x = I(z) / t_j, where
// I(z) = exp(g(z)) is the inverse response (calib/response_curve.h). The estimates of a pixel are
// averaged with weights (MergeWeighting):
// - "noise" (default): inverse variance, w = t_j^2 / var(I(z)), with the variance of a sensor
//   with shot noise, read noise and the quantisation of the levels mapped through the response:
//   var = shot_noise * I + read_noise^2 + (I'(z) / 2^bits)^2 / 12, I in units of full scale
//   (I(top level) = 1). This is Granados et al. (CVPR 2010) / Hasinoff et al. (CVPR 2010).
//   The variance is evaluated at the measured value, through a lookup table per level.
// - "hat": Debevec & Malik's merge, ln E = sum w(z) (g(z) - ln t) / sum w(z) with the hat w.
// Values at or below `black` or at or above `saturated` (normalised) get no weight. A pixel
// with no usable value in a channel is saturated (in the shortest exposure) or black (in the
// longest) everywhere: it gets the bound that exposure gives (I(z) / t) and is masked.
//
// The output is linear radiance in the response's units (exp(g) per second): relative, not
// absolute. Work is a per-pixel loop over lookup tables, parallel over rows (ParallelFor), with
// an igi::Progress bar over the rows (drawn on a terminal once a merge runs past ~2 s).
// Each pixel's result depends only on that pixel's values, so a merge band by band (BandMerger,
// hdr/merge_stream.h) gives bit-identical values to a merge of the whole images.

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "calib/response_curve.h"
#include "tools/common/image.h"
#include "tools/common/progress.h"

namespace igi::hdr {

// The weights of a merge (see the top of this file): kNoise, inverse variance; kHat, Debevec &
// Malik's hat.
enum class MergeWeighting { kNoise, kHat };
// "noise", "hat" (the --weighting flag's spelling and the radiance map's igi:weighting).
std::string_view MergeWeightingName(MergeWeighting weighting);
std::optional<MergeWeighting> MergeWeightingFromName(std::string_view name);

struct MergeOptions {
  MergeWeighting weighting = MergeWeighting::kNoise;  // kNoise (default) or kHat
  double black = 0.02;             // normalised value at or below which a value is unusable
  double saturated = 0.98;         // normalised value at or above which a value is unusable
  double shot_noise = 1.0 / 4000;  // variance per unit signal (1 / full well in electrons)
  double read_noise = 1.0 / 2000;  // standard deviation, units of full scale
  // One weight per pixel and exposure, the mean of the channels' weights (as OpenCV's
  // MergeDebevec does), instead of one per channel.
  bool shared_weights = false;
  int bits = 8;         // quantisation of the input levels (8 or 16)
  int num_threads = 0;  // 0 = the process default

  // Throws InputError "option: VALUE: RULE".
  void Validate() const;
};

struct MergeResult {
  Image radiance;  // linear radiance, float, channels of the input
  Image mask;      // 1 channel: 1 = good, 0 = saturated or black in every exposure (any channel)
  int64_t saturated_pixels = 0;  // pixels saturated in every exposure (in some channel)
  int64_t black_pixels = 0;      // pixels black in every exposure (in some channel)
  double seconds = 0.0;          // wall time of the merge
};

// `images` are normalised levels in [0, 1] (8- or 16-bit files, or linear raw data scaled so
// that the white level is 1), all of one size and channel count; `exposures_s` their times.
// The response must have one curve per channel (or one, used for all). Throws InputError on a
// mismatch between images, exposures and response.
MergeResult MergeBracket(const std::vector<Image>& images, const std::vector<double>& exposures_s,
                         const calib::ResponseCurve& response, const MergeOptions& options);

// The merge of bands of rows: the lookup tables are built once for a bracket, then any number of
// bands (the same rows of every image) are merged. MergeBracket is one band of the whole height.
class BandMerger {
 public:
  struct Counts {
    int64_t saturated_pixels = 0;  // pixels saturated in every exposure (in some channel)
    int64_t black_pixels = 0;      // pixels black in every exposure (in some channel)
  };

  // Throws InputError on bad options, more than 8 channels, or a response with neither 1 curve
  // nor `channels` curves.
  BandMerger(int channels, const std::vector<double>& exposures_s,
             const calib::ResponseCurve& response, const MergeOptions& options);
  ~BandMerger();
  BandMerger(const BandMerger&) = delete;
  BandMerger& operator=(const BandMerger&) = delete;

  // `bands[j]` holds `rows` rows of `width` pixels of exposure j (normalised levels, channels
  // interleaved). Writes linear radiance (rows x width x channels values) to `radiance` and the
  // mask (rows x width values, 1 = good, 0 = bad) to `mask`; `progress` (optional) gets the rows.
  Counts Merge(const std::vector<const float*>& bands, int width, int rows, float* radiance,
               float* mask, Progress* progress = nullptr) const;

  int channels() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace igi::hdr
