// Highlight coverage against scenes whose highlights are known by construction: a glossy square
// at z = 0 lit by a light at (-1, 0, 2) mirrors it at the origin toward (1, 0, 2). Observations
// are made by this test's own ray caster (one per pixel centre of a pinhole camera).
#include "solver/inverse/highlight_coverage.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "solver/render/ray_scene.h"
#include "solver/synth/camera_placement.h"
#include "tests/solver/test_scenes.h"

namespace igi::solver {
namespace {

using Eigen::Vector3d;
using test::SquareObj;
using test::WriteText;

const Vector3d kLightPosition(-1, 0, 2);

// Region "glossy" (ward, ρs and α unknown): a square of half-size 0.5 at z = 0. Further regions
// off to the side: "matte" (lambert), "known" (ward, all known), "half" (ward, α unknown),
// "aniso" (anisotropic ward, α_x α_y known, ρs unknown). With `blocker`, a lambert square of
// half-size 0.4 at z = 1 centred on (-0.5, 0) shadows the glossy square's centre.
recon::Scene MakeScene(const std::filesystem::path& dir, const Json& light, bool blocker = false) {
  WriteText(dir / "glossy.obj", SquareObj("glossy", 0.5));
  WriteText(dir / "matte.obj", SquareObj("matte", 0.5, 0, false, 3));
  WriteText(dir / "known.obj", SquareObj("known", 0.5, 0, false, -3));
  WriteText(dir / "half.obj", SquareObj("half", 0.5, 0, false, 6));
  WriteText(dir / "aniso.obj", SquareObj("aniso", 0.5, 0, false, -6));
  WriteText(dir / "blocker.obj", SquareObj("blocker", 0.4, 1.0, true, -0.5));
  Json geometry = Json::array();
  for (const char* f : {"glossy.obj", "matte.obj", "known.obj", "half.obj", "aniso.obj"}) {
    geometry.push_back({{"file", f}});
  }
  if (blocker) geometry.push_back({{"file", "blocker.obj"}});
  Json materials = {
      {"glossy", ParseJson(R"({"brdf":"ward","rho_d":0.3})", "m")},
      {"matte", ParseJson(R"({"brdf":"lambert","rho_d":0.5})", "m")},
      {"known", ParseJson(R"({"brdf":"ward","rho_d":0.3,"rho_s":0.1,"alpha":0.05})", "m")},
      {"half", ParseJson(R"({"brdf":"ward","rho_d":0.3,"rho_s":0.1})", "m")},
      {"aniso", ParseJson(R"({"brdf":"ward_aniso","rho_d":0.3,"alpha_x":0.04,"alpha_y":0.09,
                             "tangent":[1,0,0]})",
                          "m")}};
  if (blocker) materials["blocker"] = ParseJson(R"({"brdf":"lambert","rho_d":0.5})", "m");
  const Json doc{{"format", "igi-scene"},       {"version", 1},
                 {"geometry", geometry},        {"materials", materials},
                 {"lights", {{"lamp", light}}}, {"lightings", {{"L0", {"lamp"}}}}};
  WriteJsonFile(dir / "scene.json", doc);
  return recon::LoadScene(dir / "scene.json", recon::SceneLoadOptions{.check_images = false});
}

Json PointLight() { return Json{{"type", "point"}, {"position", {-1, 0, 2}}, {"intensity", 10}}; }
Json SphereLight() {
  return Json{{"type", "sphere"}, {"center", {-1, 0, 2}}, {"radius", 0.1}, {"radiance", 100}};
}

// Adds a 64x48 camera at `eye` looking at `target` and its photo under lighting 0.
int AddPhoto(recon::Scene* scene, const Vector3d& eye, const Vector3d& target) {
  const int n = static_cast<int>(scene->photos.size());
  scene->cameras.push_back(synth::LookAtCamera("c" + std::to_string(n), eye, target, 64, 48, 40));
  recon::Photo photo;
  photo.file = scene->dir / ("p" + std::to_string(n) + ".exr");
  photo.camera = static_cast<int>(scene->cameras.size()) - 1;
  photo.lighting = 0;
  scene->photos.push_back(photo);
  return n;
}

