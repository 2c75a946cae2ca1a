// SceneDocument: each edit's effect on the JSON (the key it sets, in place or last), a rebase
// round trip over the mini scene, a new light's unique name, and Validate reporting what
// LoadScene reports for the same document.
#include "recon/scene_document.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "tests/temp_dir.h"
#include "tools/common/error.h"

namespace igi::recon {
namespace {

namespace fs = std::filesystem;
const fs::path kMiniDir = fs::path(IGI_SOURCE_DIR) / "tests/data/scenes/mini";

Json Mini() { return ReadJsonFile(kMiniDir / "scene.json"); }

// The keys of an object in order.
std::vector<std::string> Keys(const Json& j) {
  std::vector<std::string> keys;
  for (const auto& [k, v] : j.items()) keys.push_back(k);
  return keys;
}

TEST(SceneDocumentTest, MaterialSettersEditTheirKeysInPlaceAndAddNewOnesLast) {
  SceneDocument doc(Mini());
  doc.SetMaterialBrdf("floor", BrdfModel::kWardFresnel);
  doc.SetMaterialValue("floor", "ior", 1.6);
  doc.EraseMaterialValue("floor", "alpha");
  doc.ScaleMaterialValue("floor", "rho_s", 2);
  doc.ScaleMaterialValue("walls", "rho_d", 0.5);
  doc.ScaleMaterialValue("walls", "rho_s", 2);  // absent: nothing
  const Json& floor = doc.json()["materials"]["floor"];
  EXPECT_EQ(floor["brdf"], "ward_fresnel");
  EXPECT_EQ(Keys(floor), (std::vector<std::string>{"brdf", "rho_d_map", "rho_s", "ior"}));
  EXPECT_DOUBLE_EQ(floor["rho_s"].get<double>(), 0.08);
  EXPECT_EQ(doc.json()["materials"]["walls"],
            Json({{"brdf", "lambert"}, {"rho_d", {0.3, 0.275, 0.25}}}));
  EXPECT_EQ(doc.Material("floor"), floor);
  EXPECT_TRUE(doc.Material("nothing").is_null());

  doc.SetMaterial("box", {{"brdf", "ward"}, {"rho_d", 0.5}});
  EXPECT_EQ(doc.json()["materials"]["box"], Json({{"brdf", "ward"}, {"rho_d", 0.5}}));
  EXPECT_EQ(Keys(doc.json()["materials"]),
            (std::vector<std::string>{"floor", "ceiling", "walls", "box"}));
}

TEST(SceneDocumentTest, LightSettersReplaceALightAndScaleItsEmission) {
  SceneDocument doc(Mini());
  doc.SetLight("lamp", {{"type", "point"}, {"position", {0, 0, 1}}, {"intensity", {2, 2, 2}}});
  doc.ScaleLightEmission("lamp", 3);
  doc.ScaleLightEmission("spot2", 2);  // a grey intensity (one number)
  doc.ScaleLightEmission("sun", 0.5);
  EXPECT_EQ(doc.json()["lights"]["lamp"],
            Json({{"type", "point"}, {"position", {0, 0, 1}}, {"intensity", {6.0, 6.0, 6.0}}}));
  EXPECT_EQ(doc.json()["lights"]["spot2"]["intensity"], 10.0);
  EXPECT_EQ(doc.json()["lights"]["sun"]["irradiance"], Json({1.5, 1.5, 1.5}));
  EXPECT_EQ(Keys(doc.json()["lights"]).front(), "lamp");  // replaced in place
}

TEST(SceneDocumentTest, ALightAddedToEveryLightingTakesANameNotYetTaken) {
  SceneDocument doc(Mini());
  const Json ambient = {{"type", "ambient"}, {"radiance", {0.1, 0.1, 0.1}}};
  EXPECT_EQ(doc.AddLightToEveryLighting("lamp", ambient), "lamp_");
  EXPECT_EQ(doc.AddLightToEveryLighting("lamp", ambient), "lamp__");
  EXPECT_EQ(doc.json()["lights"]["lamp"]["type"], "point");  // the light of that name is kept
  EXPECT_EQ(doc.json()["lights"]["lamp_"], ambient);
  for (const auto& [name, list] : doc.json()["lightings"].items()) {
    ASSERT_GE(list.size(), 2u) << name;
    EXPECT_EQ(list[list.size() - 2], "lamp_") << name;
    EXPECT_EQ(list.back(), "lamp__") << name;
  }
}

TEST(SceneDocumentTest, CameraSettersWriteTheEntryIntrinsicsPoseAndVignetting) {
  SceneDocument doc(Mini());
  EXPECT_EQ(doc.CameraNames(), (std::vector<std::string>{"cam0", "cam1"}));
  EXPECT_TRUE(doc.HasCamera("cam1"));
  EXPECT_FALSE(doc.HasCamera("cam2"));

  Camera cam;
  cam.width = 4;
  cam.height = 3;
  cam.params = {2, 2, 2, 1.5};
  cam.cam_from_world = Rigid3d(Eigen::Quaterniond(0, 0, 1, 0), Eigen::Vector3d(1, 2, 3));
  doc.SetCameraIntrinsics("cam1", cam);
  const Json& cam1 = doc.json()["cameras"]["cam1"];
  EXPECT_EQ(cam1["model"], "PINHOLE");
  EXPECT_EQ(cam1["width"], 4);
  EXPECT_EQ(cam1["params"], Json({2.0, 2.0, 2.0, 1.5}));
  EXPECT_EQ(cam1["tvec"], Json({-1, 1, 1.2}));  // the pose kept

  // The pose as given (not normalised) is written; read back, it is normalised.
  doc.SetCameraPose("cam0", Rigid3d(Eigen::Quaterniond(0, 2, 0, 0), Eigen::Vector3d(4, 5, 6)));
  EXPECT_EQ(doc.json()["cameras"]["cam0"]["qvec"], Json({0.0, 2.0, 0.0, 0.0}));
  EXPECT_EQ(doc.json()["cameras"]["cam0"]["tvec"], Json({4.0, 5.0, 6.0}));
  const Rigid3d pose = doc.CameraPose("cam0");
  EXPECT_EQ(pose.rotation.coeffs(), Eigen::Vector4d(1, 0, 0, 0));  // x, y, z, w
  EXPECT_EQ(pose.translation, Eigen::Vector3d(4, 5, 6));

  EXPECT_EQ(doc.CameraVignetting("cam0"), Eigen::Vector2d::Zero());
  doc.SetCameraVignetting("cam0", -0.2, 0.05);
  EXPECT_EQ(doc.json()["cameras"]["cam0"]["vignetting"], Json({{"k1", -0.2}, {"k2", 0.05}}));
  EXPECT_EQ(doc.CameraVignetting("cam0"), Eigen::Vector2d(-0.2, 0.05));

  doc.SetCamera("cam2", cam);
  EXPECT_EQ(doc.json()["cameras"]["cam2"], CameraJson(cam));
  doc.SetCameras(Json::object());
  EXPECT_TRUE(doc.CameraNames().empty());
}

TEST(SceneDocumentTest, PhotoSettersWriteFileCameraMaskExposureAndResponse) {
  SceneDocument doc(Mini());
  ASSERT_EQ(doc.NumPhotos(), 2u);
  EXPECT_EQ(doc.PhotoFile(0), "photos/cam0_L0.exr");
  EXPECT_FALSE(doc.PhotoExposure(0));
  EXPECT_FALSE(doc.PhotoResponseExponent(0));
  doc.SetPhotoExposure(0, 2.5);
  doc.SetPhotoResponse(0, 0.8, 0.5);
  doc.SetPhotoMask(0, std::nullopt);
  doc.SetPhotoMask(1, fs::path("photos/m.png"));
  doc.SetPhotoFile(1, "/abs/p.exr");
  doc.SetPhotoCamera(1, "cam1");
  EXPECT_EQ(doc.json()["photos"][0], Json({{"file", "photos/cam0_L0.exr"},
                                           {"camera", "cam0"},
                                           {"lighting", "L0"},
                                           {"exposure_scale", 2.5},
                                           {"response", {{"exponent", 0.8}, {"reference", 0.5}}}}));
  EXPECT_EQ(doc.json()["photos"][1], Json({{"file", "/abs/p.exr"},
                                           {"camera", "cam1"},
                                           {"lighting", "L1"},
                                           {"mask", "photos/m.png"}}));
  EXPECT_EQ(doc.PhotoExposure(0), 2.5);
  EXPECT_EQ(doc.PhotoResponseExponent(0), 0.8);
  EXPECT_THROW(doc.SetPhotoExposure(2, 1.0), Json::out_of_range);

  doc.SetPhotos({{"a.exr", "cam0", "L0", std::nullopt}, {"b.exr", "cam1", "L2", "b_mask.png"}});
  EXPECT_EQ(doc.json()["photos"],
            Json::parse(R"([{"file": "a.exr", "camera": "cam0", "lighting": "L0"},
                            {"file": "b.exr", "camera": "cam1", "lighting": "L2",
                             "mask": "b_mask.png"}])"));
}

TEST(SceneDocumentTest, GeometryFilesReplaceTheGeometry) {
  SceneDocument doc(Mini());
  doc.SetGeometryFiles({"geometry/solved.obj"});
  EXPECT_EQ(doc.json()["geometry"], Json::parse(R"([{"file": "geometry/solved.obj"}])"));
}

// Rebased into another folder the paths hold from there (the scene validates there, files and
// all); rebased back they are the strings they were. Absolute paths are left as they are.
TEST(SceneDocumentTest, RebasedPathsHoldFromTheNewFolderAndComeBackAsTheyWere) {
  const fs::path dir = test::UniqueTempDir("scene_document_rebase") / "deeper" / "out";
  fs::create_directories(dir);
  Json mini = Mini();
  mini["photos"][1]["mask"] = "/abs/mask.png";
  SceneDocument doc(mini);
  doc.RebasePaths(kMiniDir, dir);
  EXPECT_EQ(doc.json()["photos"][1]["mask"], "/abs/mask.png");
  const std::string geometry = doc.json()["geometry"][0]["file"];
  EXPECT_EQ(fs::weakly_canonical(dir / geometry),
            fs::weakly_canonical(kMiniDir / "geometry/room.obj"));
  EXPECT_EQ(geometry.rfind("../", 0), 0u) << geometry;
  SceneDocument valid(Mini());
  valid.RebasePaths(kMiniDir, dir);
  EXPECT_NO_THROW(valid.Validate(dir));

  doc.RebasePaths(dir, kMiniDir);
  EXPECT_EQ(doc.json(), mini) << doc.json().dump();

  SceneDocument abs(Mini());
  abs.AbsolutePaths(kMiniDir);
  EXPECT_EQ(abs.json()["lights"]["spot"]["profile"]["ies"],
            (fs::absolute(kMiniDir) / "lights/spot.ies").lexically_normal().string());
  abs.RelativePaths(kMiniDir);
  EXPECT_EQ(abs.json(), Mini());
}

// A bad value is the reader's problem line, naming DIR/scene.json: the same lines LoadScene
// gives for that document written there.
TEST(SceneDocumentTest, ValidateRejectsABadValueWithTheReadersError) {
  SceneDocument doc(Mini());
  doc.SetMaterialValue("walls", "rho_d", 1.5);
  std::string validated;
  try {
    doc.Validate(kMiniDir);
    FAIL() << "a rho_d of 1.5 was accepted";
  } catch (const InputError& e) {
    validated = e.what();
    ASSERT_EQ(e.problems().size(), 1u) << validated;
    EXPECT_NE(e.problems()[0].find((kMiniDir / "scene.json").string() + ": materials.walls.rho_d"),
              std::string::npos)
        << validated;
  }
  const fs::path dir = test::UniqueTempDir("scene_document_validate");
  SceneDocument there(doc.json());
  there.RebasePaths(kMiniDir, dir);
  WriteJsonFile(dir / "scene.json", there.json());
  try {
    LoadScene(dir / "scene.json");
    FAIL() << "LoadScene accepted a rho_d of 1.5";
  } catch (const InputError& e) {
    std::string expected = e.what();
    EXPECT_EQ(validated.substr(validated.find(": materials")),
              expected.substr(expected.find(": materials")));
  }
}

}  // namespace
}  // namespace igi::recon
