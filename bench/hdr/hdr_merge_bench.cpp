// igi-hdr's merge against OpenCV's MergeDebevec (and response recovery against
// CalibrateDebevec) on Debevec's 16 Memorial images (512x768), in one process, with the same
// number of threads. Images are decoded once before timing (igi: float levels, OpenCV: 8-bit
// Mats, each library's own input form); the timed work is the merge alone, the median of
// `repeats` runs. Prints the times and the ratios.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/photo.hpp>
#include <string>
#include <vector>

#include "calib/bracket.h"
#include "calib/response_recovery.h"
#include "hdr/merge.h"
#include "tools/common/parallel.h"

namespace {

double MedianSeconds(int repeats, const std::function<void()>& work) {
  std::vector<double> times;
  for (int r = 0; r < repeats; ++r) {
    const auto start = std::chrono::steady_clock::now();
    work();
    times.push_back(
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  std::sort(times.begin(), times.end());
  return times[times.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  int threads = 2, repeats = 15;
  for (int i = 1; i + 1 < argc; ++i) {
    if (std::strcmp(argv[i], "--threads") == 0) threads = std::atoi(argv[i + 1]);
    if (std::strcmp(argv[i], "--repeats") == 0) repeats = std::atoi(argv[i + 1]);
  }
  igi::SetDefaultThreads(threads);
  cv::setNumThreads(threads);
  const std::string dir = std::string(IGI_SHARED_DATA_DIR) + "/real/memorial/";
  std::vector<std::filesystem::path> paths;
  std::vector<cv::Mat> mats;
  for (int i = 61; i <= 76; ++i) {
    paths.push_back(dir + "memorial00" + std::to_string(i) + ".png");
    mats.push_back(cv::imread(paths.back().string(), cv::IMREAD_COLOR));
  }
  igi::calib::ExposureSource source;
  source.file = dir + "shutter_times.txt";
  const igi::calib::Bracket bracket = igi::calib::LoadBracket(paths, source);
  std::vector<float> times(bracket.exposures_s.begin(), bracket.exposures_s.end());

  igi::calib::ResponseCurve response;
  const double igi_calib_s =
      MedianSeconds(3, [&] { response = igi::calib::RecoverResponse(bracket, {}).curve; });
  cv::Mat cv_response;
  const double cv_calib_s =
      MedianSeconds(3, [&] { cv::createCalibrateDebevec()->process(mats, cv_response, times); });

  igi::hdr::MergeOptions noise;
  noise.num_threads = threads;
  igi::hdr::MergeOptions hat = noise;
  hat.weighting = igi::hdr::MergeWeighting::kHat;
  cv::Ptr<cv::MergeDebevec> merge = cv::createMergeDebevec();
  cv::Mat hdr;
  // Interleaved: each repeat times OpenCV, igi noise-aware and igi hat back to back, so a busy
  // machine slows all three alike; the ratios are medians of per-repeat ratios.
  std::vector<double> cv_s, noise_s, hat_s, noise_ratio, hat_ratio;
  for (int r = 0; r < repeats; ++r) {
    cv_s.push_back(MedianSeconds(1, [&] { merge->process(mats, hdr, times, cv_response); }));
    noise_s.push_back(MedianSeconds(
        1, [&] { igi::hdr::MergeBracket(bracket.images, bracket.exposures_s, response, noise); }));
    hat_s.push_back(MedianSeconds(
        1, [&] { igi::hdr::MergeBracket(bracket.images, bracket.exposures_s, response, hat); }));
    noise_ratio.push_back(cv_s.back() / noise_s.back());
    hat_ratio.push_back(cv_s.back() / hat_s.back());
  }
  const auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
  };
  const double cv_merge_s = median(cv_s), igi_noise_s = median(noise_s), igi_hat_s = median(hat_s);

  std::printf("HDR merge, 16 x 512x768 8-bit RGB (Memorial), %d threads, median of %d runs\n",
              threads, repeats);
  std::printf("  OpenCV MergeDebevec          %8.1f ms\n", 1e3 * cv_merge_s);
  std::printf("  igi merge, noise-aware       %8.1f ms   %.2fx faster\n", 1e3 * igi_noise_s,
              median(noise_ratio));
  std::printf("  igi merge, hat (Debevec)     %8.1f ms   %.2fx faster\n", 1e3 * igi_hat_s,
              median(hat_ratio));
  std::printf("Response recovery, median of 3\n");
  std::printf("  OpenCV CalibrateDebevec (70 samples)     %8.1f ms\n", 1e3 * cv_calib_s);
  std::printf("  igi Debevec (%d samples, Schur + LDLT)  %8.1f ms   %.2fx\n", 100,
              1e3 * igi_calib_s, cv_calib_s / igi_calib_s);
  return 0;
}
