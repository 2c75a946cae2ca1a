// Vignetting from flat fields and from overlapping photos (calib/vignetting.h), camera.json's
// "vignetting", and igi-calib vignetting end to end.
#include "calib/vignetting.h"

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>

#include "calib/camera_file.h"
#include "tests/e2e/run.h"
#include "tests/temp_dir.h"
#include "tools/common/error.h"
#include "tools/common/image.h"
#include "tools/common/json.h"

namespace igi::calib {
namespace {

using test::Quote;
using test::RunTool;

constexpr double kK1 = -0.32, kK2 = 0.06;

// A flat field of a w × h camera with principal point (cx, cy): a Lambertian card facing the
// camera, lit by a point light at `light` (metres; the card is the plane z = 1 in the camera's
// frame, the image spans ±0.4 m × ±0.3 m of it), times the vignetting k1, k2.
Image CardFlatField(int w, int h, double cx, double cy, const Eigen::Vector3d& light, double k1,
                    double k2, double scale = 1.0) {
  Image image(w, h, 3);
  const Vignetting v{k1, k2};
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const Eigen::Vector3d p(0.8 * ((x + 0.5) / w - 0.5), 0.6 * ((y + 0.5) / h - 0.5), 1.0);
      const Eigen::Vector3d to_light = light - p;
      const double d = to_light.norm();
      // Irradiance of a plane facing -z: cos at the card over d².
      const double e = -to_light.z() / d / (d * d);
      const double f = v.Factor(VignettingRadius2(x + 0.5, y + 0.5, cx, cy, w, h));
      for (int c = 0; c < 3; ++c) image.at(x, y, c) = float(scale * e * f * (0.6 + 0.1 * c));
    }
  }
  return image;
}

FlatField Reduce(const Image& image, const std::string& name) {
  FlatFieldReducer reducer(name, image.width, image.height,
                           FlatFieldBlockSize(image.width, image.height));
  std::vector<float> lum(size_t(image.width));
  std::vector<uint8_t> ok(size_t(image.width), 1);
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      lum[size_t(x)] = (image.at(x, y, 0) + image.at(x, y, 1) + image.at(x, y, 2)) / 3;
    }
    reducer.AddRow(y, lum.data(), ok.data());
  }
  return reducer.Finish();
}

// Lamps in front of the card, off its axis in different directions, each at about 12 times the
// card's half diagonal (0.5 m): each photo's light is non-uniform — a gradient of 6–12 % and a
// fall-off across the card — differently each time.
std::vector<Eigen::Vector3d> Lamps() {
  return {{2.5, 0.8, -5.0}, {-2.0, 1.8, -5.5}, {0.6, -2.6, -4.8}, {-1.6, -1.4, -6.0}};
}

TEST(VignettingTest, RadiusIsInHalfDiagonalsFromThePrincipalPoint) {
  EXPECT_DOUBLE_EQ(VignettingRadius2(320, 240, 320, 240, 640, 480), 0.0);
  EXPECT_DOUBLE_EQ(VignettingRadius2(0, 0, 320, 240, 640, 480), 1.0);
  EXPECT_DOUBLE_EQ(VignettingRadius2(640, 240, 320, 240, 640, 480), 0.64);
  EXPECT_DOUBLE_EQ((Vignetting{-0.3, 0.05}.Factor(1.0)), 0.75);
}

