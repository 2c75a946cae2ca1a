// Agreement with an independent renderer: igi-render's path tracer against RADIANCE 6.1a
// renders of ../shared/data/reference/radiance_room (same scene, cameras, units).
//
// Tolerances:
// - Image means per channel within 1 %. RADIANCE's -ab 8 bounce cap loses about 0.35 % of the
//   image mean (its README), the two references' own Monte Carlo noise on a mean is ~0.02 %,
//   and ours at the spp below is ~0.1 %: 1 % leaves room for those and nothing systematic.
// - Means over 16x16-pixel blocks within 3 %. A block mean of RADIANCE carries 2-5 %/sqrt(256)
//   ~ 0.3 % noise; ours at 256 spp about 0.5 % rms (measured: every block within 2.5 %; at
//   64 spp heavy-tailed indirect noise reached 7 %). RADIANCE point-samples pixel centres while
//   igi integrates each pixel's square, so blocks crossing a high-contrast edge differ by
//   aliasing: a block whose four 8x8 quadrant means (in RADIANCE's image) differ by more than
//   25 % holds an edge, a highlight or a steep gradient and is left out of the 3 % check. At
//   least 60 % of all blocks must remain in it.
//   "Where the noise allows": a block's tolerance is max(3 %, 4 sigma), sigma the noise of the
//   difference of the two block means, estimated from each image alone as RADIANCE's README
//   does (each pixel's residual against the mean of its four neighbours; independent noise
//   gives that residual a variance of 1.25 sigma_pixel^2; our pixels use independent random
//   streams too). It matters only in dim, noisy blocks of cam0_L1 (RADIANCE: 5 % rms per
//   pixel, heavy-tailed; ours: the floor near the camera, far from lamp2).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "recon/scene.h"
#include "solver/render/render.h"
#include "tools/common/image.h"

namespace igi::render {
namespace {

namespace fs = std::filesystem;
const fs::path kRoom = fs::path(IGI_SHARED_DATA_DIR) / "reference/radiance_room";

struct Case {
  const char* photo;
  const char* camera;
  const char* lighting;
};

double Luminance(const Image& im, int x, int y) {
  return 0.2126 * im.at(x, y, 0) + 0.7152 * im.at(x, y, 1) + 0.0722 * im.at(x, y, 2);
}

// Variance of one pixel's Monte Carlo noise, from its residual against its 4 neighbours.
double PixelNoiseVariance(const Image& im, int x, int y) {
  const int xl = std::max(x - 1, 0), xr = std::min(x + 1, im.width - 1);
  const int yu = std::max(y - 1, 0), yd = std::min(y + 1, im.height - 1);
  const double neighbours =
      (Luminance(im, xl, y) + Luminance(im, xr, y) + Luminance(im, x, yu) + Luminance(im, x, yd)) /
      4.0;
  const double r = Luminance(im, x, y) - neighbours;
  return r * r / 1.25;
}

class RadianceRoomTest : public ::testing::TestWithParam<Case> {
 protected:
  static void SetUpTestSuite() {
    recon::SceneLoadOptions options;
    options.require_complete_materials = true;
    scene_ = new recon::Scene(recon::LoadScene(kRoom / "scene.json", options));
  }
  static void TearDownTestSuite() { delete scene_; }
  static recon::Scene* scene_;
};
recon::Scene* RadianceRoomTest::scene_ = nullptr;

TEST_P(RadianceRoomTest, MatchesRadianceImageAndBlockMeans) {
  const Case& c = GetParam();
  const Image reference = ReadImage(kRoom / "photos" / c.photo, 3);
  const Renderer renderer(*scene_, scene_->FindLighting(c.lighting));
  RenderOptions options;
  options.spp = 256;
  options.seed = 7;
  options.show_progress = false;
  const Image ours = renderer.Render(scene_->cameras[scene_->FindCamera(c.camera)], options);
  ASSERT_EQ(ours.width, reference.width);
  ASSERT_EQ(ours.height, reference.height);

  for (int ch = 0; ch < 3; ++ch) {
    double sum_ref = 0, sum_ours = 0;
    for (int y = 0; y < ours.height; ++y) {
      for (int x = 0; x < ours.width; ++x) {
        sum_ref += reference.at(x, y, ch);
        sum_ours += ours.at(x, y, ch);
      }
    }
    const double rel = sum_ours / sum_ref - 1.0;
    RecordProperty(std::string("mean_rel_diff_ch") + std::to_string(ch), std::to_string(rel));
    EXPECT_LT(std::abs(rel), 0.01) << c.photo << " channel " << ch;
  }

  constexpr int kBlock = 16;
  int blocks = 0, compared = 0, failed = 0;
  double worst = 0;
  for (int by = 0; by + kBlock <= ours.height; by += kBlock) {
    for (int bx = 0; bx + kBlock <= ours.width; bx += kBlock) {
      ++blocks;
      double ref = 0, mine = 0, quadrant[4] = {0, 0, 0, 0}, noise_var = 0;
      for (int y = by; y < by + kBlock; ++y) {
        for (int x = bx; x < bx + kBlock; ++x) {
          const double r = Luminance(reference, x, y);
          ref += r;
          noise_var += PixelNoiseVariance(reference, x, y) + PixelNoiseVariance(ours, x, y);
          mine += Luminance(ours, x, y);
          quadrant[2 * ((y - by) * 2 / kBlock) + (x - bx) * 2 / kBlock] += r;
        }
      }
      ref /= kBlock * kBlock;
      mine /= kBlock * kBlock;
      const auto [lo, hi] = std::minmax_element(quadrant, quadrant + 4);
      if (*hi > 1.25 * *lo) continue;  // an edge, highlight or steep gradient (aliasing)
      ++compared;
      const double sigma = std::sqrt(noise_var) / (kBlock * kBlock) / ref;  // relative
      const double tolerance = std::max(0.03, 4 * sigma);
      const double rel = std::abs(mine / ref - 1.0);
      worst = std::max(worst, rel / tolerance * 0.03);
      if (rel > tolerance) {
        ++failed;
        std::printf("  block (%d, %d): %.2f %% (tolerance %.2f %%)\n", bx, by, 100 * rel,
                    100 * tolerance);
      }
    }
  }
  std::printf("%s: %d of %d blocks compared, worst %.2f %% (scaled to a 3 %% tolerance), %d over\n",
              c.photo, compared, blocks, 100 * worst, failed);
  EXPECT_GE(compared, blocks * 6 / 10) << c.photo;
  EXPECT_EQ(failed, 0) << c.photo << ": worst block differs by " << 100 * worst << " %";
}

INSTANTIATE_TEST_SUITE_P(Reference, RadianceRoomTest,
                         ::testing::Values(Case{"cam0_L0.exr", "cam0", "L0"},
                                           Case{"cam1_L0.exr", "cam1", "L0"},
                                           Case{"cam2_L0.exr", "cam2", "L0"},
                                           Case{"cam0_L1.exr", "cam0", "L1"}),
                         [](const auto& param_info) {
                           return std::string(param_info.param.camera) + "_" +
                                  param_info.param.lighting;
                         });

}  // namespace
}  // namespace igi::render
