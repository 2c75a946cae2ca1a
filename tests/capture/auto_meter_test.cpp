// --auto on synthetic scenes with known truth: a linear 12-bit sensor viewing a
// scene whose radiances span a known range, so the right shortest and longest
// exposures are known.
#include "capture/auto_meter.h"

#include <gtest/gtest.h>

#include <cmath>

namespace igi::capture {
namespace {

// Scene: radiances log-uniform in [dark, bright]; level = radiance *
// exposure_us, clipped at 1.
struct LinearScene {
  double dark = 1e-6;  // full scale per µs at the darkest pixel
  double bright = 1e-3;
  int samples = 4096;
  Frame Take(double exposure_us) const {
    Frame frame;
    frame.width = samples;
    frame.height = 1;
    frame.format = {"Mono12", 1, 12, 2, false};
    std::vector<uint16_t> levels;
    for (int i = 0; i < samples; ++i) {
      const double radiance = dark * std::pow(bright / dark, double(i) / (samples - 1));
      const double level = std::min(1.0, radiance * exposure_us);
      levels.push_back(uint16_t(std::lround(level * 4095)));
    }
    frame.SetLevels(levels);
    return frame;
  }
};

TEST(ReadMeter, ReadsPercentilesAsFractionsOfFullScale) {
  Frame frame;
  frame.width = 100;
  frame.height = 1;
  frame.format = {"Mono8", 1, 8, 1, false};
  std::vector<uint16_t> levels;
  for (int i = 0; i < 100; ++i) levels.push_back(uint16_t(i));
  frame.SetLevels(levels);
  AutoMeterOptions options;
  options.highlight_percentile = 90;
  options.shadow_percentile = 10;
  const MeterReading reading = ReadMeter(frame, options);
  EXPECT_DOUBLE_EQ(reading.highlight, 90.0 / 255.0);
  EXPECT_DOUBLE_EQ(reading.shadow, 10.0 / 255.0);
}

TEST(ChooseExposures, CoversHighlightsAndShadowsOfALinearScene) {
  const LinearScene scene;  // 10 stops of scene range
  AutoMeterOptions options;
  int frames = 0;
  auto measure = [&](double exposure_us) {
    ++frames;
    return ReadMeter(scene.Take(exposure_us), options);
  };
  const AutoMeterReport report = ChooseExposures(measure, 10, 1e7, 10000, options);
  ASSERT_TRUE(report.highlights_covered);
  ASSERT_TRUE(report.shadows_covered);
  EXPECT_EQ(report.frames_metered, frames);
  // Highlight percentile radiance r_h: the shortest exposure puts it at or
  // under the target, within a quarter stop (the stopping rule), so r_h * e in
  // [0.84, 1] * target (± a level).
  const double r_high = scene.dark * std::pow(scene.bright / scene.dark, 0.995);
  const double high = r_high * report.shortest_us;
  EXPECT_LE(high, options.highlight_target + 1.0 / 4095);
  EXPECT_GE(high, 0.84 * options.highlight_target - 1.0 / 4095);
  // Shadow percentile radiance r_s reaches the target at the longest exposure.
  const double r_low = scene.dark * std::pow(scene.bright / scene.dark, 0.02);
  EXPECT_GE(r_low * report.longest_us, options.shadow_target - 1.0 / 4095);
  // 2-stop steps from the shortest up to (at least) the longest.
  ASSERT_GE(report.exposures_us.size(), 2u);
  for (size_t i = 1; i < report.exposures_us.size(); ++i) {
    EXPECT_NEAR(std::log2(report.exposures_us[i] / report.exposures_us[i - 1]), 2.0, 1e-9);
  }
  EXPECT_GE(report.exposures_us.back(), report.longest_us * (1 - 1e-9));
  EXPECT_LT(report.exposures_us.back(), report.longest_us * 4);
}

TEST(ChooseExposures, ReportsHighlightsThatClipAtTheShortestExposure) {
  LinearScene scene;
  scene.bright = 10.0;  // clips at 1 µs already
  scene.dark = 1e-3;
  AutoMeterOptions options;
  auto measure = [&](double e) { return ReadMeter(scene.Take(e), options); };
  const AutoMeterReport report = ChooseExposures(measure, 10, 1e7, 1000, options);
  EXPECT_FALSE(report.highlights_covered);
  EXPECT_DOUBLE_EQ(report.shortest_us, 10.0);
  EXPECT_FALSE(report.notes.empty());
}

TEST(ChooseExposures, StopsAtTheLongestAllowedExposure) {
  LinearScene scene;
  scene.dark = 1e-12;  // shadows out of reach
  AutoMeterOptions options;
  options.max_exposure_us = 1e5;
  auto measure = [&](double e) { return ReadMeter(scene.Take(e), options); };
  const AutoMeterReport report = ChooseExposures(measure, 10, 1e7, 1000, options);
  EXPECT_TRUE(report.highlights_covered);
  EXPECT_FALSE(report.shadows_covered);
  EXPECT_DOUBLE_EQ(report.exposures_us.back(), 1e5);
  EXPECT_FALSE(report.notes.empty());
}

TEST(AutoMeterOptions, RejectsBadValues) {
  AutoMeterOptions options;
  options.stop_spacing = 0;
  EXPECT_THROW(options.Validate(), InputError);
  options = {};
  options.shadow_target = 0.9;
  EXPECT_THROW(options.Validate(), InputError);
}

}  // namespace
}  // namespace igi::capture