TEST(VignettingTest, FlatFieldsUnderNonUniformLightGiveTheFallOff) {
  const int w = 480, h = 360;
  const double cx = 250.0, cy = 170.0;  // off the image centre, as a real lens's is
  std::vector<FlatField> fields;
  for (const Eigen::Vector3d& lamp : Lamps()) {
    fields.push_back(Reduce(CardFlatField(w, h, cx, cy, lamp, kK1, kK2), "card"));
    // The light alone is far from uniform: it varies by more than 5 % over the card.
    const Image light = CardFlatField(w, h, cx, cy, lamp, 0, 0);
    float lo = light.at(0, 0), hi = lo;
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        lo = std::min(lo, light.at(x, y));
        hi = std::max(hi, light.at(x, y));
      }
    }
    EXPECT_GT(hi / lo, 1.05);
  }
  const VignettingFit fit = FitFlatFields(fields, cx, cy);
  std::printf("flat fields: k1 %.4f (truth %.2f), k2 %.4f (truth %.2f), RMS %.4f\n",
              fit.vignetting.k1, kK1, fit.vignetting.k2, kK2, fit.rms_ln);
  EXPECT_NEAR(fit.vignetting.k1, kK1, 0.01);
  EXPECT_NEAR(fit.vignetting.k2, kK2, 0.01);
  EXPECT_EQ(fit.photos, 4);
  EXPECT_LT(fit.rms_ln, 0.005);
  // Fitted about the image centre instead (10 px from the principal point, as when no
  // intrinsics are known), the cubic terms of the light take up the shift: k moves little.
  const VignettingFit centred = FitFlatFields(fields, w / 2.0, h / 2.0);
  EXPECT_NEAR(centred.vignetting.k1, kK1, 0.01);
  EXPECT_NEAR(centred.vignetting.k2, kK2, 0.01);
}

TEST(VignettingTest, WithoutVignettingTheFallOffOfTheLightIsNotTakenForOne) {
  std::vector<FlatField> fields;
  for (const Eigen::Vector3d& lamp : Lamps()) {
    fields.push_back(Reduce(CardFlatField(400, 300, 200, 150, lamp, 0, 0), "card"));
  }
  const VignettingFit fit = FitFlatFields(fields, 200, 150);
  EXPECT_NEAR(fit.vignetting.k1, 0, 0.01);
  EXPECT_NEAR(fit.vignetting.k2, 0, 0.01);
}

TEST(VignettingTest, ClippedFlatFieldIsRefusedNamingAPixel) {
  FlatFieldReducer reducer("flat.exr", 100, 100, 10);
  std::vector<float> lum(100, 0.5f);
  std::vector<uint8_t> ok(100, 1);
  for (int y = 0; y < 100; ++y) {
    if (y == 7) {
      ok[3] = 0;  // one clipped pixel in 10⁴ is within the allowance…
      ok[4] = 0;  // …two are not
    }
    reducer.AddRow(y, lum.data(), ok.data());
    ok[3] = ok[4] = 1;
  }
  try {
    reducer.Finish();
    FAIL() << "a clipped flat field was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("flat.exr: pixel (3, 7)"), std::string::npos) << e.what();
  }
}

TEST(VignettingTest, DarkCornerIsRefused) {
  FlatFieldReducer reducer("flat.exr", 100, 100, 10);
  std::vector<float> lum(100);
  std::vector<uint8_t> ok(100, 1);
  for (int y = 0; y < 100; ++y) {
    for (int x = 0; x < 100; ++x) lum[size_t(x)] = (x < 10 && y < 10) ? 0.01f : 0.5f;
    reducer.AddRow(y, lum.data(), ok.data());
  }
  EXPECT_THROW(reducer.Finish(), InputError);
}

TEST(VignettingTest, OverlapPairsGiveTheFallOffAndTheExposures) {
  // Points of a diffuse surface seen by 5 photos of different exposures at random radii, with
  // 2 % noise and one pair in ten an outlier (a highlight or an occlusion).
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> uni(0, 1);
  std::normal_distribution<double> noise(0, 0.02);
  const Vignetting truth{kK1, kK2};
  const double exposure[5] = {0, 0.3, -0.2, 0.1, 0.5};
  std::vector<OverlapPair> pairs;
  for (int i = 0; i < 3000; ++i) {
    const int a = int(uni(rng) * 5), b = (a + 1 + int(uni(rng) * 4)) % 5;
    const double ln_l = std::log(0.2 + uni(rng));
    const double r2a = uni(rng), r2b = uni(rng);
    OverlapPair p{a,
                  b,
                  r2a,
                  r2b,
                  ln_l + exposure[a] + std::log(truth.Factor(r2a)) + noise(rng),
                  ln_l + exposure[b] + std::log(truth.Factor(r2b)) + noise(rng)};
    if (i % 10 == 0) p.ln_a += 1.0;
    pairs.push_back(p);
  }
  const VignettingFit fit = FitOverlap(pairs, 5, /*free_exposures=*/true);
  EXPECT_NEAR(fit.vignetting.k1, kK1, 0.01);
  EXPECT_NEAR(fit.vignetting.k2, kK2, 0.01);
  for (int i = 0; i < 5; ++i) {
    EXPECT_NEAR(fit.exposures_ln[size_t(i)] - fit.exposures_ln[0], exposure[i], 0.005) << i;
  }
}

