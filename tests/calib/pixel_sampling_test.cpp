#include "calib/pixel_sampling.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "tests/calib/synthetic_bracket.h"

namespace igi::calib {
namespace {

TEST(PixelSampling, MiddleExposure) {
  EXPECT_EQ(MiddleExposureIndex({4, 1, 2}), 2);
  EXPECT_EQ(MiddleExposureIndex({1, 2, 4, 8}), 2);
}

TEST(PixelSampling, SpreadUnsaturatedFlatAndOverTheRange) {
  testing::SyntheticOptions o;
  o.full_well = 0;
  const testing::SyntheticBracket s = testing::MakeSyntheticBracket(o);
  SamplingOptions options;
  options.samples = 100;
  const std::vector<int64_t> pixels = SelectSamplePixels(s.bracket, options);
  ASSERT_EQ(pixels.size(), 100u);
  const Image& mid = s.bracket.images[size_t(MiddleExposureIndex(s.bracket.exposures_s))];
  std::set<int> quadrants;
  int low = 0, high = 0;
  for (int64_t p : pixels) {
    const int x = int(p % mid.width), y = int(p / mid.width);
    quadrants.insert((x < mid.width / 2 ? 0 : 1) + (y < mid.height / 2 ? 0 : 2));
    for (int c = 0; c < 3; ++c) {
      const float v = mid.at(x, y, c);
      EXPECT_GT(v, options.black);
      EXPECT_LT(v, options.saturated);
    }
    // Flat: never on a horizontal tile edge (a jump between two random radiances; inside a tile
    // the vertical gradient is 0).
    EXPECT_NE(y % 8, 7);
    EXPECT_NE(y % 8, 0);
    low += mid.at(x, y, 1) < 0.4f ? 1 : 0;
    high += mid.at(x, y, 1) > 0.6f ? 1 : 0;
  }
  EXPECT_EQ(quadrants.size(), 4u);
  EXPECT_GE(low, 15);  // intensity bins are visited round-robin
  EXPECT_GE(high, 15);
}

}  // namespace
}  // namespace igi::calib