// One observation per pixel centre that hits the scene mesh (flat faces: normal = face normal).
std::vector<Observation> Observe(const recon::Scene& scene, const render::RayScene& impl,
                                 int photo) {
  const recon::Camera& cam = scene.cameras[scene.photos[photo].camera];
  const Vector3d c = cam.CenterInWorld();
  std::vector<Observation> out;
  for (int y = 0; y < cam.height; ++y) {
    for (int x = 0; x < cam.width; ++x) {
      const Vector3d dir = cam.WorldRayFromImg(Eigen::Vector2d(x + 0.5, y + 0.5));
      const std::optional<render::RayHit> hit = impl.Intersect(c, dir);
      if (!hit || hit->triangle < 0) continue;
      Observation o;
      o.photo = photo;
      o.x = x;
      o.y = y;
      o.triangle = hit->triangle;
      o.region = scene.mesh.triangle_region[hit->triangle];
      o.position = (c + dir * hit->t).cast<float>();
      Eigen::Vector3f n = scene.mesh.FaceNormal(hit->triangle);
      if (n.cast<double>().dot(dir) > 0) n = -n;
      o.normal = n;
      o.view = (-dir).cast<float>();
      out.push_back(o);
    }
  }
  return out;
}

// Brute force for a point light without occluders: observations of `region` with
// tanθh < factor·alpha, and the smallest tanθh.
int LobeCount(const std::vector<Observation>& obs, int region, double limit, double* min_tan) {
  int count = 0;
  *min_tan = std::numeric_limits<double>::infinity();
  for (const Observation& o : obs) {
    if (o.region != region) continue;
    const Vector3d p = o.position.cast<double>();
    const Vector3d h = ((kLightPosition - p).normalized() + o.view.cast<double>()).normalized();
    const double c = h.dot(o.normal.cast<double>());
    const double tan = std::sqrt(1 - c * c) / c;
    *min_tan = std::min(*min_tan, tan);
    if (tan < limit) ++count;
  }
  return count;
}

struct Fixture {
  recon::Scene scene;
  std::vector<std::unique_ptr<render::RayScene>> scenes;
  std::vector<Observation> observations;
};

Fixture Make(const std::string& name, const Json& light, bool blocker = false) {
  Fixture f;
  f.scene = MakeScene(test::UniqueTempDir("igi_cover_" + name), light, blocker);
  f.scenes.push_back(std::make_unique<render::RayScene>(f.scene, 0));
  return f;
}

const RegionHighlightCoverage* Find(const std::vector<RegionHighlightCoverage>& c,
                                    const std::string& name) {
  for (const RegionHighlightCoverage& r : c) {
    if (r.name == name) return &r;
  }
  return nullptr;
}

TEST(HighlightCoverageTest, ListsOnlyGlossyRegionsWithUnknowns) {
  Fixture f = Make("list", PointLight());
  const auto coverage = AnalyseHighlightCoverage(f.scene, {}, f.scenes, {});
  std::vector<std::string> names;
  for (const auto& c : coverage) names.push_back(c.name);
  EXPECT_EQ(names, (std::vector<std::string>{"glossy", "half", "aniso"}));
  ASSERT_EQ(coverage.size(), 3u);
  EXPECT_FALSE(coverage[0].alpha_known);
  EXPECT_DOUBLE_EQ(coverage[0].alpha, 0.1);  // alpha_assumed
  EXPECT_TRUE(coverage[2].alpha_known);
  EXPECT_NEAR(coverage[2].alpha, 0.06, 1e-12);  // sqrt(0.04 * 0.09)
  // Nothing observed: every listed region is unobserved with no lit observation.
  for (const auto& c : coverage) {
    EXPECT_FALSE(c.observed);
    EXPECT_TRUE(std::isinf(c.min_tan_theta_h_over_alpha));
  }
}