TEST(VignettingTest, OverlapAtOneRadiusIsRefused) {
  std::vector<OverlapPair> pairs(500, OverlapPair{0, 1, 0.3, 0.31, 0.0, 0.0});
  EXPECT_THROW(FitOverlap(pairs, 2), InputError);
  EXPECT_THROW(FitOverlap(std::vector<OverlapPair>(10), 2), InputError);
}

TEST(VignettingTest, CameraJsonHoldsVignettingWithOrWithoutIntrinsics) {
  const auto dir = test::UniqueTempDir("igi_vignetting_json");
  CameraFile only;
  only.width = 640;
  only.height = 480;
  only.vignetting = CameraVignetting{{-0.3, 0.05}, "flat_field", 0.004, 2000, 4};
  WriteCameraFile(dir / "a.json", only);
  const CameraFile a = ReadCameraFile(dir / "a.json");
  ASSERT_TRUE(a.vignetting);
  EXPECT_FALSE(a.HasIntrinsics());
  EXPECT_DOUBLE_EQ(a.vignetting->model.k1, -0.3);
  EXPECT_EQ(a.vignetting->method, "flat_field");
  EXPECT_DOUBLE_EQ(a.principal_x_px(), 320);

  CameraFile both = only;
  both.model = ColmapCameraModel::kOpenCv;
  both.params = {500, 500, 300, 250, 0, 0, 0, 0};
  WriteCameraFile(dir / "b.json", both);
  const CameraFile b = ReadCameraFile(dir / "b.json");
  EXPECT_TRUE(b.HasIntrinsics());
  EXPECT_DOUBLE_EQ(b.principal_y_px(), 250);
  EXPECT_DOUBLE_EQ(b.vignetting->model.k2, 0.05);

  // Neither intrinsics nor vignetting; a fall-off that turns negative inside the image.
  CameraFile none;
  none.width = 640;
  none.height = 480;
  EXPECT_THROW(WriteCameraFile(dir / "c.json", none), InputError);
  CameraFile negative = only;
  negative.vignetting->model = {-1.5, 0.2};
  EXPECT_THROW(WriteCameraFile(dir / "d.json", negative), InputError);
  EXPECT_FALSE(std::filesystem::exists(dir / "d.json"));
  std::filesystem::remove_all(dir);
}

