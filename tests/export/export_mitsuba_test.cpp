// Mitsuba 3 export: well-formed XML (checked by a small tag-balance reader), the counts of
// shapes, BSDFs, emitters and sensors, the meshes beside it and the fitted roughplastic.
#include "solver/export/export_mitsuba.h"

#include <gtest/gtest.h>

#include <regex>

#include "solver/export/export.h"
#include "tests/export/export_test_scene.h"
#include "tests/temp_dir.h"
#include "tools/common/atomic_file.h"
#include "tools/common/image.h"

namespace igi::exporter {
namespace {

struct XmlSummary {
  bool well_formed = false;
  std::map<std::string, int> open_tags;  // tag -> count (elements, self-closing included)
  std::map<std::string, int> types;      // "tag:type" -> count
  std::vector<std::string> filenames;    // <string name="filename" value="...">
  std::vector<std::string> top_level;    // tags of the <scene>'s children
};

// Checks that tags nest and close, the root is <scene>, and counts elements. Enough for the
// writer's output (no CDATA, no '>' inside attribute values).
XmlSummary ReadXml(const std::string& text) {
  XmlSummary s;
  std::vector<std::string> stack;
  const std::regex tag(R"re(<(/?)([A-Za-z_][\w.]*)([^>]*?)(/?)>)re");
  const std::regex type_attr(R"re(type="([^"]*)")re"),
      file_attr(R"re(name="filename" value="([^"]*)")re");
  std::string body = std::regex_replace(text, std::regex(R"re(<!--[\s\S]*?-->|<\?[^>]*\?>)re"), "");
  for (auto it = std::sregex_iterator(body.begin(), body.end(), tag); it != std::sregex_iterator();
       ++it) {
    const std::smatch& m = *it;
    const std::string name = m[2];
    if (m[1] == "/") {
      if (stack.empty() || stack.back() != name) return s;
      stack.pop_back();
      continue;
    }
    if (stack.size() == 1) s.top_level.push_back(name);
    if (stack.empty() && name != "scene") return s;
    ++s.open_tags[name];
    const std::string attrs = m[3];
    std::smatch a;
    if (std::regex_search(attrs, a, type_attr)) ++s.types[name + ":" + a[1].str()];
    if (std::regex_search(attrs, a, file_attr)) s.filenames.push_back(a[1]);
    if (m[4] != "/") stack.push_back(name);
  }
  s.well_formed = stack.empty() && s.open_tags["scene"] == 1;
  return s;
}

TEST(ExportMitsuba, RadianceRoom) {
  const recon::Scene scene = test::LoadRadianceRoom();
  const auto dir = test::UniqueTempDir("igi_export_mi") / "out";
  ExportScene(scene, dir, {.format = ExportFormat::kMitsuba});
  for (const std::string lighting : {"L0", "L1"}) {
    XmlSummary x = ReadXml(ReadFileToString(dir / ("scene_" + lighting + ".xml")));
    ASSERT_TRUE(x.well_formed) << lighting;
    EXPECT_EQ(x.types["sensor:perspective"], 3);
    EXPECT_EQ(x.types["integrator:path"], 1);
    EXPECT_EQ(x.types["shape:obj"], 8);     // one per region
    EXPECT_EQ(x.types["shape:sphere"], 1);  // the lamp of this lighting
    EXPECT_EQ(x.types["emitter:area"], 1);
    EXPECT_EQ(std::count(x.top_level.begin(), x.top_level.end(), "bsdf"), 8);
    EXPECT_EQ(x.types["bsdf:roughplastic"], 1);  // glossy_box
    EXPECT_EQ(x.types["bsdf:diffuse"], 7 + 1);   // lambert regions + the lamp's black bsdf
    for (const auto& f : x.filenames) EXPECT_TRUE(std::filesystem::exists(dir / f)) << f;
  }
  // The glossy box: beckmann with the fitted alpha near 0.1 and int_ior giving F0 = 0.05.
  const std::string xml = ReadFileToString(dir / "scene_L0.xml");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(xml, m, std::regex(R"re(name="alpha" value="([0-9.e-]+)")re")));
  EXPECT_NEAR(std::stod(m[1]), 0.1, 0.01);
  ASSERT_TRUE(std::regex_search(xml, m, std::regex(R"re(name="int_ior" value="([0-9.e-]+)")re")));
  const double eta = std::stod(m[1]);
  EXPECT_NEAR((eta - 1) * (eta - 1) / ((eta + 1) * (eta + 1)), 0.05, 1e-8);
}

TEST(ExportMitsuba, EveryLightType) {
  recon::Scene scene = test::SyntheticScene();
  const auto tmp = test::UniqueTempDir("igi_export_mi");
  const auto dir = tmp / "out";
  // A 4x2 linear albedo map on "matte": written as textures/matte.exr, values unchanged.
  Image texture;
  texture.width = 4, texture.height = 2, texture.channels = 3;
  texture.pixels.assign(4 * 2 * 3, 0.25f);
  WriteImage(tmp / "matte.exr", texture);
  scene.materials[0].rho_d_map = tmp / "matte.exr";
  ExportScene(scene, dir, {.format = ExportFormat::kMitsuba});
  XmlSummary x = ReadXml(ReadFileToString(dir / "scene_all.xml"));
  EXPECT_EQ(x.types["texture:bitmap"], 1);
  EXPECT_EQ(ReadImage(dir / "textures" / "matte.exr").pixels, texture.pixels);
  ASSERT_TRUE(x.well_formed);
  EXPECT_EQ(x.types["emitter:point"], 1);
  EXPECT_EQ(x.types["emitter:spot"], 1);
  EXPECT_EQ(x.types["emitter:directional"], 1);
  EXPECT_EQ(x.types["emitter:area"], 3);   // sphere lamp, area panel, emitter region "glow"
  EXPECT_EQ(x.types["shape:obj"], 5 + 1);  // regions + the panel
  for (const auto& f : x.filenames) EXPECT_TRUE(std::filesystem::exists(dir / f)) << f;
}

// A GGX region keeps its distribution: roughplastic with distribution ggx and the fitted alpha
// within 5 % of its own; the Ward regions stay beckmann.
TEST(ExportMitsuba, GgxKeepsItsDistribution) {
  recon::Scene scene = test::SyntheticScene();
  recon::Material& ggx = scene.materials[2];
  ggx.brdf = recon::BrdfModel::kGgx, ggx.alpha = 0.15;
  const auto dir = test::UniqueTempDir("igi_export_mi_ggx") / "out";
  ExportScene(scene, dir, {.format = ExportFormat::kMitsuba});
  const std::string xml = ReadFileToString(dir / "scene_all.xml");
  std::smatch m;
  const std::regex bsdf(
      R"re(<!-- old_ward \(ggx\) -->\s*<bsdf[^\n]*name="distribution" value="(\w+)"/><float name="alpha" value="([0-9.e-]+)")re");
  ASSERT_TRUE(std::regex_search(xml, m, bsdf)) << xml;
  EXPECT_EQ(m[1], "ggx");
  EXPECT_NEAR(std::stod(m[2]), 0.15, 0.05 * 0.15);
  EXPECT_EQ(ReadXml(xml).types["bsdf:roughplastic"], 3);  // gold, old_ward, brushed
  const std::regex beckmann(R"re(<!-- gold \(ward_gmd\) -->\s*<bsdf[^\n]*value="beckmann")re");
  EXPECT_TRUE(std::regex_search(xml, beckmann));
}

}  // namespace
}  // namespace igi::exporter
