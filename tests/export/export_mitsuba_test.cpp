// Mitsuba 3 export: well-formed XML (checked by a small tag-balance reader), the counts of
// shapes, BSDFs, emitters and sensors, the meshes beside it and the fitted roughplastic; the
// load_dict dictionary built from the same description, and unique ids.
#include "solver/export/export_mitsuba.h"

#include <gtest/gtest.h>

#include <regex>

#include "solver/export/export.h"
#include "tests/export/export_test_scene.h"
#include "tests/temp_dir.h"
#include "tools/common/atomic_file.h"
#include "tools/common/image.h"
#include "tools/common/json.h"

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

// The load_dict dictionary of a lighting holds every top-level object of the XML of that lighting
// under its id, with the XML's plugin type, and the values of the one description both come from.
TEST(ExportMitsuba, SceneDictHasTheXmlObjects) {
  recon::Scene scene = test::SyntheticScene();
  const auto tmp = test::UniqueTempDir("igi_export_mi_dict");
  ExportScene(scene, tmp / "xml", {.format = ExportFormat::kMitsuba});
  ExportReport report;
  const Json d =
      MitsubaSceneDict(scene, 0, {.format = ExportFormat::kMitsuba}, tmp / "dict", &report);
  EXPECT_EQ(d["type"], "scene");
  EXPECT_EQ(d["integrator"]["type"], "path");
  const std::string xml = ReadFileToString(tmp / "xml" / "scene_all.xml");
  const std::regex top(R"re(\n  <(\w+) type="([^"]+)" id="([^"]+)")re");
  int objects = 0;
  for (auto it = std::sregex_iterator(xml.begin(), xml.end(), top); it != std::sregex_iterator();
       ++it, ++objects) {
    const std::string id = (*it)[3];
    ASSERT_TRUE(d.contains(id)) << id;
    EXPECT_EQ(d[id]["type"], (*it)[2].str()) << id;
  }
  EXPECT_EQ(objects, 1 + 2 * 5 + 5);  // the sensor, a BSDF and a shape per region, the lights
  EXPECT_EQ(d.size(), size_t(objects) + 2);  // and "type", "integrator"
  // A shape refers to its BSDF; the emitter region carries its area emitter.
  EXPECT_EQ(d["glow"]["bsdf"], Json({{"type", "ref"}, {"id", "bsdf.glow"}}));
  EXPECT_EQ(d["glow"]["emitter"]["radiance"]["value"], Json::array({5.0, 5.0, 5.0}));
  EXPECT_EQ(d["bsdf.matte"]["bsdf"]["reflectance"]["value"], Json::array({0.5, 0.4, 0.3}));
  EXPECT_EQ(d["bulb"]["position"], Json::array({0.5, 0.5, 3.0}));
  EXPECT_EQ(d["cam"]["film"]["width"], 200);
  EXPECT_EQ(d["cam"]["sampler"]["sample_count"], 256);
  // The camera's to_world is Mitsuba's look_at: its third column the viewing direction (the
  // camera's z in the world), its fourth the centre, its first the image's left (−x).
  const Json& m = d["cam"]["to_world"]["matrix"];
  EXPECT_EQ(d["cam"]["to_world"]["type"], "transform");
  const Eigen::Matrix3d world_from_cam =
      scene.cameras[0].cam_from_world.rotation.toRotationMatrix().transpose();
  const Eigen::Vector3d center = scene.cameras[0].CenterInWorld();
  for (int r = 0; r < 3; ++r) {
    EXPECT_NEAR(m[r][0].get<double>(), -world_from_cam(r, 0), 1e-12);
    EXPECT_NEAR(m[r][1].get<double>(), -world_from_cam(r, 1), 1e-12);
    EXPECT_NEAR(m[r][2].get<double>(), world_from_cam(r, 2), 1e-12);
    EXPECT_NEAR(m[r][3].get<double>(), center(r), 1e-12);
  }
  // Filenames are absolute and written: the regions' meshes, the area light's, no XML.
  for (const std::string id : {"matte", "glow", "panel"}) {
    const std::filesystem::path file = d[id]["filename"].get<std::string>();
    EXPECT_TRUE(file.is_absolute()) << file;
    EXPECT_TRUE(std::filesystem::exists(file)) << file;
  }
  EXPECT_FALSE(std::filesystem::exists(tmp / "dict" / "scene_all.xml"));
  EXPECT_FALSE(report.approximations.empty());
  // Another call into the same folder replaces the files.
  EXPECT_NO_THROW(
      MitsubaSceneDict(scene, 0, {.format = ExportFormat::kMitsuba}, tmp / "dict", &report));
  EXPECT_THROW(
      MitsubaSceneDict(scene, 1, {.format = ExportFormat::kMitsuba}, tmp / "dict", &report),
      InputError);
}

// Names that would give two objects one id get "_2", "_3", ... in both outputs.
TEST(ExportMitsuba, IdsAreUnique) {
  recon::Scene scene = test::SyntheticScene();
  scene.cameras[0].name = "matte";
  scene.lights[0].name = "matte";
  const auto tmp = test::UniqueTempDir("igi_export_mi_ids");
  ExportScene(scene, tmp / "xml", {.format = ExportFormat::kMitsuba});
  const std::string xml = ReadFileToString(tmp / "xml" / "scene_all.xml");
  EXPECT_NE(xml.find("<sensor type=\"perspective\" id=\"matte\">"), std::string::npos);
  EXPECT_NE(xml.find("<shape type=\"obj\" id=\"matte_2\">"), std::string::npos);
  EXPECT_NE(xml.find("<ref id=\"bsdf.matte_2\"/>"), std::string::npos);
  EXPECT_NE(xml.find("<emitter type=\"point\" id=\"matte_3\">"), std::string::npos);
  ExportReport report;
  const Json d =
      MitsubaSceneDict(scene, 0, {.format = ExportFormat::kMitsuba}, tmp / "dict", &report);
  EXPECT_EQ(d["matte"]["type"], "perspective");
  EXPECT_EQ(d["matte_2"]["type"], "obj");
  EXPECT_EQ(d["matte_3"]["type"], "point");
}

}  // namespace
}  // namespace igi::exporter