class HighlightCoverageLights : public ::testing::TestWithParam<int> {
 protected:
  Json Light() const { return GetParam() == 0 ? PointLight() : SphereLight(); }
};

TEST_P(HighlightCoverageLights, CameraAtTheMirrorPositionSeesTheHighlight) {
  Fixture f = Make("mirror", Light());
  const int photo = AddPhoto(&f.scene, Vector3d(1, 0, 2), Vector3d::Zero());
  f.observations = Observe(f.scene, *f.scenes[0], photo);
  const int glossy = f.scene.FindMaterial("glossy");
  double min_tan = 0;
  const int expected = LobeCount(f.observations, glossy, 0.2, &min_tan);
  ASSERT_GT(expected, 10);
  const auto coverage = AnalyseHighlightCoverage(f.scene, f.observations, f.scenes, {});
  const RegionHighlightCoverage* c = Find(coverage, "glossy");
  ASSERT_NE(c, nullptr);
  EXPECT_TRUE(c->observed);
  EXPECT_TRUE(c->suggestions.empty());
  EXPECT_EQ(c->photos, std::vector<std::string>{"p0.exr"});
  if (GetParam() == 0) {
    // The point light's count is the brute force's; a pixel on the lobe's edge may round the
    // other way (float positions), hence ±1.
    EXPECT_NEAR(c->highlight_pixels, expected, 1);
    EXPECT_NEAR(c->min_tan_theta_h_over_alpha, min_tan / 0.1, 1e-5);
  } else {
    // A sphere of angular radius ~2.6° widens the lobe: at least the point light's pixels.
    EXPECT_GE(c->highlight_pixels, expected);
    EXPECT_LE(c->min_tan_theta_h_over_alpha, min_tan / 0.1 + 1e-5);
  }
}

TEST_P(HighlightCoverageLights, SideCameraGetsASuggestionThatWorks) {
  Fixture f = Make("side", Light());
  // From here the light's mirror image lies beyond the square's edge.
  const int side = AddPhoto(&f.scene, Vector3d(0, 1.5, 0.3), Vector3d::Zero());
  f.observations = Observe(f.scene, *f.scenes[0], side);
  const int glossy = f.scene.FindMaterial("glossy");
  double min_tan = 0;
  ASSERT_EQ(LobeCount(f.observations, glossy, 0.2, &min_tan), 0);
  ASSERT_GT(std::count_if(f.observations.begin(), f.observations.end(),
                          [&](const Observation& o) { return o.region == glossy; }),
            100);
  const auto coverage = AnalyseHighlightCoverage(f.scene, f.observations, f.scenes, {});
  const RegionHighlightCoverage* c = Find(coverage, "glossy");
  ASSERT_NE(c, nullptr);
  EXPECT_FALSE(c->observed);
  EXPECT_EQ(c->highlight_pixels, 0);
  EXPECT_TRUE(std::isfinite(c->min_tan_theta_h_over_alpha));
  EXPECT_GT(c->min_tan_theta_h_over_alpha, 2.0);
  ASSERT_FALSE(c->suggestions.empty());
  const HighlightSuggestion& s = c->suggestions.front();
  EXPECT_EQ(s.lighting, "L0");
  EXPECT_EQ(s.light, "lamp");
  EXPECT_NE(s.text.find("stand at ("), std::string::npos) << s.text;
  EXPECT_NE(s.text.find("lamp's highlight on glossy"), std::string::npos) << s.text;
  EXPECT_GT(s.highlight_area_m2, 0);
  EXPECT_LE(s.highlight_area_m2, 1.0 + 1e-9);  // the square's area
  EXPECT_NEAR(s.distance_m, (s.position - s.look_at).norm(), 1e-12);
  // Distance: the median from the side camera to the observed glossy pixels (~1.5 m), at most.
  EXPECT_LT(s.distance_m, 1.7);
  EXPECT_GT(s.distance_m, 0.15);
  EXPECT_LT(std::abs(s.look_at.x()), 0.5 + 1e-6);
  EXPECT_LT(std::abs(s.look_at.y()), 0.5 + 1e-6);
  EXPECT_NEAR(s.look_at.z(), 0, 1e-6);
  EXPECT_GT(s.position.z(), 0);  // above the square, on the light's side

  // A camera placed there sees the highlight.
  const int suggested = AddPhoto(&f.scene, s.position, s.look_at);
  const std::vector<Observation> seen = Observe(f.scene, *f.scenes[0], suggested);
  const auto again = AnalyseHighlightCoverage(f.scene, seen, f.scenes, {});
  const RegionHighlightCoverage* d = Find(again, "glossy");
  ASSERT_NE(d, nullptr);
  EXPECT_TRUE(d->observed);
  EXPECT_GT(d->highlight_pixels, 10);
  if (GetParam() == 0) {
    EXPECT_GT(LobeCount(seen, glossy, 0.2, &min_tan), 10);  // independent of the library
  }
}

