// The capture igi-diagnose analyses when the photos are large (solver/diagnose/analysis_capture.h):
// the factor, the block means (linear, through a declared response), the masks of blocks with an
// unusable pixel, the intrinsics divided by the factor (a world point lands at the reduced
// pixel), and the way back to the declared photos and intrinsics with what was fitted kept.
#include "solver/diagnose/analysis_capture.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "tests/solver/test_scenes.h"
#include "tools/common/image.h"

namespace igi::diagnose {
namespace {

namespace fs = std::filesystem;
using test::DownCamera;
using test::SquareObj;
using test::TempSceneDir;
using test::WriteText;

// Two cameras over a floor: photo a (37 x 29) with a NaN pixel, photo b (40 x 24) with a response
// and a mask that leaves out its top-left pixel.
struct TwoPhotos {
  fs::path dir;
  recon::Scene scene;
  Image a, b, b_mask;
};

TwoPhotos WriteTwoPhotos(const std::string& name) {
  TwoPhotos t;
  t.dir = TempSceneDir(name);
  WriteText(t.dir / "floor.obj", SquareObj("floor", 3.0));
  t.a = Image(37, 29, 3);
  t.b = Image(40, 24, 3);
  for (int y = 0; y < 29; ++y) {
    for (int x = 0; x < 37; ++x) {
      for (int c = 0; c < 3; ++c) t.a.at(x, y, c) = float(x + 10 * y + 0.1 * c);
    }
  }
  t.a.at(4, 4, 1) = std::numeric_limits<float>::quiet_NaN();
  for (int y = 0; y < 24; ++y) {
    for (int x = 0; x < 40; ++x) {
      for (int c = 0; c < 3; ++c) {
        t.b.at(x, y, c) = float(0.05 + 0.002 * x + 0.011 * y + 0.001 * c + 0.01 * ((x * 7) % 5));
      }
    }
  }
  t.b_mask = Image(40, 24, 1, 1.0f);
  t.b_mask.at(0, 0) = 0;
  WriteImage(t.dir / "a.exr", t.a);
  WriteImage(t.dir / "b.exr", t.b);
  WriteImageOptions png;
  png.type = PixelType::kUInt8;
  WriteImage(t.dir / "b_mask.png", t.b_mask, png);
  const Json doc = {
      {"format", "igi-scene"},
      {"version", 1},
      {"geometry", {{{"file", "floor.obj"}}}},
      {"materials", {{"floor", {{"brdf", "lambert"}, {"rho_d", 0.4}}}}},
      {"lights", {{"l", {{"type", "point"}, {"position", {0.3, 0, 1}}, {"intensity", 3}}}}},
      {"lightings", {{"L", {"l"}}}},
      {"cameras",
       {{"a", DownCamera(0, 0, 3, 37, 29, 30)}, {"b", DownCamera(0.2, 0, 2, 40, 24, 25)}}},
      {"photos",
       {{{"file", "a.exr"}, {"camera", "a"}, {"lighting", "L"}},
        {{"file", "b.exr"},
         {"camera", "b"},
         {"lighting", "L"},
         {"mask", "b_mask.png"},
         {"response", {{"exponent", 0.8}, {"reference", 0.2}}}}}}};
  WriteJsonFile(t.dir / "scene.json", doc);
  t.scene = recon::LoadScene(t.dir / "scene.json");
  return t;
}

// The scene document with absolute paths, as igi-diagnose hands it over.
Json AbsoluteDocument(const TwoPhotos& t) {
  Json doc = t.scene.document;
  doc["geometry"][0]["file"] = (t.dir / "floor.obj").string();
  for (Json& p : doc["photos"]) {
    p["file"] = (t.dir / p["file"].get<std::string>()).string();
    if (p.contains("mask")) p["mask"] = (t.dir / p["mask"].get<std::string>()).string();
  }
  return doc;
}

TEST(ReduceCapture, PhotosWithinTheLimitAreLeftAsTheyAre) {
  const TwoPhotos t = WriteTwoPhotos("analysis_none");
  const AnalysisCapture c = ReduceCapture(t.scene, AbsoluteDocument(t), 0.5, t.dir / "analysis");
  EXPECT_FALSE(c.reduced);
  EXPECT_TRUE(c.cameras.empty());
  EXPECT_FALSE(fs::exists(t.dir / "analysis"));
  fs::remove_all(t.dir);
}

TEST(ReduceCapture, BlockMeansMaskTheUnusableBlocksAndTheIntrinsicsFollow) {
  const TwoPhotos t = WriteTwoPhotos("analysis_blocks");
  // 120 pixels: a (37 x 29) and b (40 x 24) both need a factor of 3 (12 x 9 and 13 x 8).
  const AnalysisCapture c = ReduceCapture(t.scene, AbsoluteDocument(t), 120e-6, t.dir / "analysis");
  ASSERT_TRUE(c.reduced);
  ASSERT_EQ(c.cameras.size(), 2u);
  EXPECT_EQ(c.cameras.at("a").factor, 3);
  EXPECT_EQ(c.cameras.at("a").width, 12);
  EXPECT_EQ(c.cameras.at("b").height, 8);
  const recon::Scene r =
      recon::LoadScene(c.scene_file);  // the sizes agree with the photos: it loads
  ASSERT_EQ(r.photos.size(), 2u);
  for (int k = 0; k < 2; ++k) {
    const recon::Camera &full = t.scene.cameras[k], &small = r.cameras[k];
    EXPECT_EQ(small.width, full.width / 3);
    EXPECT_EQ(small.height, full.height / 3);
    for (const Eigen::Vector3d& p : {Eigen::Vector3d(0.1, 0.2, 0), Eigen::Vector3d(-0.4, 0.3, 0)}) {
      const auto u = full.ImgFromWorld(p), v = small.ImgFromWorld(p);
      ASSERT_TRUE(u && v);
      EXPECT_NEAR((*v - *u / 3).norm(), 0, 1e-9);
    }
  }
  // Photo a: the plain means; the block holding the NaN is masked (and no mask was declared).
  const Image a = ReadImage(r.photos[0].file, 3);
  ASSERT_TRUE(r.photos[0].mask);
  const Image a_mask = ReadImage(*r.photos[0].mask, 1);
  for (int y = 0; y < 9; ++y) {
    for (int x = 0; x < 12; ++x) {
      const bool nan_block = x == 1 && y == 1;
      EXPECT_EQ(a_mask.at(x, y), nan_block ? 0.0f : 1.0f) << x << "," << y;
      if (nan_block) continue;
      for (int ch = 0; ch < 3; ++ch) {
        double sum = 0;
        for (int v = 3 * y; v < 3 * y + 3; ++v) {
          for (int u = 3 * x; u < 3 * x + 3; ++u) sum += t.a.at(u, v, ch);
        }
        EXPECT_NEAR(a.at(x, y, ch), sum / 9, 1e-4) << x << "," << y << "," << ch;
      }
    }
  }
  // Photo b: means of the linear values, encoded again; the masked pixel's block is masked.
  const recon::Photo& pb = t.scene.photos[1];
  const Image b = ReadImage(r.photos[1].file, 3);
  const Image b_mask = ReadImage(*r.photos[1].mask, 1);
  EXPECT_DOUBLE_EQ(r.photos[1].response_exponent, 0.8);
  int apart = 0;
  for (int y = 0; y < 8; ++y) {
    for (int x = 0; x < 13; ++x) {
      EXPECT_EQ(b_mask.at(x, y), x == 0 && y == 0 ? 0.0f : 1.0f) << x << "," << y;
      if (x == 0 && y == 0) continue;
      double lin = 0, rec = 0;
      for (int v = 3 * y; v < 3 * y + 3; ++v) {
        for (int u = 3 * x; u < 3 * x + 3; ++u) {
          lin += pb.LinearFromRecorded(t.b.at(u, v, 0)) / 9;
          rec += t.b.at(u, v, 0) / 9;
        }
      }
      EXPECT_NEAR(b.at(x, y, 0), pb.RecordedFromLinear(lin), 1e-6) << x << "," << y;
      apart += std::abs(pb.RecordedFromLinear(lin) - rec) > 1e-5;
    }
  }
  EXPECT_GT(apart, 50);  // the check tells them from the means of the recorded values
  fs::remove_all(t.dir);
}

TEST(AtDeclaredSize, PutsBackThePhotosAndIntrinsicsAndKeepsWhatWasFitted) {
  const TwoPhotos t = WriteTwoPhotos("analysis_back");
  const AnalysisCapture c = ReduceCapture(t.scene, AbsoluteDocument(t), 120e-6, t.dir / "analysis");
  ASSERT_TRUE(c.reduced);
  Json fitted = ReadJsonFile(c.scene_file);
  fitted["cameras"]["a"]["qvec"] = {0, 0.6, 0.8, 0};
  fitted["cameras"]["b"]["vignetting"] = {{"k1", -0.2}, {"k2", 0.05}};
  fitted["photos"][1]["exposure_scale"] = 1.3;
  const Json back = AtDeclaredSize(fitted, t.scene);
  EXPECT_EQ(back["cameras"]["a"]["width"], 37);
  EXPECT_EQ(back["cameras"]["b"]["height"], 24);
  EXPECT_EQ(back["cameras"]["a"]["params"], Json({30.0, 30.0, 18.5, 14.5}));
  EXPECT_EQ(back["cameras"]["a"]["qvec"], Json({0, 0.6, 0.8, 0}));
  EXPECT_EQ(back["cameras"]["b"]["vignetting"]["k1"], -0.2);
  EXPECT_EQ(back["photos"][0]["file"], fs::absolute(t.dir / "a.exr").lexically_normal().string());
  EXPECT_FALSE(back["photos"][0].contains("mask"));
  EXPECT_EQ(back["photos"][1]["mask"],
            fs::absolute(t.dir / "b_mask.png").lexically_normal().string());
  EXPECT_EQ(back["photos"][1]["exposure_scale"], 1.3);
  // It is a scene of the declared photos again.
  WriteJsonFile(t.dir / "back.json", back);
  const recon::Scene s = recon::LoadScene(t.dir / "back.json");
  EXPECT_EQ(s.cameras[0].width, 37);
  EXPECT_DOUBLE_EQ(s.photos[1].exposure_scale, 1.3);
  fs::remove_all(t.dir);
}

}  // namespace
}  // namespace igi::diagnose
