// The re-renders' paths chosen from the photos' noise (solver/diagnose/render_noise.h), on images
// whose noise is known: a smooth gradient, the photo with Gaussian noise of relative σp, the
// render with Gaussian noise of relative σr at 32 paths and its variance known per pixel.

#include "solver/diagnose/render_noise.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace igi::diagnose {
namespace {

struct NoisyPair {
  PhotoSet photos;
  Simulation sim;
};

NoisyPair MakePair(double photo_sigma, double render_sigma, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> unit(0.0, 1.0);
  const int w = 160, h = 120;
  Image photo(w, h, 3), render(w, h, 3), variance(w, h, 3), valid(w, h, 1, 1.0f);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const double truth = 0.2 + 0.6 * x / w + 0.2 * y / h;  // smooth: no edge in the residual
      for (int c = 0; c < 3; ++c) {
        photo.at(x, y, c) = float(truth * (1 + photo_sigma * unit(rng)));
        render.at(x, y, c) = float(truth * (1 + render_sigma * unit(rng)));
        variance.at(x, y, c) = float(std::pow(truth * render_sigma, 2));
      }
    }
  }
  NoisyPair p;
  p.photos.recorded = {photo};
  p.photos.valid = {valid};
  p.sim.sims = {render};
  p.sim.variance = {variance};
  return p;
}

// Photo noise 3 %, render noise 12 % at 32 paths: the render's variance is 16× the photo's, so a
// quarter of it needs 64× the paths (2048), within the cap; the noises are measured within 5 %.
TEST(ChooseSpp, PathsFollowTheRatioOfTheRendersVarianceToThePhotos) {
  const NoisyPair p = MakePair(0.03, 0.12, 1);
  const RenderNoise n = ChooseSpp(p.photos, p.sim, 32, 4096, 0.25);
  // Relative to the photos' mean square: a relative noise σ over the image's values reads as σ.
  EXPECT_NEAR(std::sqrt(n.photo), 0.03, 0.05 * 0.03);
  EXPECT_NEAR(std::sqrt(n.render), 0.12, 0.05 * 0.12);
  EXPECT_NEAR(n.spp, 2048, 0.1 * 2048);
  EXPECT_EQ(n.spp_measured, 32);
}

// The cap holds, and renders already quieter than the share ask for no more paths.
TEST(ChooseSpp, StaysWithinTheRange) {
  const NoisyPair noisy = MakePair(0.03, 0.12, 2);
  EXPECT_EQ(ChooseSpp(noisy.photos, noisy.sim, 32, 256, 0.25).spp, 256);
  const NoisyPair quiet = MakePair(0.10, 0.02, 3);
  EXPECT_EQ(ChooseSpp(quiet.photos, quiet.sim, 32, 4096, 0.25).spp, 32);
  // spp_max at spp: fixed paths.
  EXPECT_EQ(ChooseSpp(quiet.photos, quiet.sim, 32, 0, 0.25).spp, 32);
}

// Invalid pixels do not count: a photo whose left half is unusable (NaN, masked out) reads the
// same noise from its right half.
TEST(ChooseSpp, OnlyValidPixelsCount) {
  NoisyPair p = MakePair(0.03, 0.12, 4);
  const RenderNoise all = ChooseSpp(p.photos, p.sim, 32, 4096, 0.25);
  for (int y = 0; y < 120; ++y) {
    for (int x = 0; x < 80; ++x) {
      p.photos.valid[0].at(x, y, 0) = 0;
      for (int c = 0; c < 3; ++c) p.photos.recorded[0].at(x, y, c) = NAN;
    }
  }
  const RenderNoise half = ChooseSpp(p.photos, p.sim, 32, 4096, 0.25);
  EXPECT_TRUE(std::isfinite(half.white));
  EXPECT_NEAR(std::sqrt(half.photo), std::sqrt(all.photo), 0.1 * std::sqrt(all.photo));
}

// The cap of the chosen paths: given (0 or N) as it is; by default the paths a capture of
// analysis_megapixels takes at spp, spread over the pixels analysed.
TEST(MaxSppTest, ASmallCaptureAffordsMorePathsPerPixel) {
  PhotoSet four;
  four.recorded.assign(4, Image(256, 192, 3));
  DiagnoseOptions o;               // spp 32, spp_max -1, analysis_megapixels 0.5
  EXPECT_EQ(MaxSpp(o, four), 81);  // 32 · 500 000 / 196 608
  o.spp_max = 0;
  EXPECT_EQ(MaxSpp(o, four), 0);
  o.spp_max = 300;
  EXPECT_EQ(MaxSpp(o, four), 300);
  // A capture analysed at the analysis size or more keeps spp, as does analysis at full size.
  o.spp_max = -1;
  PhotoSet thirty;
  thirty.recorded.assign(30, Image(816, 612, 3));
  EXPECT_EQ(MaxSpp(o, thirty), 32);
  o.analysis_megapixels = 0;
  EXPECT_EQ(MaxSpp(o, four), 32);
}

}  // namespace
}  // namespace igi::diagnose
