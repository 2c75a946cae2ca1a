// The scene.json extensions igi-diagnose writes, end to end through the loader and the renderer:
// an ambient light adds ρd·L to a diffuse surface (unoccluded), a camera's vignetting scales the
// render by 1 + k1 r² + k2 r⁴, and bad values are reported with their key.
#include <gtest/gtest.h>

#include <cmath>

#include "solver/render.h"
#include "tests/solver/test_scenes.h"
#include "tools/common/error.h"

namespace igi {
namespace {

using test::DownCamera;
using test::LoadTestScene;
using test::SquareObj;
using test::TempSceneDir;
using test::WriteText;

Json PlaneScene(const Json& lights, const Json& lighting, const Json& camera) {
  return Json{{"format", "igi-scene"},
              {"version", 1},
              {"geometry", {{{"file", "plane.obj"}}}},
              {"materials", {{"plane", {{"brdf", "lambert"}, {"rho_d", {0.5, 0.4, 0.2}}}}}},
              {"lights", lights},
              {"lightings", {{"L0", lighting}}},
              {"cameras", {{"cam", camera}}}};
}

TEST(SceneExtensionsTest, AmbientLightAddsAlbedoTimesRadianceUnoccluded) {
  const auto dir = TempSceneDir("ambient");
  WriteText(dir / "plane.obj", SquareObj("plane", 5.0));
  const Json lights = {{"amb", {{"type", "ambient"}, {"radiance", {2.0, 2.0, 2.0}}}}};
  const Scene scene = LoadTestScene(dir, PlaneScene(lights, {"amb"}, DownCamera(0, 0, 1, 16, 16, 20)));
  ASSERT_EQ(scene.lights[0].type, LightType::kAmbient);
  RenderOptions ro;
  ro.spp = 256;
  const Image img = Renderer(scene, 0).Render(scene.cameras[0], ro);
  double mean[3] = {0, 0, 0};
  for (int y = 0; y < 16; ++y) {
    for (int x = 0; x < 16; ++x) {
      for (int c = 0; c < 3; ++c) mean[c] += img.at(x, y, c) / 256.0;
    }
  }
  // ∫ ρ/π · L cos dω over the hemisphere = ρ·L; 65 536 paths, uniform-sphere sampling: ±1 %.
  EXPECT_NEAR(mean[0], 0.5 * 2.0, 0.02);
  EXPECT_NEAR(mean[1], 0.4 * 2.0, 0.016);
  EXPECT_NEAR(mean[2], 0.2 * 2.0, 0.008);
}

TEST(SceneExtensionsTest, CameraVignettingScalesTheRender) {
  const auto dir = TempSceneDir("vignetting");
  WriteText(dir / "plane.obj", SquareObj("plane", 50.0));
  Json cam = DownCamera(0, 0, 1, 40, 30, 20);
  const Json lights = {{"sun", {{"type", "directional"}, {"direction", {0, 0, -1}},
                                {"irradiance", {1, 1, 1}}}}};
  const Scene plain = LoadTestScene(dir, PlaneScene(lights, {"sun"}, cam));
  cam["vignetting"] = {{"k1", -0.3}, {"k2", -0.1}};
  const Scene vignetted = LoadTestScene(dir, PlaneScene(lights, {"sun"}, cam));
  RenderOptions ro;
  ro.spp = 4;
  const Image a = Renderer(plain, 0).Render(plain.cameras[0], ro);
  const Image b = Renderer(vignetted, 0).Render(vignetted.cameras[0], ro);
  // Same seed, same paths: the ratio is the factor exactly (float rounding).
  for (const auto& [x, y] : std::vector<std::pair<int, int>>{{0, 0}, {20, 15}, {39, 29}, {10, 5}}) {
    const double f = vignetted.cameras[0].VignettingFactor(Eigen::Vector2d(x + 0.5, y + 0.5));
    EXPECT_NEAR(b.at(x, y, 0) / a.at(x, y, 0), f, 1e-5) << x << "," << y;
  }
  // The corner pixel centre lies at r² = (19.5² + 14.5²) / 25² ≈ 0.945.
  EXPECT_NEAR(vignetted.cameras[0].VignettingFactor(Eigen::Vector2d(0.5, 0.5)),
              1 - 0.3 * 0.945 - 0.1 * 0.945 * 0.945, 2e-3);
}

TEST(SceneExtensionsTest, BadValuesNameTheirKey) {
  const auto dir = TempSceneDir("bad_extensions");
  WriteText(dir / "plane.obj", SquareObj("plane", 5.0));
  Json cam = DownCamera(0, 0, 1, 16, 16, 20);
  cam["vignetting"] = {{"k1", -0.9}, {"k2", -0.5}};
  Json doc = PlaneScene({{"amb", {{"type", "ambient"}, {"radiance", {-1, 0, 0}}}}}, {"amb"}, cam);
  try {
    LoadTestScene(dir, doc);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("cameras.cam.vignetting"), std::string::npos) << what;
    EXPECT_NE(what.find("lights.amb.radiance"), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace igi
