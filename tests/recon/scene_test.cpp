#include "recon/scene.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <tuple>

#include "recon/colmap_model.h"

namespace igi::recon {
namespace {

namespace fs = std::filesystem;
const fs::path kMini = fs::path(IGI_SOURCE_DIR) / "tests/data/scenes/mini/scene.json";
const fs::path kData(IGI_SHARED_DATA_DIR);

TEST(SceneTest, MiniSceneLoadsEveryPart) {
  const Scene scene = LoadScene(kMini);
  ASSERT_EQ(scene.materials.size(), 4u);
  EXPECT_EQ(scene.mesh.num_triangles(), 22u);
  EXPECT_TRUE(scene.mesh.has_uvs());

  const Material& floor = scene.materials[scene.FindMaterial("floor")];
  EXPECT_EQ(floor.brdf, BrdfModel::kWard);
  ASSERT_TRUE(floor.rho_d_map);
  EXPECT_TRUE(floor.rho_d_map->is_absolute());
  EXPECT_EQ(*floor.rho_s, Eigen::Vector3d::Constant(0.04));
  EXPECT_TRUE(floor.MissingForRendering().empty());
  EXPECT_EQ(*scene.materials[scene.FindMaterial("ceiling")].rho_d, Eigen::Vector3d::Constant(0.8));
  const Material& box = scene.materials[scene.FindMaterial("box")];
  EXPECT_EQ(box.brdf, BrdfModel::kWardAniso);
  EXPECT_EQ(box.MissingForRendering(),
            (std::vector<std::string>{"rho_d", "rho_s", "alpha_x", "alpha_y"}));

  // Every triangle is bound to a material index; the box's 10 triangles to "box".
  size_t box_triangles = 0;
  for (int r : scene.mesh.triangle_region) box_triangles += r == scene.FindMaterial("box");
  EXPECT_EQ(box_triangles, 10u);

  ASSERT_EQ(scene.lights.size(), 7u);
  const Light& spot = scene.lights[scene.FindLight("spot")];
  EXPECT_EQ(spot.type, LightType::kSpot);
  EXPECT_NEAR(spot.direction.norm(), 1.0, 1e-12);
  ASSERT_EQ(spot.profile.kind, SpotProfile::Kind::kIes);
  EXPECT_NEAR(spot.profile.Relative(0, 0), 1.0, 1e-12);  // peak on the axis
  EXPECT_NEAR(spot.profile.Relative(45 * M_PI / 180, 0), 0.6, 1e-9);
  const Light& cone = scene.lights[scene.FindLight("spot2")];
  EXPECT_EQ(cone.intensity, Eigen::Vector3d::Constant(5));
  EXPECT_DOUBLE_EQ(cone.profile.Relative(10 * M_PI / 180, 0), 1.0);
  EXPECT_DOUBLE_EQ(cone.profile.Relative(25 * M_PI / 180, 0), 0.5);
  EXPECT_DOUBLE_EQ(cone.profile.Relative(31 * M_PI / 180, 0), 0.0);
  const Light& cosp = scene.lights[scene.FindLight("spot3")];
  EXPECT_NEAR(cosp.profile.Relative(M_PI / 3, 0), std::pow(0.5, 4), 1e-12);
  const Light& panel = scene.lights[scene.FindLight("panel")];
  EXPECT_EQ(panel.mesh.num_triangles(), 2u);
  EXPECT_NEAR(panel.mesh.FaceNormal(0).z(), -1.0f, 1e-6f);  // faces down into the room
  EXPECT_EQ(scene.lights[scene.FindLight("bulb")].radius, 0.05);

  ASSERT_EQ(scene.lightings.size(), 3u);
  EXPECT_EQ(scene.lightings[1].lights,
            (std::vector<int>{scene.FindLight("spot"), scene.FindLight("panel")}));

  ASSERT_EQ(scene.cameras.size(), 2u);
  EXPECT_EQ(scene.cameras[1].model, CameraModel::kOpenCv);
  EXPECT_NEAR((scene.cameras[0].CenterInWorld() - Eigen::Vector3d(1, 1, 1)).norm(), 0, 1e-12);
  ASSERT_EQ(scene.photos.size(), 2u);
  EXPECT_TRUE(scene.photos[0].mask.has_value());
  EXPECT_FALSE(scene.photos[1].mask.has_value());
  EXPECT_EQ(scene.photos[1].lighting, scene.FindLighting("L1"));
  EXPECT_EQ(scene.document["materials"]["box"]["brdf"], "ward_aniso");
}

TEST(SceneTest, RenderingRequiresCompleteMaterials) {
  SceneLoadOptions options;
  options.require_complete_materials = true;
  try {
    LoadScene(kMini, options);
    FAIL();
  } catch (const InputError& e) {
    ASSERT_EQ(e.problems().size(), 1u);
    EXPECT_NE(e.problems()[0].find("materials.box"), std::string::npos);
    EXPECT_NE(e.problems()[0].find("missing rho_d, rho_s, alpha_x, alpha_y"), std::string::npos);
  }
}

TEST(SceneTest, SharedReferenceAndRealScenesLoad) {
  const Scene room = LoadScene(kData / "reference/radiance_room/scene.json");
  EXPECT_EQ(room.materials.size(), 8u);
  EXPECT_EQ(room.mesh.num_triangles(), 36u);
  EXPECT_EQ(room.photos.size(), 4u);
  EXPECT_EQ(room.materials[room.FindMaterial("glossy_box")].brdf, BrdfModel::kWardGmd);
  EXPECT_NEAR(room.lights[room.FindLight("lamp")].radius, 0.1, 1e-12);
  // cam0 stands at (2, 0.3, 1.5) (README of radiance_room).
  EXPECT_NEAR(
      (room.cameras[room.FindCamera("cam0")].CenterInWorld() - Eigen::Vector3d(2, 0.3, 1.5)).norm(),
      0.0, 1e-6);

  const Scene ball = LoadScene(kData / "real/diligent_ball/scene.json");
  EXPECT_EQ(ball.photos.size(), 48u);
  EXPECT_EQ(ball.lights.size(), 48u);
  EXPECT_EQ(ball.lights[0].type, LightType::kDirectional);
  EXPECT_FALSE(ball.materials[0].rho_d.has_value());  // unknown: the solver's job
  EXPECT_NEAR((ball.cameras[0].CenterInWorld() - Eigen::Vector3d(0, 0, 50)).norm(), 0, 1e-9);
  EXPECT_TRUE(ball.photos[0].mask.has_value());
}

TEST(SceneTest, EveryProblemIsReportedNotOnlyTheFirst) {
  const fs::path dir = fs::temp_directory_path() / "igi_scene_many_problems";
  fs::create_directories(dir);
  Json doc = ReadJsonFile(kMini);
  for (auto& g : doc["geometry"])
    g["file"] = (kMini.parent_path() / g["file"].get<std::string>()).string();
  doc["materials"]["floor"].erase("rho_d_map");
  doc["materials"]["walls"]["rho_d"] = 2.0;       // out of range
  doc["lights"]["bulb"]["radius"] = -1;           // must be > 0
  doc["cameras"]["cam0"]["qvec"] = {1, 1, 0, 0};  // not unit
  doc["lights"].erase("spot");
  doc["lightings"]["L1"] = {"panel"};
  doc["photos"] = Json::array();
  doc["lights"]["panel"]["file"] = "nowhere.obj";  // missing file
  WriteJsonFile(dir / "scene.json", doc);
  try {
    LoadScene(dir / "scene.json");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.problems().size(), 4u) << e.what();
  }
  fs::remove_all(dir);
}

// The mini scene's document with every path absolute (written elsewhere, it still loads).
Json MiniWithAbsolutePaths() {
  Json doc = ReadJsonFile(kMini);
  const fs::path mini = kMini.parent_path();
  for (auto& g : doc["geometry"]) g["file"] = (mini / g["file"].get<std::string>()).string();
  doc["materials"]["floor"]["rho_d_map"] = (mini / "textures/floor.exr").string();
  doc["lights"]["spot"]["profile"]["ies"] = (mini / "lights/spot.ies").string();
  doc["lights"]["panel"]["file"] = (mini / "geometry/panel.obj").string();
  for (auto& photo : doc["photos"]) {
    photo["file"] = (mini / photo["file"].get<std::string>()).string();
    if (photo.contains("mask") && photo["mask"].is_string()) {
      photo["mask"] = (mini / photo["mask"].get<std::string>()).string();
    }
  }
  return doc;
}

// `doc` with materials.floor.KEY set to `value`, written to dir/scene.json: loading it must fail
// with exactly one problem, naming that key (and `rule`, when given).
void ExpectOneFloorProblem(const Json& doc, const fs::path& dir, const std::string& key,
                           const Json& value, const std::string& rule = "") {
  Json broken = doc;
  broken["materials"]["floor"][key] = value;
  WriteJsonFile(dir / "scene.json", broken);
  try {
    LoadScene(dir / "scene.json");
    ADD_FAILURE() << key << " " << value;
  } catch (const InputError& e) {
    ASSERT_EQ(e.problems().size(), 1u) << e.what();
    EXPECT_NE(e.problems()[0].find("materials.floor." + key), std::string::npos) << e.what();
    EXPECT_NE(e.problems()[0].find(rule), std::string::npos) << e.what();
  }
}

// The Fresnel-weighted models (igi's additions, docs/scene-format.md) take an optional "ior" in
// (1, 5], default 1.5; the plain models do not accept the key.
TEST(SceneTest, FresnelModelsReadTheirIndexOfRefraction) {
  const fs::path dir =
      fs::temp_directory_path() / ("igi_scene_fresnel_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  Json doc = MiniWithAbsolutePaths();
  doc["materials"]["floor"]["brdf"] = "ward_gmd_fresnel";
  doc["materials"]["floor"]["ior"] = 1.33;
  doc["materials"]["box"]["brdf"] = "ward_aniso_fresnel";  // no ior: the default
  WriteJsonFile(dir / "scene.json", doc);
  const Scene scene = LoadScene(dir / "scene.json");
  const Material& floor = scene.materials[scene.FindMaterial("floor")];
  EXPECT_EQ(floor.brdf, BrdfModel::kWardGmdFresnel);
  EXPECT_EQ(floor.ior, 1.33);
  EXPECT_TRUE(floor.MissingForRendering().empty());  // ior is never missing
  const Material& box = scene.materials[scene.FindMaterial("box")];
  EXPECT_EQ(box.brdf, BrdfModel::kWardAnisoFresnel);
  EXPECT_FALSE(box.ior.has_value());
  EXPECT_EQ(box.MissingForRendering(),
            (std::vector<std::string>{"rho_d", "rho_s", "alpha_x", "alpha_y"}));

  for (double bad : {1.0, 0.5, 5.01, -2.0}) {
    doc["materials"]["floor"]["ior"] = bad;
    WriteJsonFile(dir / "scene.json", doc);
    try {
      LoadScene(dir / "scene.json");
      ADD_FAILURE() << bad;
    } catch (const InputError& e) {
      ASSERT_EQ(e.problems().size(), 1u) << e.what();
      EXPECT_NE(e.problems()[0].find("materials.floor.ior"), std::string::npos) << e.what();
      EXPECT_NE(e.problems()[0].find("must be in (1, 5]"), std::string::npos) << e.what();
    }
  }
  doc["materials"]["floor"]["ior"] = 5.0;  // the upper bound is included
  WriteJsonFile(dir / "scene.json", doc);
  EXPECT_EQ(LoadScene(dir / "scene.json").materials[scene.FindMaterial("floor")].ior, 5.0);
  fs::remove_all(dir);
}

// The microfacet models (docs/scene-format.md) take the keys of the Ward model of the same
// anisotropy: no "ior" (their Fresnel factor's F0 is rho_s), rho_s in [0, 1], α in (0, 1].
TEST(SceneTest, MicrofacetModelsReadTheKeysOfTheirWardForms) {
  const fs::path dir =
      fs::temp_directory_path() / ("igi_scene_microfacet_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  Json doc = MiniWithAbsolutePaths();
  doc["materials"]["floor"]["brdf"] = "ggx";
  doc["materials"]["box"] = {{"brdf", "beckmann_aniso"}, {"tangent", {1, 0, 0}}};
  WriteJsonFile(dir / "scene.json", doc);
  const Scene scene = LoadScene(dir / "scene.json");
  const Material& floor = scene.materials[scene.FindMaterial("floor")];
  EXPECT_EQ(floor.brdf, BrdfModel::kGgx);
  EXPECT_TRUE(floor.MissingForRendering().empty());
  const Material& box = scene.materials[scene.FindMaterial("box")];
  EXPECT_EQ(box.brdf, BrdfModel::kBeckmannAniso);
  EXPECT_EQ(box.MissingForRendering(),
            (std::vector<std::string>{"rho_d", "rho_s", "alpha_x", "alpha_y"}));

  const std::pair<const char*, Json> bad[] = {
      {"ior", 1.5}, {"rho_s", 1.2}, {"alpha", 0.0}, {"alpha", 1.5}, {"alpha_x", 0.2}};
  for (const auto& [key, value] : bad) ExpectOneFloorProblem(doc, dir, key, value);
  fs::remove_all(dir);
}

// Oren–Nayar's diffuse term (docs/scene-format.md): "diffuse": "oren_nayar" on any reflective
// model with "sigma" in [0, 1] (an unknown when absent: rendering needs it); "sigma" without it,
// an unknown diffuse name and σ out of range are one problem each.
TEST(SceneTest, OrenNayarDiffuseReadsItsRoughness) {
  const fs::path dir =
      fs::temp_directory_path() / ("igi_scene_oren_nayar_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  Json doc = MiniWithAbsolutePaths();
  doc["materials"]["floor"]["diffuse"] = "oren_nayar";
  doc["materials"]["floor"]["sigma"] = 0.3;
  doc["materials"]["box"] = {{"brdf", "ggx"}, {"diffuse", "oren_nayar"}};
  WriteJsonFile(dir / "scene.json", doc);
  const Scene scene = LoadScene(dir / "scene.json");
  const Material& floor = scene.materials[scene.FindMaterial("floor")];
  EXPECT_EQ(floor.diffuse, DiffuseShape::kOrenNayar);
  EXPECT_EQ(floor.sigma, 0.3);
  EXPECT_TRUE(floor.MissingForRendering().empty());
  const Material& box = scene.materials[scene.FindMaterial("box")];
  EXPECT_EQ(box.diffuse, DiffuseShape::kOrenNayar);
  EXPECT_EQ(box.MissingForRendering(),
            (std::vector<std::string>{"rho_d", "sigma", "rho_s", "alpha"}));

  const std::tuple<const char*, Json, const char*> bad[] = {
      {"sigma", -0.1, "must be in [0, 1]"},
      {"sigma", 1.5, "must be in [0, 1]"},
      {"diffuse", "rough", "unknown diffuse (known: lambert, oren_nayar, coated)"}};
  for (const auto& [key, value, rule] : bad) ExpectOneFloorProblem(doc, dir, key, value, rule);
  // The coated base's term has no parameter: "coated" needs nothing more and takes no sigma.
  Json coated = doc;
  coated["materials"]["floor"]["diffuse"] = "coated";
  coated["materials"]["floor"].erase("sigma");
  WriteJsonFile(dir / "scene.json", coated);
  const Scene coated_scene = LoadScene(dir / "scene.json");
  const Material& coated_floor = coated_scene.materials[coated_scene.FindMaterial("floor")];
  EXPECT_EQ(coated_floor.diffuse, DiffuseShape::kCoated);
  EXPECT_TRUE(coated_floor.MissingForRendering().empty());
  ExpectOneFloorProblem(coated, dir, "sigma", 0.2, "is read only with \"diffuse\": \"oren_nayar\"");
  Json lambert = doc;
  lambert["materials"]["floor"].erase("diffuse");
  WriteJsonFile(dir / "scene.json", lambert);
  try {
    LoadScene(dir / "scene.json");
    ADD_FAILURE() << "sigma without oren_nayar was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("materials.floor.sigma"), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace igi::recon

namespace igi::recon {
namespace {

// Cameras from a COLMAP model: each image becomes a camera named by its image name, and a
// photo without "camera" uses the image of its own file name.
TEST(SceneTest, CamerasFromColmapModel) {
  const fs::path dir = fs::temp_directory_path() / "igi_scene_colmap";
  fs::remove_all(dir);
  fs::create_directories(dir / "sparse/0");
  ColmapModel model;
  model.cameras[1] = ColmapCamera{1, "SIMPLE_RADIAL", 8, 6, {4.0, 4.0, 3.0, -0.05}};
  ColmapImage image;
  image.image_id = 3;
  image.qvec = Eigen::Vector4d(0, 1, 0, 0);
  image.tvec = Eigen::Vector3d(-1, 1, 1);
  image.camera_id = 1;
  image.name = "cam0_L0.exr";
  model.images[3] = image;
  WriteColmapModelText(model, dir / "sparse/0");

  Json doc = ReadJsonFile(kMini);
  const fs::path mini = kMini.parent_path();
  for (auto& g : doc["geometry"]) g["file"] = (mini / g["file"].get<std::string>()).string();
  doc["materials"]["floor"]["rho_d_map"] = (mini / "textures/floor.exr").string();
  doc["lights"]["spot"]["profile"]["ies"] = (mini / "lights/spot.ies").string();
  doc["lights"]["panel"]["file"] = (mini / "geometry/panel.obj").string();
  doc["cameras"] = Json{{"colmap", "sparse/0"}};
  doc["photos"] =
      Json::array({Json{{"file", (mini / "photos/cam0_L0.exr").string()}, {"lighting", "L0"}}});
  WriteJsonFile(dir / "scene.json", doc);
  const Scene scene = LoadScene(dir / "scene.json");
  ASSERT_EQ(scene.cameras.size(), 1u);
  const Camera& cam = scene.cameras[0];
  EXPECT_EQ(cam.name, "cam0_L0.exr");
  EXPECT_EQ(cam.model, CameraModel::kOpenCv);  // SIMPLE_RADIAL converts exactly
  EXPECT_EQ(cam.params, (std::vector<double>{4, 4, 4, 3, -0.05, 0, 0, 0}));
  EXPECT_NEAR((cam.CenterInWorld() - Eigen::Vector3d(1, 1, 1)).norm(), 0, 1e-12);
  ASSERT_EQ(scene.photos.size(), 1u);
  EXPECT_EQ(scene.photos[0].camera, 0);
  EXPECT_TRUE(scene.colmap_model.has_value());

  // A photo whose file name is not an image of the model is reported.
  doc["photos"][0]["file"] = (mini / "photos/cam0_L1.exr").string();
  WriteJsonFile(dir / "scene.json", doc);
  try {
    LoadScene(dir / "scene.json");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no image of this file name in the COLMAP model"),
              std::string::npos)
        << e.what();
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace igi::recon
