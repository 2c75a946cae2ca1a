// igi-diagnose's re-renders of the photos (SimulatePhotos): a trial's refit is rendered only
// where its held-out test reads (HeldOutTestMasks) and completed when it is applied; the parts
// must make up, bit for bit, the simulation rendered at once, and the held-out test's pixels
// (values and variance) must already be final after the first part.
#include <gtest/gtest.h>

#include <cmath>

#include "solver/diagnose/pixel_records.h"
#include "tests/solver/test_scenes.h"

namespace igi::diagnose {
namespace {

using test::DownCamera;
using test::LoadTestScene;
using test::SquareObj;
using test::TempSceneDir;
using test::WriteText;

// A floor under a sphere light (soft, noisy renders) seen by two cameras, one photo each; the
// second photo has an exposure scale and a response (applied per half render for the variance).
recon::Scene TwoPhotoScene(const std::filesystem::path& dir) {
  WriteText(dir / "floor.obj", SquareObj("floor", 3.0));
  const Json doc = {
      {"format", "igi-scene"},
      {"version", 1},
      {"geometry", {{{"file", "floor.obj"}}}},
      {"materials",
       {{"floor", {{"brdf", "ward_gmd"}, {"rho_d", 0.4}, {"rho_s", 0.1}, {"alpha", 0.15}}}}},
      {"lights",
       {{"l", {{"type", "sphere"}, {"center", {0.3, 0, 1}}, {"radius", 0.3}, {"radiance", 30}}}}},
      {"lightings", {{"L", {"l"}}}},
      {"cameras",
       {{"a", DownCamera(0, 0, 3, 37, 29, 30)}, {"b", DownCamera(0.2, 0, 2, 40, 24, 25)}}}};
  recon::Scene scene = LoadTestScene(dir, doc);
  for (int c = 0; c < 2; ++c) {
    recon::Photo p;
    p.file = dir / (scene.cameras[c].name + ".exr");
    p.camera = c;
    p.lighting = 0;
    if (c == 1) p.exposure_scale = 1.7, p.response_exponent = 0.8, p.response_reference = 0.2;
    scene.photos.push_back(p);
  }
  return scene;
}

DiagnoseOptions Options() {
  DiagnoseOptions o;
  o.spp = 5;  // halves of 2 and 3 paths
  o.num_threads = 2;
  return o;
}

TEST(SimulatePhotosTest, HeldOutTestMasksCoverTheBlocksTheirWindowAndTheGrid) {
  const auto dir = TempSceneDir("sim_masks");
  const recon::Scene scene = TwoPhotoScene(dir);
  const solver::PixelHoldout h{0.3, 6, 5};
  const PixelMasks masks = HeldOutTestMasks(scene, h, 8);
  ASSERT_EQ(masks.size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    const recon::Camera& cam = scene.cameras[scene.photos[i].camera];
    ASSERT_EQ(masks[i].size(), size_t(cam.width) * cam.height);
    size_t marked = 0, held = 0;
    for (int y = 0; y < cam.height; ++y) {
      for (int x = 0; x < cam.width; ++x) {
        bool near = false;  // a held-out pixel within 2 pixels (Chebyshev)
        for (int v = y - 2; v <= y + 2; ++v) {
          for (int u = x - 2; u <= x + 2; ++u) {
            near |= u >= 0 && v >= 0 && u < cam.width && v < cam.height && h.HeldOut(int(i), u, v);
          }
        }
        const bool want = near || (x % 8 == 0 && y % 8 == 0);
        EXPECT_EQ(masks[i][size_t(y) * cam.width + x] != 0, want) << i << ": " << x << "," << y;
        marked += want;
        held += h.HeldOut(int(i), x, y);
      }
    }
    EXPECT_GT(held, 0u);
    EXPECT_LT(marked, masks[i].size());  // not everything: the point of the masks
  }
}

// Cross-fitting's folds: fold 0 is exactly the held-out blocks, the fitted blocks split into
// near-equal shares, a block is one fold, and a single fold leaves every fitted block in fold 1.
TEST(SimulatePhotosTest, FoldsAreTheHeldOutBlocksAndSharesOfTheOthers) {
  const solver::PixelHoldout h{0.25, 8, 7};
  std::vector<int> count(4, 0);
  for (int photo = 0; photo < 4; ++photo) {
    for (int y = 0; y < 400; y += 8) {
      for (int x = 0; x < 400; x += 8) {
        const int f = h.Fold(photo, x, y, 4);
        ASSERT_GE(f, 0);
        ASSERT_LT(f, 4);
        EXPECT_EQ(f == 0, h.HeldOut(photo, x, y));
        EXPECT_EQ(h.Fold(photo, x + 7, y + 5, 4), f);  // the same block
        EXPECT_EQ(h.Fold(photo, x, y, 1), f == 0 ? 0 : 1);
        ++count[size_t(f)];
      }
    }
  }
  for (int f = 0; f < 4; ++f) EXPECT_NEAR(count[size_t(f)], 2500, 150) << "fold " << f;
  // No held-out blocks: every block in a fitted fold, still split evenly.
  const solver::PixelHoldout none{0, 8, 7};
  std::vector<int> split(3, 0);
  for (int y = 0; y < 800; y += 8) {
    for (int x = 0; x < 800; x += 8) ++split[size_t(none.Fold(0, x, y, 4) - 1)];
  }
  for (int n : split) EXPECT_NEAR(n, 10000 / 3.0, 250);
}

TEST(SimulatePhotosTest, PartsRenderedSeparatelyEqualOneRender) {
  const auto dir = TempSceneDir("sim_parts");
  const recon::Scene scene = TwoPhotoScene(dir);
  const DiagnoseOptions o = Options();
  const solver::PixelHoldout h{0.3, 6, 5};
  Simulation whole;
  SimulatePhotos(scene, o, 9, &whole);
  ASSERT_TRUE(whole.Complete());
  ASSERT_EQ(whole.sims.size(), 2u);

  const PixelMasks masks = HeldOutTestMasks(scene, h, 8);
  Simulation part;
  SimulatePhotos(scene, o, 9, &part, &masks);
  EXPECT_FALSE(part.Complete());
  size_t some_variance = 0;
  for (size_t i = 0; i < 2; ++i) {
    const Image& s = part.sims[i];
    for (int y = 0; y < s.height; ++y) {
      for (int x = 0; x < s.width; ++x) {
        const bool rendered = masks[i][size_t(y) * s.width + x] != 0;
        for (int c = 0; c < 3; ++c) {
          if (!rendered) {
            EXPECT_TRUE(std::isnan(s.at(x, y, c)));
            continue;
          }
          EXPECT_EQ(s.at(x, y, c), whole.sims[i].at(x, y, c)) << i << ": " << x << "," << y;
          // The held-out pixels' variance is final: its window lies inside the rendered part.
          if (h.HeldOut(int(i), x, y)) {
            EXPECT_EQ(part.variance[i].at(x, y, c), whole.variance[i].at(x, y, c))
                << i << ": " << x << "," << y;
            some_variance += whole.variance[i].at(x, y, c) > 0;
          }
        }
      }
    }
  }
  EXPECT_GT(some_variance, 0u);  // the renders are noisy: the comparison means something

  SimulatePhotos(scene, o, 9, &part);  // the rest
  EXPECT_TRUE(part.Complete());
  for (size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(part.sims[i].pixels, whole.sims[i].pixels) << i;
    EXPECT_EQ(part.variance[i].pixels, whole.variance[i].pixels) << i;
  }
  // A different seed is a different render (the equality above is not of constant images).
  Simulation other;
  SimulatePhotos(scene, o, 10, &other);
  EXPECT_NE(other.sims[0].pixels, whole.sims[0].pixels);
}

}  // namespace
}  // namespace igi::diagnose
