// Sensor noise and LDR brackets of igi-synth (solver/synth/sensor.h).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "solver/synth/sensor.h"
#include "tools/common/json.h"

namespace igi::synth {
namespace {

Image Flat(int w, int h, float value) { return Image(w, h, 3, value); }

struct Stats {
  double mean = 0, variance = 0;
};

Stats ChannelStats(const Image& img, int channel) {
  double sum = 0, sum2 = 0;
  const size_t n = size_t(img.width) * img.height;
  for (size_t i = 0; i < n; ++i) {
    const double v = img.pixels[i * img.channels + channel];
    sum += v;
    sum2 += v * v;
  }
  const double mean = sum / n;
  return {mean, sum2 / n - mean * mean};
}

// A flat patch at several signal levels: mean and variance match the model. With n = 65536
// samples the sample mean's standard error is sqrt(var/n) (we allow 5 of them) and the sample
// variance's relative standard error is sqrt(2/n) ~ 0.55% (we allow 3%, covering also the
// Gaussian approximation of Poisson from 30 e- on).
TEST(SynthSensor, FlatPatchMeanAndVarianceMatchTheModel) {
  SensorOptions o;
  o.read_noise_e = 5;
  const double exposure_s = 0.01;
  for (double radiance : {0.5, 3.0, 50.0, 1500.0}) {  // 5, 30, 500, 15000 electrons
    const SensorResult r = SimulateSensor(Flat(256, 256, float(radiance)), o, exposure_s, 7);
    EXPECT_EQ(r.saturated_pixels, 0);
    const double expected_var = SensorVariance(radiance, o, exposure_s);
    for (int c = 0; c < 3; ++c) {
      const Stats s = ChannelStats(r.photo, c);
      EXPECT_NEAR(s.mean, radiance, 5 * std::sqrt(expected_var / 65536)) << radiance;
      EXPECT_NEAR(s.variance / expected_var, 1.0, 0.03) << radiance << " channel " << c;
    }
  }
}

TEST(SynthSensor, ShotNoiseDominatesAtHighSignal) {
  SensorOptions o;
  // 10000 e-: relative sigma ~ 1%.
  const double var = SensorVariance(1000.0, o, 0.01);
  EXPECT_NEAR(std::sqrt(var) / 1000.0, 0.01, 0.0005);
}

TEST(SynthSensor, SaturationIsClippedAndMasked) {
  SensorOptions o;
  Image img = Flat(16, 16, 10.0f);
  img.at(3, 4, 1) = 1e6f;  // far above the full well
  const SensorResult r = SimulateSensor(img, o, 0.01, 1);
  EXPECT_EQ(r.saturated_pixels, 1);
  EXPECT_EQ(r.mask.at(3, 4), 0.0f);
  EXPECT_EQ(r.mask.at(5, 5), 1.0f);
  EXPECT_NEAR(r.photo.at(3, 4, 1), o.full_well_e / (o.electrons_per_radiance_s * 0.01), 1e-3);
}

TEST(SynthSensor, DeterministicForASeed) {
  SensorOptions o;
  const Image img = Flat(32, 32, 2.0f);
  const auto a = SimulateSensor(img, o, 0.01, 42, 1);
  const auto b = SimulateSensor(img, o, 0.01, 42, 2);
  const auto c = SimulateSensor(img, o, 0.01, 43, 2);
  EXPECT_EQ(a.photo.pixels, b.photo.pixels);
  EXPECT_NE(a.photo.pixels, c.photo.pixels);
}

TEST(SynthSensor, AutoExposurePutsThe99thPercentileAt80PercentWell) {
  SensorOptions o;
  Image img = Flat(100, 100, 2.0f);
  const double t = ChooseExposure(img, o);
  EXPECT_NEAR(2.0 * o.electrons_per_radiance_s * t, 0.8 * o.full_well_e, 1e-6);
  o.exposure_s = 0.5;
  EXPECT_EQ(ChooseExposure(img, o), 0.5);
}

TEST(SynthResponse, InverseUndoesForward) {
  for (const ResponseCurve& r : {ResponseCurve::Gamma(2.2), ResponseCurve::Sigmoid(1.6, 0.18)}) {
    EXPECT_NEAR(r.Forward(0, 0), 0.0, 1e-12);
    EXPECT_NEAR(r.Forward(1, 0), 1.0, 1e-12);
    for (double x : {1e-4, 0.01, 0.1, 0.5, 0.9}) {
      EXPECT_NEAR(r.Inverse(r.Forward(x, 1), 1), x, 1e-9 * (1 + x)) << x;
      EXPECT_GT(r.Forward(x * 1.01, 0), r.Forward(x, 0));
    }
  }
}

// The curve written as an igi-response JSON reads back as a file response with the same shape
// (within the interpolation between 256 levels: 1 level = 0.4% of the range).
TEST(SynthResponse, ResponseJsonRoundTrip) {
  const ResponseCurve gamma = ResponseCurve::Gamma(2.2);
  const auto path = std::filesystem::temp_directory_path() / "igi_synth_response_test.json";
  WriteJsonFile(path, gamma.ToResponseJson(256));
  const ResponseCurve file = ResponseCurve::FromFile(path);
  for (double x : {0.01, 0.1, 0.3, 0.7}) {
    EXPECT_NEAR(file.Forward(x, 0), gamma.Forward(x, 0), 0.004) << x;
  }
  std::filesystem::remove(path);
}

// Noise-free brackets: invert the response, divide by the exposure, and get the radiance back
// (relative error bounded by 8-bit quantisation, checked only on well-exposed levels 20..235).
TEST(SynthBrackets, BracketsFollowTheResponseCurve) {
  SensorOptions sensor;
  BracketOptions b;
  b.count = 3;
  b.stops = 2;
  Image radiance(64, 1, 3);
  for (int x = 0; x < 64; ++x) {
    for (int c = 0; c < 3; ++c) radiance.at(x, 0, c) = float(0.5 * std::pow(1.12, x));
  }
  const ResponseCurve response = ResponseCurve::Gamma(2.2);
  const double mid = ChooseExposure(radiance, sensor);
  const auto brackets = MakeBrackets(radiance, sensor, b, response, mid, false, 3);
  ASSERT_EQ(brackets.size(), 3u);
  EXPECT_NEAR(brackets[2].exposure_s / brackets[0].exposure_s, 16.0, 1e-9);
  EXPECT_NEAR(brackets[1].exposure_s, mid, 1e-15);
  int checked = 0;
  for (const Bracket& br : brackets) {
    for (int x = 0; x < 64; ++x) {
      const double v = br.encoded.at(x, 0, 1);
      const double level = v * 255;
      EXPECT_NEAR(level, std::round(level), 1e-3);  // quantised
      if (level < 20 || level > 235) continue;
      const double x_rel = response.Inverse(v, 1);
      const double l =
          x_rel * sensor.full_well_e / (sensor.electrons_per_radiance_s * br.exposure_s);
      // Rounding moves v by at most half a level: x = v^2.2 is off by at most a factor
      // (level / (level − 0.5))^2.2 (6% at level 20).
      EXPECT_NEAR(l / radiance.at(x, 0, 1), 1.0, std::pow(level / (level - 0.5), 2.2) - 1 + 1e-9);
      ++checked;
    }
  }
  EXPECT_GT(checked, 60);
}

}  // namespace
}  // namespace igi::synth
