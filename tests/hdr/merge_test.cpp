// Merging on synthetic brackets with known radiance (1 % recovery, noise-aware beats hat) and
// on the real Memorial bracket against OpenCV's MergeDebevec.
#include "hdr/merge.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/photo.hpp>

#include "calib/bracket.h"
#include "calib/response_recovery.h"
#include "tests/calib/memorial_bracket.h"
#include "tests/calib/synthetic_bracket.h"
#include "tools/common/error.h"

namespace igi::hdr {
namespace {

// OpenCV's response (a 256 x 1 CV_32FC3 matrix of exposures, BGR) as igi's curve.
calib::ResponseCurve OpenCvCurve(const cv::Mat& response) {
  calib::ResponseCurve curve;
  curve.levels = 256;
  curve.channels = {"R", "G", "B"};
  curve.g.assign(3, std::vector<double>(256));
  for (int c = 0; c < 3; ++c) {
    for (int z = 0; z < 256; ++z)
      curve.g[size_t(c)][size_t(z)] = std::log(response.at<cv::Vec3f>(z)[2 - c]);
  }
  return curve;
}

double Median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + long(v.size() / 2), v.end());
  return v[v.size() / 2];
}

// The true response as a curve with `levels` levels.
calib::ResponseCurve TrueResponse(int levels) {
  calib::ResponseCurve curve;
  curve.levels = levels;
  curve.channels = {"R", "G", "B"};
  std::vector<double> g(static_cast<size_t>(levels));
  for (int z = 0; z < levels; ++z) {
    g[size_t(z)] = testing::SyntheticLnExposure(std::max(double(z), 0.5) / (levels - 1));
  }
  curve.g.assign(3, g);
  return curve;
}

struct Errors {
  double rms = 0.0;             // per-pixel relative error, free scale removed
  double worst_bin_bias = 0.0;  // largest |median ratio - 1| over half-decade radiance bins
};

Errors Compare(const Image& radiance, const std::vector<double>& truth) {
  std::vector<double> ratio(truth.size());
  for (size_t i = 0; i < truth.size(); ++i) ratio[i] = radiance.pixels[i] / truth[i];
  const double scale = Median(ratio);
  Errors e;
  double sum = 0.0;
  std::vector<std::vector<double>> bins(16);
  for (size_t i = 0; i < truth.size(); ++i) {
    const double r = ratio[i] / scale;
    sum += (r - 1.0) * (r - 1.0);
    bins[size_t(std::clamp(int(2.0 * std::log10(truth[i] / 0.01)), 0, 15))].push_back(r);
  }
  e.rms = std::sqrt(sum / truth.size());
  for (const auto& bin : bins) {
    if (bin.size() > 500) e.worst_bin_bias = std::max(e.worst_bin_bias, std::abs(Median(bin) - 1));
  }
  return e;
}

// The whole radiance range of the scene (0.02 x 0.8 x 0.6 .. 30 x 1.25) is well exposed (1 % .. 50
// % of full scale) in at least one exposure of the x4 bracket, so every pixel counts. Per-pixel
// noise (shot noise of a 20000 e- sensor, ~0.5 % after merging) is in the RMS; the recovery claim
// is on the bias: the median ratio in each half-decade of radiance within 1 %.
TEST(Merge, RecoversKnownRadianceWithin1PercentWithRecoveredResponse) {
  testing::SyntheticOptions o;
  o.max_radiance = 30;  // brightest tile x ramp x 1/64 s stays below full scale
  const testing::SyntheticBracket s = testing::MakeSyntheticBracket(o);
  calib::ResponseOptions response_options;
  response_options.lambda = 300;
  response_options.samples = 1000;
  const calib::ResponseCurve response = calib::RecoverResponse(s.bracket, response_options).curve;
  MergeOptions options;
  options.shot_noise = 1.0 / 20000;
  options.read_noise = 5.0 / 20000;
  const MergeResult result =
      MergeBracket(s.bracket.images, s.bracket.exposures_s, response, options);
  const Errors e = Compare(result.radiance, s.radiance);
  std::printf("recovered response, noise-aware merge: bias %.3f %%, rms %.3f %%\n",
              100 * e.worst_bin_bias, 100 * e.rms);
  EXPECT_LT(e.worst_bin_bias, 0.01);
  EXPECT_LT(e.rms, 0.02);
  EXPECT_EQ(result.saturated_pixels, 0);
  EXPECT_EQ(result.black_pixels, 0);
}

