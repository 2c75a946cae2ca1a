// RADIANCE export: the radiance_room reference (its room_L0.rad materials, lamp and views are
// reproduced) and one of every mapping on a synthetic scene.
#include "solver/export/export_radiance.h"

#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <sstream>

#include "solver/export/export.h"
#include "solver/render/sampling.h"
#include "tests/export/export_test_scene.h"
#include "tests/temp_dir.h"
#include "tools/common/atomic_file.h"
#include "tools/common/strings.h"

namespace igi::exporter {
namespace {

struct Primitive {
  std::string modifier, type, name;
  std::vector<std::string> strings;
  std::vector<double> reals;
};

// A minimal RADIANCE scene reader: comments and `!command` lines skipped, then
// "modifier type name n_strings s... n_ints i... n_reals r..." records.
std::vector<Primitive> ParseRad(const std::filesystem::path& path) {
  std::istringstream lines(ReadFileToString(path));
  std::string line, text;
  while (std::getline(lines, line)) {
    const std::string t(Trim(line));
    if (t.empty() || t[0] == '#' || t[0] == '!') continue;
    text += t + "\n";
  }
  std::istringstream in(text);
  std::vector<Primitive> out;
  Primitive p;
  while (in >> p.modifier >> p.type >> p.name) {
    int n = 0;
    in >> n;
    p.strings.assign(n, "");
    for (auto& s : p.strings) in >> s;
    in >> n;
    EXPECT_EQ(n, 0);
    in >> n;
    p.reals.assign(n, 0.0);
    for (auto& r : p.reals) in >> r;
    out.push_back(p);
  }
  return out;
}

// The primitive called `name`; throws (failing the test) when there is none.
const Primitive& Find(const std::vector<Primitive>& prims, const std::string& name) {
  for (const auto& p : prims) {
    if (p.name == name) return p;
  }
  throw std::runtime_error("no primitive " + name);
}

int Count(const std::vector<Primitive>& prims, const std::string& type) {
  return int(std::count_if(prims.begin(), prims.end(), [&](auto& p) { return p.type == type; }));
}

// "-vp x y z" etc. of a .vf file.
std::map<std::string, std::vector<double>> ParseView(const std::filesystem::path& path) {
  std::istringstream in(ReadFileToString(path));
  std::map<std::string, std::vector<double>> view;
  std::string token, key;
  while (in >> token) {
    if (token.rfind("-v", 0) == 0) {
      key = token;
      view[key];
    } else if (!key.empty()) {
      view[key].push_back(std::stod(token));
    }
  }
  return view;
}

TEST(ExportRadiance, ReproducesTheReferenceRoom) {
  const recon::Scene scene = test::LoadRadianceRoom();
  const auto dir = test::UniqueTempDir("igi_export_rad") / "out";
  const ExportReport report = ExportScene(scene, dir, {.format = ExportFormat::kRadiance});
  const auto mine = ParseRad(dir / "scene.rad");
  const auto ref = ParseRad(test::RadianceRoomDir() / "radiance" / "room_L0.rad");

  // The reference prints 6 significant digits: 1e-5 covers its rounding.
  const std::map<std::string, std::string> ref_name = {
      {"floor", "floor_mat"},        {"ceiling", "ceil_mat"},  {"wall_x0", "red_wall"},
      {"wall_x4", "green_wall"},     {"wall_y4", "back_wall"}, {"wall_y0", "front_wall"},
      {"glossy_box", "glossy_blue"}, {"tall_box", "white_box"}};
  for (const auto& [region, ref_mat] : ref_name) {
    const Primitive& a = Find(mine, region);
    const Primitive& b = Find(ref, ref_mat);
    EXPECT_EQ(a.type, "plastic");
    ASSERT_EQ(a.reals.size(), 5u);
    for (int k = 0; k < 5; ++k) EXPECT_NEAR(a.reals[k], b.reals[k], 1e-5) << region << k;
  }
  const std::vector<double> glossy = {0.210526, 0.315789, 0.631579, 0.05, 0.1};
  for (int k = 0; k < 5; ++k) EXPECT_NEAR(Find(mine, "glossy_box").reals[k], glossy[k], 1e-5);

  // One polygon per triangle (18 RADIANCE quads = 36 triangles), 12 on the glossy box.
  EXPECT_EQ(Count(mine, "polygon"), 36);
  EXPECT_EQ(
      std::count_if(mine.begin(), mine.end(), [](auto& p) { return p.modifier == "glossy_box"; }),
      12);

  // Lighting L0: the lamp exactly as in room_L0.rad.
  const auto lights = ParseRad(dir / "lighting_L0.rad");
  ASSERT_EQ(lights.size(), 2u);
  EXPECT_EQ(lights[0].type, "light");
  EXPECT_EQ(lights[0].reals, Find(ref, "bulb").reals);
  EXPECT_EQ(lights[1].type, "sphere");
  EXPECT_EQ(lights[1].reals, Find(ref, "lamp").reals);
  EXPECT_EQ(ParseRad(dir / "lighting_L1.rad").size(), 2u);

  // Views: same position, direction, fields of view (up may differ within the vd-vu plane).
  for (const std::string cam : {"cam0", "cam1", "cam2"}) {
    auto a = ParseView(dir / (cam + ".vf"));
    auto b = ParseView(test::RadianceRoomDir() / "radiance" / (cam + ".vf"));
    const Eigen::Vector3d vd_a(a["-vd"].data()), vd_b(b["-vd"].data());
    EXPECT_LT((vd_a.normalized() - vd_b.normalized()).norm(), 1e-6) << cam;
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(a["-vp"][k], b["-vp"][k], 1e-6) << cam;
    EXPECT_NEAR(a["-vh"][0], b["-vh"][0], 1e-5);
    EXPECT_NEAR(a["-vv"][0], b["-vv"][0], 1e-5);
    const Eigen::Vector3d vu_a(a["-vu"].data());
    EXPECT_NEAR(vu_a.dot(vd_a.cross(Eigen::Vector3d::UnitZ()).normalized()), 0, 1e-6) << cam;
  }
  // Only exact mappings here, except the flat polygons.
  ASSERT_EQ(report.approximations.size(), 1u);
  EXPECT_EQ(report.approximations[0].item, "geometry");
  EXPECT_TRUE(std::filesystem::exists(dir / "export_report.json"));
}

TEST(ExportRadiance, MapsEveryMaterialAndLight) {
  const recon::Scene scene = test::SyntheticScene();
  const auto dir = test::UniqueTempDir("igi_export_rad") / "out";
  const ExportReport report = ExportScene(scene, dir, {.format = ExportFormat::kRadiance});
  const auto prims = ParseRad(dir / "scene.rad");
  // gold: ρs = ρd/2 -> metal with spec = 0.5/1.5, RGB = ρd/(1 - spec): exact.
  const Primitive& gold = Find(prims, "gold");
  EXPECT_EQ(gold.type, "metal");
  const double spec = 0.5 / 1.5;
  EXPECT_NEAR(gold.reals[3], spec, 1e-8);
  EXPECT_NEAR(gold.reals[0] * (1 - spec), 0.4, 1e-8);
  EXPECT_NEAR(gold.reals[0] * spec, 0.2, 1e-8);  // metal: ρs = RGB·spec
  EXPECT_NEAR(gold.reals[4], 0.2, 1e-12);
  // brushed: plastic2 with the tangent as u vector, urough/vrough = alpha_x/alpha_y.
  const Primitive& brushed = Find(prims, "brushed");
  EXPECT_EQ(brushed.type, "plastic2");
  EXPECT_EQ(brushed.strings, (std::vector<std::string>{"1", "0", "0", "."}));
  EXPECT_NEAR(brushed.reals[4], 0.05, 1e-12);
  EXPECT_NEAR(brushed.reals[5], 0.3, 1e-12);
  // old_ward: fitted GMD (alpha within 2%, spec 0.04 x ~0.77), reported with its error.
  const Primitive& old_ward = Find(prims, "old_ward");
  EXPECT_NEAR(old_ward.reals[4], 0.1, 0.002);
  EXPECT_NEAR(old_ward.reals[3], 0.04 * 0.77, 0.003);
  bool fit_reported = false;
  for (const auto& a : report.approximations) {
    if (a.item == "materials.old_ward" && a.relative_error) {
      fit_reported = true;
      EXPECT_NEAR(*a.relative_error, 0.18, 0.03);
    }
  }
  EXPECT_TRUE(fit_reported);
  EXPECT_EQ(Find(prims, "glow").type, "light");
  EXPECT_EQ(Count(prims, "polygon"), 10);

  const auto lights = ParseRad(dir / "lighting_all.rad");
  EXPECT_EQ(Count(lights, "light"), 4);  // bulb, sun, lamp, panel
  EXPECT_EQ(Count(lights, "spotlight"), 1);
  EXPECT_EQ(Count(lights, "sphere"), 3);  // bulb, spot, lamp
  EXPECT_EQ(Count(lights, "source"), 1);
  EXPECT_EQ(Count(lights, "polygon"), 2);
  // Point light: radiance I/(π r²) on a sphere of the default radius 0.01 m.
  EXPECT_NEAR(Find(lights, "bulb.mat").reals[0], 10 / (render::kPi * 1e-4), 1e-3);
  // Spot (cone 20°..30°): spotlight of full angle 50° along the direction.
  EXPECT_NEAR(Find(lights, "spot.mat").reals[3], 50, 0.1);
  EXPECT_EQ(Find(lights, "spot.mat").reals[6], -1);
  // Sun: source toward -direction.
  EXPECT_EQ(Find(lights, "sun").reals[2], 1);

  // Off-centre principal point: cx = 110 of 200 -> the image centre is 0.05 widths left of the
  // axis; cy = 45 of 100 -> 0.05 heights below it.
  auto view = ParseView(dir / "cam.vf");
  EXPECT_NEAR(view["-vs"][0], -0.05, 1e-9);
  EXPECT_NEAR(view["-vl"][0], -0.05, 1e-9);
  EXPECT_NEAR(view["-vh"][0], 2 * std::atan(1.0) * 180 / render::kPi, 1e-6);
}

TEST(ExportRadiance, RefusesIncompleteMaterialsAndBusyFolders) {
  recon::Scene scene = test::SyntheticScene();
  const auto dir = test::UniqueTempDir("igi_export_rad");
  WriteFileAtomic(dir / "busy" / "keep.txt", "x");
  EXPECT_THROW(ExportScene(scene, dir / "busy", {.format = ExportFormat::kRadiance}), InputError);
  EXPECT_EQ(ReadFileToString(dir / "busy" / "keep.txt"), "x");
  scene.materials[1].alpha.reset();
  EXPECT_THROW(ExportScene(scene, dir / "out", {.format = ExportFormat::kRadiance}), InputError);
  EXPECT_FALSE(std::filesystem::exists(dir / "out"));
}

}  // namespace
}  // namespace igi::exporter