// igi-calib vignetting end to end: 16-bit PNG flat fields through a gamma response, and EXR.
class VignettingE2eTest : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = test::UniqueTempDir("igi_vignetting_e2e"); }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  // Writes the card flat fields: EXR (linear) or 16-bit PNG through v = u^(1/2.2).
  std::string WriteFlatFields(bool png, double scale = 0.5) {
    std::string args;
    int i = 0;
    for (const Eigen::Vector3d& lamp : Lamps()) {
      Image image = CardFlatField(640, 480, 330, 230, lamp, kK1, kK2);
      float peak = 0;
      for (float v : image.pixels) peak = std::max(peak, v);
      for (float& v : image.pixels) v = float(scale * v / peak);
      if (png) {
        for (float& v : image.pixels) v = std::pow(v, 1 / 2.2f);
      }
      const auto path = dir_ / ("flat" + std::to_string(i++) + (png ? ".png" : ".exr"));
      WriteImageOptions o;
      if (png) o.type = PixelType::kUInt16;
      WriteImage(path, image, o);
      args += Quote(path.string()) + " ";
    }
    return args;
  }

  // A response.json of v = u^(1/2.2) at 65536 levels: g(z) = 2.2 ln(z / 65535).
  std::string WriteGammaResponse() {
    const auto path = dir_ / "response.json";
    Json g = Json::array();
    for (int c = 0; c < 3; ++c) {
      Json curve = Json::array();
      for (int z = 0; z < 65536; ++z) curve.push_back(2.2 * std::log(std::max(z, 1) / 65535.0));
      g.push_back(curve);
    }
    WriteJsonFile(path, Json{{"format", "igi-response"},
                             {"version", 1},
                             {"method", "gamma 2.2"},
                             {"levels", 65536},
                             {"channels", {"R", "G", "B"}},
                             {"g", g}});
    return path.string();
  }

  std::filesystem::path dir_;
};

TEST_F(VignettingE2eTest, ExrFlatFieldsBesideKnownIntrinsics) {
  CameraFile intrinsics;
  intrinsics.model = ColmapCameraModel::kPinhole;
  intrinsics.width = 640;
  intrinsics.height = 480;
  intrinsics.params = {550, 550, 330, 230};
  intrinsics.rms_px = 0.3;
  WriteCameraFile(dir_ / "intrinsics.json", intrinsics);
  const auto out = dir_ / "camera.json";
  const auto r = RunTool("igi-calib", "vignetting " + WriteFlatFields(false) + "--camera " +
                                          Quote((dir_ / "intrinsics.json").string()) + " --out " +
                                          Quote(out.string()));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const CameraFile camera = ReadCameraFile(out);
  ASSERT_TRUE(camera.vignetting);
  EXPECT_NEAR(camera.vignetting->model.k1, kK1, 0.01);
  EXPECT_NEAR(camera.vignetting->model.k2, kK2, 0.01);
  EXPECT_EQ(camera.vignetting->photos, 4);
  EXPECT_EQ(camera.params, intrinsics.params);  // the intrinsics are kept
  EXPECT_DOUBLE_EQ(camera.rms_px, 0.3);
}

TEST_F(VignettingE2eTest, SixteenBitFlatFieldsThroughTheirResponse) {
  const auto out = dir_ / "camera.json";
  // No intrinsics: the principal point is taken at the image centre, 10 px from the truth.
  const auto r =
      RunTool("igi-calib", "vignetting " + WriteFlatFields(true) + "--response " +
                               Quote(WriteGammaResponse()) + " --out " + Quote(out.string()));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const CameraFile camera = ReadCameraFile(out);
  EXPECT_FALSE(camera.HasIntrinsics());
  EXPECT_NEAR(camera.vignetting->model.k1, kK1, 0.01);
  EXPECT_NEAR(camera.vignetting->model.k2, kK2, 0.01);
  // Without the response, 8/16-bit levels are not light: refused.
  const auto no_response = RunTool("igi-calib", "vignetting " + WriteFlatFields(true) + "--out " +
                                                    Quote((dir_ / "none.json").string()));
  EXPECT_EQ(no_response.exit_code, 2);
  EXPECT_NE(no_response.err.find("--response"), std::string::npos) << no_response.err;
  EXPECT_FALSE(std::filesystem::exists(dir_ / "none.json"));
}

TEST_F(VignettingE2eTest, ClippedFlatFieldExitsTwoWritingNothing) {
  // Exposed so that the centre clips: one line naming the file and a pixel, exit 2.
  const auto out = dir_ / "camera.json";
  const auto r =
      RunTool("igi-calib", "vignetting " + WriteFlatFields(true, 1.3) + "--response " +
                               Quote(WriteGammaResponse()) + " --out " + Quote(out.string()));
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("flat0.png: pixel ("), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("clipped"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(out));
}

}  // namespace
}  // namespace igi::calib
