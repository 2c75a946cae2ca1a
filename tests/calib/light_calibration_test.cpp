// Light calibration from glossy spheres and diffuse targets (calib/light_calibration.h) and
// igi-calib lights end to end: the DiLiGenT ball's real photos against DiLiGenT's own light
// directions, a rendered glossy sphere under a point light seen from three cameras, and photos
// that do not show the sphere.
#include "calib/light_calibration.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <random>
#include <sstream>

#include "tests/e2e/run.h"
#include "tests/temp_dir.h"
#include "tools/common/error.h"
#include "tools/common/image.h"
#include "tools/common/json.h"

namespace igi::calib {
namespace {

namespace fs = std::filesystem;
using test::Quote;
using test::RunTool;

constexpr double kPi = std::numbers::pi;

double AngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b)) * 180 / kPi;
}

Eigen::Vector3d ToVec(const Json& j) {
  return {j[0].get<double>(), j[1].get<double>(), j[2].get<double>()};
}

TEST(LightCalibrationTest, MirrorDirectionReflectsAboutTheNormal) {
  const Eigen::Vector3d n(0, 0, 1);
  const Eigen::Vector3d v = Eigen::Vector3d(1, 0, 1).normalized();
  EXPECT_NEAR((MirrorDirection(n, v) - Eigen::Vector3d(-1, 0, 1).normalized()).norm(), 0, 1e-12);
  EXPECT_NEAR((MirrorDirection(n, n) - n).norm(), 0, 1e-12);
}

TEST(LightCalibrationTest, FitSphereRecoversCentreAndRadius) {
  std::mt19937 rng(3);
  std::normal_distribution<double> g;
  const Eigen::Vector3d c(0.3, -1.2, 2.0);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 200; ++i)
    points.push_back(c + 0.4 * Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized());
  const auto s = FitSphere(points);
  ASSERT_TRUE(s);
  EXPECT_NEAR((s->center - c).norm(), 0, 1e-9);
  EXPECT_NEAR(s->radius, 0.4, 1e-9);
  EXPECT_FALSE(FitSphere({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {2, 1, 0}}));  // a plane
}

// Rays from points around the light toward it, with exact directions: the closest point is the
// light, to rounding.
TEST(LightCalibrationTest, TriangulationOfExactRaysIsExact) {
  const Eigen::Vector3d light(1.0, 2.0, 3.0);
  std::vector<LightRay> rays(3);
  const Eigen::Vector3d origins[] = {{0, 0, 0}, {0.5, 0, 0.1}, {0, 0.4, -0.2}};
  for (int i = 0; i < 3; ++i) {
    rays[size_t(i)].surface = origins[i];
    rays[size_t(i)].to_light = (light - origins[i]).normalized();
  }
  const PositionEstimate e = TriangulateRays(rays, "lamp");
  EXPECT_NEAR((e.position - light).norm(), 0, 1e-9);
  EXPECT_LT(e.rms_distance, 1e-9);
  // Parallel rays cannot be triangulated; one ray neither.
  rays[1].to_light = rays[0].to_light;
  rays[2].to_light = rays[0].to_light;
  EXPECT_THROW(TriangulateRays(rays, "lamp"), InputError);
  EXPECT_THROW(TriangulateRays({rays[0]}, "lamp"), InputError);
}

// A Gaussian highlight with a clipped core on a dim disc, at a known sub-pixel place: the
// centroid of the pixels above half the peak finds it within 0.05 px (the spot is symmetric, so
// only the pixel grid's sampling moves the centroid).
TEST(LightCalibrationTest, HighlightIsFoundToSubPixel) {
  Image image(120, 100, 3, 0.01f);
  const ImageCircle circle{{60.0, 50.0}, 40.0};
  const Eigen::Vector2d spot(71.3, 42.7);
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      const Eigen::Vector2d p(x + 0.5, y + 0.5);
      if ((p - circle.center_px).norm() > circle.radius_px) continue;
      const double v = 0.2 + 1.6 * std::exp(-(p - spot).squaredNorm() / (2 * 2.5 * 2.5));
      for (int c = 0; c < 3; ++c) image.at(x, y, c) = float(std::min(v, 1.0));
    }
  }
  HighlightOptions options;
  options.saturated = 1.0;  // as in a photo from an 8/16-bit file
  const Highlight h = FindSphereHighlight(image, circle, nullptr, options, "spot.exr");
  EXPECT_NEAR((h.pixel - spot).norm(), 0, 0.05);
  EXPECT_GT(h.saturated_pixels, 0);
}