// A noisier sensor (5000 e- full well, 10 e- read noise): inverse-variance weights lean on the
// longer exposures (t^2 / variance), the hat treats a short, noisy exposure like a long one.
TEST(Merge, NoiseAwareWeightsBeatTheHat) {
  testing::SyntheticOptions o;
  o.full_well = 5000;
  o.read_noise = 10;
  const testing::SyntheticBracket s = testing::MakeSyntheticBracket(o);
  const calib::ResponseCurve response = TrueResponse(256);
  MergeOptions noise;
  noise.shot_noise = 1.0 / 5000;
  noise.read_noise = 10.0 / 5000;
  MergeOptions hat = noise;
  hat.weighting = MergeWeighting::kHat;
  const Errors e_noise = Compare(
      MergeBracket(s.bracket.images, s.bracket.exposures_s, response, noise).radiance, s.radiance);
  const Errors e_hat = Compare(
      MergeBracket(s.bracket.images, s.bracket.exposures_s, response, hat).radiance, s.radiance);
  std::printf("rms error: noise-aware %.3f %%, hat %.3f %%\n", 100 * e_noise.rms, 100 * e_hat.rms);
  EXPECT_LT(e_noise.rms, 0.85 * e_hat.rms);
}

TEST(Merge, MasksPixelsSaturatedOrBlackInEveryExposure) {
  // Two exposures; pixel 0 saturated in both, pixel 1 black in both, pixel 2 fine.
  Image a(3, 1, 1), b(3, 1, 1);
  a.pixels = {1.0f, 0.0f, 0.25f};
  b.pixels = {1.0f, 0.0f, 0.5f};
  const calib::ResponseCurve linear = calib::LinearResponse(256, 1);
  const MergeResult r = MergeBracket({a, b}, {1.0, 2.0}, linear, {});
  EXPECT_EQ(r.saturated_pixels, 1);
  EXPECT_EQ(r.black_pixels, 1);
  EXPECT_EQ(r.mask.pixels, (std::vector<float>{0.0f, 0.0f, 1.0f}));
  EXPECT_NEAR(r.radiance.pixels[0], 1.0, 1e-5);   // the bound from the shortest exposure
  EXPECT_NEAR(r.radiance.pixels[2], 0.25, 1e-3);  // 0.25 / 1 and 0.5 / 2 agree
}

TEST(Merge, RejectsMismatchedInputs) {
  Image a(3, 1, 1), b(2, 1, 1);
  const calib::ResponseCurve linear = calib::LinearResponse(256, 1);
  EXPECT_THROW(MergeBracket({a, b}, {1.0, 2.0}, linear, {}), InputError);
  EXPECT_THROW(MergeBracket({a}, {1.0, 2.0}, linear, {}), InputError);
  MergeOptions bad;
  bad.weighting = static_cast<MergeWeighting>(7);  // no such weighting
  EXPECT_THROW(bad.Validate(), InputError);
}

TEST(Merge, WeightingNamesRoundTripAndOthersAreRejected) {
  for (MergeWeighting w : {MergeWeighting::kNoise, MergeWeighting::kHat}) {
    EXPECT_EQ(MergeWeightingFromName(MergeWeightingName(w)), w);
  }
  EXPECT_EQ(MergeWeightingName(MergeWeighting::kHat), "hat");
  EXPECT_FALSE(MergeWeightingFromName("box"));
}