INSTANTIATE_TEST_SUITE_P(PointAndSphere, HighlightCoverageLights, ::testing::Values(0, 1));

TEST(HighlightCoverageTest, ShadowedHighlightDoesNotCount) {
  Fixture f = Make("shadow", PointLight(), /*blocker=*/true);
  const int photo = AddPhoto(&f.scene, Vector3d(1, 0, 2), Vector3d::Zero());
  f.observations = Observe(f.scene, *f.scenes[0], photo);
  const int glossy = f.scene.FindMaterial("glossy");
  double min_tan = 0;
  // The camera sees the highlight's pixels (geometrically inside the lobe) ...
  ASSERT_GT(LobeCount(f.observations, glossy, 0.2, &min_tan), 10);
  const auto coverage = AnalyseHighlightCoverage(f.scene, f.observations, f.scenes, {});
  const RegionHighlightCoverage* c = Find(coverage, "glossy");
  ASSERT_NE(c, nullptr);
  // ... but the blocker shadows them all (its shadow covers x, y in [-0.8, 0.8]).
  EXPECT_FALSE(c->observed);
  EXPECT_EQ(c->highlight_pixels, 0);
  EXPECT_TRUE(c->photos.empty());
}

TEST(HighlightCoverageTest, JsonAndValidation) {
  Fixture f = Make("json", PointLight());
  const int photo = AddPhoto(&f.scene, Vector3d(1, 0, 2), Vector3d::Zero());
  f.observations = Observe(f.scene, *f.scenes[0], photo);
  const Json j =
      HighlightCoverageJson(AnalyseHighlightCoverage(f.scene, f.observations, f.scenes, {}));
  ASSERT_TRUE(j.is_array());
  ASSERT_EQ(j.size(), 3u);
  EXPECT_EQ(j[0]["region"], "glossy");
  EXPECT_EQ(j[0]["observed"], true);
  EXPECT_EQ(j[0]["photos"], Json::array({"p0.exr"}));
  EXPECT_TRUE(j[0]["min_tan_theta_h_over_alpha"].is_number());
  // "half" and "aniso" lie at x = 6 and -6, outside the camera's view: no observation, null.
  EXPECT_EQ(j[1]["region"], "half");
  EXPECT_TRUE(j[1]["min_tan_theta_h_over_alpha"].is_null());
  ASSERT_FALSE(j[1]["suggestions"].empty());
  EXPECT_TRUE(j[1]["suggestions"][0]["text"].is_string());
  EXPECT_EQ(j[1]["suggestions"][0]["position"].size(), 3u);

  HighlightCoverageOptions bad;
  bad.alpha_assumed = 0;
  EXPECT_THROW(bad.Validate(), InputError);
  bad = HighlightCoverageOptions{};
  bad.light_samples = 0;
  EXPECT_THROW(AnalyseHighlightCoverage(f.scene, {}, f.scenes, bad), InputError);
}

}  // namespace
}  // namespace igi::solver