TEST(LightCalibrationTest, SphereOutsideThePhotoOrWithoutHighlightIsBadInput) {
  Image image(64, 48, 3, 0.2f);
  try {
    FindSphereHighlight(image, {{200.0, 20.0}, 15.0}, nullptr, {}, "away.exr");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("away.exr"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("not in this photo"), std::string::npos) << e.what();
  }
  // Uniform: no highlight.
  EXPECT_THROW(FindSphereHighlight(image, {{32.0, 24.0}, 15.0}, nullptr, {}, "flat.exr"),
               InputError);
}

TEST(LightCalibrationTest, IntensityFromALambertianTarget) {
  // A card of reflectance 0.5 at z = 0 facing +z under a point light of 10 W/sr at (0.3, 0, 2):
  // L = ρ/π · I cosθ / d².
  const Eigen::Vector3d light(0.3, 0.0, 2.0), rho(0.5, 0.5, 0.5);
  std::vector<TargetSample> samples;
  for (int i = 0; i < 50; ++i) {
    const Eigen::Vector3d p(0.02 * i - 0.5, 0.01 * i, 0);
    const Eigen::Vector3d w = light - p;
    const double cos = w.z() / w.norm();
    samples.push_back({Eigen::Vector3d::Constant(0.5 / kPi * 10 * cos / w.squaredNorm()), p,
                       Eigen::Vector3d::UnitZ()});
  }
  const EmissionEstimate point = PointIntensityFromTarget(samples, light, rho, "lamp");
  EXPECT_NEAR(point.value.x(), 10, 1e-9);
  EXPECT_EQ(point.samples, 50);
  // The same card under the sun: E ⟂ = π L / (ρ cosθ).
  const Eigen::Vector3d travel = Eigen::Vector3d(0.5, 0, -1).normalized();
  for (TargetSample& s : samples) s.radiance.setConstant(0.5 / kPi * 3.0 * -travel.z());
  EXPECT_NEAR(DirectionalIrradianceFromTarget(samples, travel, rho, "sun").value.y(), 3.0, 1e-9);
}

// --- DiLiGenT ball: 48 real photos under directional lights calibrated with a mirror sphere ---

const fs::path kDiligent = fs::path(IGI_SHARED_DATA_DIR) / "real" / "diligent_ball";

TEST(LightCalibrationDiligent, MaskCircleMatchesTheCameraOfTheScene) {
  if (!fs::exists(kDiligent / "mask.png")) GTEST_SKIP() << "no " << kDiligent;
  const auto circle = CircleFromMask(ReadImage(kDiligent / "mask.png", 1));
  ASSERT_TRUE(circle);
  // README: (cx, cy) = (308.358, 264.380) is the mask's centroid, r = sqrt(area / π) = 70.897.
  EXPECT_NEAR(circle->center_px.x(), 308.358, 0.01);
  EXPECT_NEAR(circle->center_px.y(), 264.380, 0.01);
  EXPECT_NEAR(circle->radius_px, 70.897, 0.01);
}

TEST(LightCalibrationDiligent, HighlightsGiveDiligentsLightDirections) {
  if (!fs::exists(kDiligent / "scene.json")) GTEST_SKIP() << "no " << kDiligent;
  const fs::path out = test::UniqueTempDir("igi_lights_diligent") / "lights.json";
  // --saturated 1: the photos' clipped value (README).
  const auto r =
      RunTool("igi-calib", "lights --scene " + Quote((kDiligent / "scene.json").string()) +
                               " --sphere ball --saturated 1 --out " + Quote(out.string()));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Json lights = ReadJsonFile(out);
  const Json scene = ReadJsonFile(kDiligent / "scene.json");
  ASSERT_EQ(lights["format"], "igi-lights");
  ASSERT_EQ(lights["lights"].size(), 48u);
  std::vector<double> angles;
  std::string worst;
  for (const auto& [name, light] : lights["lights"].items()) {
    const Json& truth = scene["lights"][name];
    EXPECT_EQ(light["type"], "directional");
    EXPECT_EQ(light["irradiance"], truth["irradiance"]) << "kept from the scene without a target";
    const double a = AngleDeg(ToVec(light["direction"]), ToVec(truth["direction"]));
    if (angles.empty() || a > *std::max_element(angles.begin(), angles.end())) worst = name;
    angles.push_back(a);
  }
  std::sort(angles.begin(), angles.end());
  const double median = angles[angles.size() / 2], max = angles.back();
  std::printf("DiLiGenT ball, 48 lights: median %.3f deg, worst %.3f deg (%s)\n", median, max,
              worst.c_str());
  // Measured 0.38° median, 0.68° worst: a pixel of highlight error is 1.6° of light direction at
  // this 71 px radius, and DiLiGenT's own mirror-sphere directions carry an error of their own.
  EXPECT_LT(median, 0.6);
  EXPECT_LT(max, 1.2);
}

// --- A rendered glossy sphere under a point light, from three cameras ---

