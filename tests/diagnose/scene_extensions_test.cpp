// The scene.json extensions igi-diagnose writes, end to end through the loader and the renderer:
// an ambient light adds ρd·L to a diffuse surface (unoccluded, evaluated exactly) and
// L·(ρd + ρs·A(wo)) to a Ward surface, a camera's vignetting scales the
// render by 1 + k1 r² + k2 r⁴, and bad values are reported with their key.
#include <gtest/gtest.h>

#include <cmath>

#include "solver/render/brdf.h"
#include "solver/render/render.h"
#include "tests/solver/test_scenes.h"
#include "tools/common/error.h"

namespace igi::diagnose {
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

// The renderer evaluates an ambient light exactly (no samples) for the diffuse term: on an open
// plane (paths leave after the first vertex) every pixel is ρd·L at 1 path per pixel, up to float
// rounding; with a sun beside it (a delta light on an unoccluded plane: next-event estimation is
// exact too) the ambient light is not among the sampled lights, so the sum stays exact.
TEST(SceneExtensionsTest, AmbientLightAddsAlbedoTimesRadianceExactly) {
  const auto dir = TempSceneDir("ambient");
  WriteText(dir / "plane.obj", SquareObj("plane", 5.0));
  const Json camera = DownCamera(0, 0, 1, 16, 16, 20);
  const Json amb = {{"type", "ambient"}, {"radiance", {2.0, 2.0, 2.0}}};
  const Json sun = {{"type", "directional"}, {"direction", {0, 0.6, -0.8}},
                    {"irradiance", {1.0, 1.0, 1.0}}};
  const recon::Scene ambient_only = LoadTestScene(dir, PlaneScene({{"amb", amb}}, {"amb"}, camera));
  ASSERT_EQ(ambient_only.lights[0].type, recon::LightType::kAmbient);
  const recon::Scene with_sun =
      LoadTestScene(dir, PlaneScene({{"amb", amb}, {"sun", sun}}, {"amb", "sun"}, camera));
  render::RenderOptions ro;
  ro.spp = 1;
  const Image a = render::Renderer(ambient_only, 0).Render(ambient_only.cameras[0], ro);
  const Image b = render::Renderer(with_sun, 0).Render(with_sun.cameras[0], ro);
  const double rho[3] = {0.5, 0.4, 0.2};
  for (int y = 0; y < 16; ++y) {
    for (int x = 0; x < 16; ++x) {
      for (int c = 0; c < 3; ++c) {
        // ρd·L, and ρd/π·E·cosθ of the sun (cos 0.8) on top: float rounding only (1e-6).
        EXPECT_NEAR(a.at(x, y, c), rho[c] * 2.0, 1e-6) << x << "," << y << "," << c;
        EXPECT_NEAR(b.at(x, y, c), rho[c] * (2.0 + 0.8 / render::kPi), 1e-6)
            << x << "," << y << "," << c;
      }
    }
  }
}

// A Ward lobe under an ambient light reflects L·(ρd + ρs·A(wo)), A the lobe's directional albedo
// ∫ S(wo, wi) cosθi dωi. The renderer estimates the lobe's part with one direction drawn from the
// lobe per vertex; the reference here is a midpoint quadrature of the BRDF's definition.
TEST(SceneExtensionsTest, AmbientLightOnAGlossyLobeMatchesTheQuadrature) {
  const auto dir = TempSceneDir("ambient_glossy");
  WriteText(dir / "plane.obj", SquareObj("plane", 50.0));
  Json doc = PlaneScene({{"amb", {{"type", "ambient"}, {"radiance", {1.0, 1.0, 1.0}}}}}, {"amb"},
                        DownCamera(0, 0, 1, 16, 16, 20));
  doc["materials"]["plane"] = {{"brdf", "ward"}, {"rho_d", {0.2, 0.2, 0.2}},
                               {"rho_s", {0.3, 0.3, 0.3}}, {"alpha", 0.15}};
  const recon::Scene scene = LoadTestScene(dir, doc);
  const render::Renderer renderer(scene, 0);
  render::BrdfParams lobe;
  lobe.model = recon::BrdfModel::kWard;
  lobe.rho_s = Eigen::Vector3d::Constant(0.3);
  lobe.alpha = 0.15;
  for (const double theta_deg : {0.0, 45.0, 70.0}) {
    const double theta = theta_deg * render::kPi / 180;
    const Eigen::Vector3d wo(std::sin(theta), 0, std::cos(theta));  // toward the viewer
    // Midpoint rule over (θi, φi), 1200 × 2400 cells: its error is far below the tolerance.
    const int n_theta = 1200, n_phi = 2400;
    double integral = 0;
    for (int i = 0; i < n_theta; ++i) {
      const double ti = (i + 0.5) * (render::kPi / 2) / n_theta;
      for (int j = 0; j < n_phi; ++j) {
        const double pj = (j + 0.5) * 2 * render::kPi / n_phi;
        const Eigen::Vector3d wi(std::sin(ti) * std::cos(pj), std::sin(ti) * std::sin(pj),
                                 std::cos(ti));
        integral += render::EvalBrdf(lobe, wo, wi)[0] * std::cos(ti) * std::sin(ti);
      }
    }
    integral *= (render::kPi / 2 / n_theta) * (2 * render::kPi / n_phi);
    const double expected = 0.2 + integral;
    // 4096 paths along one ray (they end on the open plane after one vertex), one direction
    // drawn from the lobe per path: the mean's standard error is well under 0.5 % at these
    // views, so 1 % of the quadrature.
    const Eigen::Vector3d origin = wo * 2.0;
    const Eigen::Vector3d mean = renderer.Radiance(origin, -wo, 4096, 5);
    EXPECT_NEAR(mean[0], expected, 0.01 * expected) << "view " << theta_deg << " deg";
    // And one path alone: the ambient light adds no uniform-sphere noise (the old sampling's
    // single path was 0 or up to 4·ρd·L); within 25 % of the mean up to 45° from the normal. At
    // 70° a good part of the lobe's draws mirror below the horizon (the path is then ρd·L alone,
    // −33 %): only the mean is checked there.
    for (uint64_t seed = 0; seed < 16 && theta_deg < 60; ++seed) {
      EXPECT_NEAR(renderer.Radiance(origin, -wo, 1, seed)[0], expected, 0.25 * expected)
          << "view " << theta_deg << " deg, seed " << seed;
    }
  }
}

TEST(SceneExtensionsTest, CameraVignettingScalesTheRender) {
  const auto dir = TempSceneDir("vignetting");
  WriteText(dir / "plane.obj", SquareObj("plane", 50.0));
  Json cam = DownCamera(0, 0, 1, 40, 30, 20);
  const Json lights = {{"sun", {{"type", "directional"}, {"direction", {0, 0, -1}},
                                {"irradiance", {1, 1, 1}}}}};
  const recon::Scene plain = LoadTestScene(dir, PlaneScene(lights, {"sun"}, cam));
  cam["vignetting"] = {{"k1", -0.3}, {"k2", -0.1}};
  const recon::Scene vignetted = LoadTestScene(dir, PlaneScene(lights, {"sun"}, cam));
  render::RenderOptions ro;
  ro.spp = 4;
  const Image a = render::Renderer(plain, 0).Render(plain.cameras[0], ro);
  const Image b = render::Renderer(vignetted, 0).Render(vignetted.cameras[0], ro);
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
}  // namespace igi::diagnose