// Memorial: igi's hat merge against cv::MergeDebevec, both with OpenCV's CalibrateDebevec
// response, so only the merges differ. Ratios after the free scale (per channel: Debevec–Malik
// fix g(128) = 0 in each).
TEST(Merge, MemorialAgreesWithOpenCvMergeDebevec) {
  const testing::MemorialBracket m = testing::LoadMemorial();
  cv::Mat cv_response, cv_hdr;
  cv::createCalibrateDebevec(200, 50.0f, false)->process(m.mats, cv_response, m.times_s);
  cv::createMergeDebevec()->process(m.mats, cv_hdr, m.times_s, cv_response);
  MergeOptions hat;
  hat.weighting = MergeWeighting::kHat;
  hat.black = 0.0;
  hat.saturated = 1.0;
  hat.shared_weights = true;  // as MergeDebevec: one weight per pixel, the channels' mean
  const Image merged =
      MergeBracket(m.bracket.images, m.bracket.exposures_s, OpenCvCurve(cv_response), hat).radiance;
  std::vector<double> deviation;
  for (int c = 0; c < 3; ++c) {
    std::vector<double> ratio;
    for (int y = 0; y < merged.height; ++y) {
      for (int x = 0; x < merged.width; ++x) {
        ratio.push_back(merged.at(x, y, c) / cv_hdr.at<cv::Vec3f>(y, x)[2 - c]);
      }
    }
    const double scale = Median(ratio);
    for (double r : ratio) deviation.push_back(std::abs(r / scale - 1.0));
  }
  std::sort(deviation.begin(), deviation.end());
  const double median = deviation[deviation.size() / 2];
  const double p95 = deviation[size_t(0.95 * deviation.size())];
  std::printf("memorial vs MergeDebevec (OpenCV's response): median %.3f %%, p95 %.3f %%\n",
              100 * median, 100 * p95);
  EXPECT_LT(median, 0.001);
  EXPECT_LT(p95, 0.05);
}

// Memorial, without a ground truth: the odd and the even exposures (two independent brackets,
// 2 stops apart each) merged apart must give the same radiance. igi (its response, default
// options, and its noise-aware merge) against OpenCV (CalibrateDebevec and MergeDebevec, their
// defaults): the median |ln(odd / even)| over pixels and channels. Measured: igi 0.052, OpenCV
// 0.126. igi's and OpenCV's full merges differ by a median 17 % (scale removed); with the same
// curve the two merges agree to 0.002 % (above), so that difference is the curves'.
TEST(Merge, MemorialHalfBracketsAgreeBetterThanOpenCvs) {
  const testing::MemorialBracket m = testing::LoadMemorial();
  const calib::ResponseCurve ours =
      calib::RecoverResponse(m.bracket, calib::ResponseOptions()).curve;
  cv::Mat cv_response;
  cv::createCalibrateDebevec()->process(m.mats, cv_response, m.times_s);
  std::vector<double> ours_ln[2], theirs_ln[2];
  for (int half = 0; half < 2; ++half) {
    std::vector<Image> images;
    std::vector<double> exposures_s;
    std::vector<cv::Mat> mats;
    std::vector<float> times_s;
    for (size_t j = size_t(half); j < m.mats.size(); j += 2) {
      images.push_back(m.bracket.images[j]);
      exposures_s.push_back(m.bracket.exposures_s[j]);
      mats.push_back(m.mats[j]);
      times_s.push_back(m.times_s[j]);
    }
    const Image merged = MergeBracket(images, exposures_s, ours, MergeOptions()).radiance;
    cv::Mat cv_hdr;
    cv::createMergeDebevec()->process(mats, cv_hdr, times_s, cv_response);
    for (int y = 0; y < merged.height; ++y) {
      for (int x = 0; x < merged.width; ++x) {
        for (int c = 0; c < 3; ++c) {
          ours_ln[half].push_back(std::log(std::max(merged.at(x, y, c), 1e-30f)));
          theirs_ln[half].push_back(std::log(std::max(cv_hdr.at<cv::Vec3f>(y, x)[2 - c], 1e-30f)));
        }
      }
    }
  }
  const auto median_difference = [](const std::vector<double>* ln) {
    std::vector<double> d;
    for (size_t i = 0; i < ln[0].size(); ++i) d.push_back(std::abs(ln[0][i] - ln[1][i]));
    return Median(d);
  };
  const double our_difference = median_difference(ours_ln);
  const double their_difference = median_difference(theirs_ln);
  std::printf("memorial odd vs even exposures merged: median |ln ratio| igi %.4f, OpenCV %.4f\n",
              our_difference, their_difference);
  EXPECT_LT(our_difference, 0.6 * their_difference);
}

}  // namespace
}  // namespace igi::hdr