// An icosphere of radius 1 at the origin (region "ball", smooth normals) and a 6 m x 6 m
// floor card at z = −1.2 facing +z (region "card").
std::string SphereAndCardObj(int subdivisions) {
  std::vector<Eigen::Vector3d> v;
  std::vector<Eigen::Vector3i> f;
  const double t = (1 + std::sqrt(5.0)) / 2;
  for (const auto& p : std::vector<Eigen::Vector3d>{{-1, t, 0},
                                                    {1, t, 0},
                                                    {-1, -t, 0},
                                                    {1, -t, 0},
                                                    {0, -1, t},
                                                    {0, 1, t},
                                                    {0, -1, -t},
                                                    {0, 1, -t},
                                                    {t, 0, -1},
                                                    {t, 0, 1},
                                                    {-t, 0, -1},
                                                    {-t, 0, 1}}) {
    v.push_back(p.normalized());
  }
  f = {{0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
       {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
       {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (int s = 0; s < subdivisions; ++s) {
    std::map<std::pair<int, int>, int> mid;
    auto middle = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      v.push_back((v[size_t(a)] + v[size_t(b)]).normalized());
      return mid[key] = int(v.size()) - 1;
    };
    std::vector<Eigen::Vector3i> next;
    for (const Eigen::Vector3i& tri : f) {
      const int a = middle(tri[0], tri[1]), b = middle(tri[1], tri[2]), c = middle(tri[2], tri[0]);
      next.insert(next.end(), {{tri[0], a, c}, {tri[1], b, a}, {tri[2], c, b}, {a, b, c}});
    }
    f = next;
  }
  std::ostringstream s;
  for (const Eigen::Vector3d& p : v) s << "v " << p.x() << " " << p.y() << " " << p.z() << "\n";
  for (const Eigen::Vector3d& p : v) s << "vn " << p.x() << " " << p.y() << " " << p.z() << "\n";
  s << "usemtl ball\n";
  for (const Eigen::Vector3i& tri : f) {
    s << "f";
    for (int k = 0; k < 3; ++k) s << " " << tri[k] + 1 << "//" << tri[k] + 1;
    s << "\n";
  }
  const size_t n = v.size();
  s << "v -3 -3 -1.2\nv 3 -3 -1.2\nv 3 3 -1.2\nv -3 3 -1.2\nusemtl card\n";
  s << "f " << n + 1 << " " << n + 2 << " " << n + 3 << "\nf " << n + 1 << " " << n + 3 << " "
    << n + 4 << "\n";
  return s.str();
}

constexpr int kSize = 200;

// A PINHOLE camera at `eye` looking at `at` (world z up), f such that the unit sphere at 7 m
// spans about 70 px of radius.
Json LookAtCamera(const Eigen::Vector3d& eye, const Eigen::Vector3d& at) {
  const Eigen::Vector3d forward = (at - eye).normalized();
  const Eigen::Vector3d right = forward.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d down = forward.cross(right);
  Eigen::Matrix3d r;
  r.row(0) = right;
  r.row(1) = down;
  r.row(2) = forward;
  const Eigen::Quaterniond q(r);
  const Eigen::Vector3d t = -(r * eye);
  const double f = 500;
  return {{"model", "PINHOLE"},
          {"width", kSize},
          {"height", kSize},
          {"params", {f, f, kSize / 2.0, kSize / 2.0}},
          {"qvec", {q.w(), q.x(), q.y(), q.z()}},
          {"tvec", {t.x(), t.y(), t.z()}}};
}

const Eigen::Vector3d kLamp(1.6, 1.1, 2.4);
constexpr double kIntensity = 40.0, kCardRho = 0.5;

Json SyntheticScene(const std::vector<std::pair<std::string, Eigen::Vector3d>>& cameras,
                    const Eigen::Vector3d& look_at) {
  Json cams = Json::object(), photos = Json::array();
  for (const auto& [name, eye] : cameras) {
    cams[name] = LookAtCamera(eye, look_at);
    photos.push_back({{"file", "photos/" + name + ".exr"}, {"camera", name}, {"lighting", "L0"}});
  }
  return {{"format", "igi-scene"},
          {"version", 1},
          {"geometry", Json::array({{{"file", "geometry/scene.obj"}}})},
          {"materials",
           {{"ball", {{"brdf", "ward"}, {"rho_d", 0.1}, {"rho_s", 0.5}, {"alpha", 0.04}}},
            {"card", {{"brdf", "lambert"}, {"rho_d", kCardRho}}}}},
          {"lights", {{"lamp", {{"type", "point"}, {"position", {0, 0, 5}}, {"intensity", 1.0}}}}},
          {"lightings", {{"L0", {"lamp"}}}},
          {"cameras", cams},
          {"photos", photos}};
}

TEST(LightCalibrationSynthetic, PointLightPositionAndIntensityFromThreeViews) {
  const fs::path dir = test::UniqueTempDir("igi_lights_synth");
  fs::create_directories(dir / "geometry");
  fs::create_directories(dir / "photos");
  std::ofstream(dir / "geometry" / "scene.obj") << SphereAndCardObj(5);
  const std::vector<std::pair<std::string, Eigen::Vector3d>> cameras = {
      {"cam0", {6.5, -2.5, 2.0}}, {"cam1", {4.0, 5.5, 2.5}}, {"cam2", {-2.0, 6.5, 1.5}}};
  // The truth, rendered; the scene handed to igi-calib says the lamp is elsewhere, at 1 W/sr.
  Json truth = SyntheticScene(cameras, {0, 0, -0.3});
  truth["lights"]["lamp"] = {{"type", "point"},
                             {"position", {kLamp.x(), kLamp.y(), kLamp.z()}},
                             {"intensity", kIntensity}};
  truth["photos"] = Json::array();  // rendered from it, not yet there
  WriteJsonFile(dir / "truth_scene.json", truth);
  for (const auto& [name, eye] : cameras) {
    const auto r = RunTool("igi-render", Quote((dir / "truth_scene.json").string()) + " --camera " +
                                             name + " --lighting L0 --spp 16 --out " +
                                             Quote((dir / "photos" / (name + ".exr")).string()));
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  WriteJsonFile(dir / "scene.json", SyntheticScene(cameras, {0, 0, -0.3}));
  const fs::path out = dir / "lights.json";
  const auto r = RunTool("igi-calib", "lights --scene " + Quote((dir / "scene.json").string()) +
                                          " --sphere ball --target card --reflectance 0.5 --out " +
                                          Quote(out.string()));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Json lights = ReadJsonFile(out);
  const Json& lamp = lights["lights"]["lamp"];
  ASSERT_EQ(lamp["type"], "point");
  const double distance = kLamp.norm();  // from the sphere's centre
  const double position_error = (ToVec(lamp["position"]) - kLamp).norm() / distance;
  const double intensity_error = ToVec(lamp["intensity"]).mean() / kIntensity - 1;
  std::printf("point light at %.2f m: position error %.3f %% of the distance, intensity %+.2f %%\n",
              distance, 100 * position_error, 100 * intensity_error);
  EXPECT_EQ(lights["calibration"]["lamp"]["views"].size(), 3u);
  // 1 %: a light three sphere radii away seen from three sides (measured 0.2 %; the rays' baseline
  // is the sphere's own size, so 0.1 px of highlight error can move it 0.7 % of the distance).
  EXPECT_LT(position_error, 0.01);
  // 3 %: light the sphere reflects onto the card (measured +1.7 %, +0.2 % when rendered without
  // interreflection) and the position's own error, squared in d².
  EXPECT_LT(std::abs(intensity_error), 0.03);
}

TEST(LightCalibrationSynthetic, PhotoWithoutTheSphereExitsTwoAndWritesNothing) {
  const fs::path dir = test::UniqueTempDir("igi_lights_bad");
  fs::create_directories(dir / "geometry");
  fs::create_directories(dir / "photos");
  std::ofstream(dir / "geometry" / "scene.obj") << SphereAndCardObj(2);
  // cam0 sees the sphere; "away" looks 6 m to the side of it.
  Json scene = SyntheticScene({{"cam0", {6.5, -2.5, 2.0}}}, {0, 0, -0.3});
  scene["cameras"]["away"] = LookAtCamera({6.5, -2.5, 2.0}, {2.0, 6.0, 0});
  scene["photos"].push_back({{"file", "photos/away.exr"}, {"camera", "away"}, {"lighting", "L0"}});
  WriteJsonFile(dir / "scene.json", scene);
  // cam0's photo: a dim sphere with a bright spot; away's: anything.
  Image photo(kSize, kSize, 3, 0.05f);
  for (int y = 95; y < 100; ++y) {
    for (int x = 95; x < 100; ++x) photo.at(x, y, 0) = photo.at(x, y, 1) = photo.at(x, y, 2) = 1;
  }
  WriteImage(dir / "photos" / "cam0.exr", photo);
  WriteImage(dir / "photos" / "away.exr", photo);
  const fs::path out = dir / "out" / "lights.json";
  fs::create_directories(out.parent_path());
  const auto r = RunTool("igi-calib", "lights --scene " + Quote((dir / "scene.json").string()) +
                                          " --sphere ball --out " + Quote(out.string()));
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find("photos/away.exr"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::is_empty(out.parent_path())) << "something was written";
}

}  // namespace
}  // namespace igi::calib
