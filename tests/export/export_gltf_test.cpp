// glTF 2.0 export, validated by loading it back with Assimp's glTF importer: counts of meshes,
// materials, cameras and lights, vertex positions, and the camera and light placement.
#include "solver/export/export_gltf.h"

#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <gtest/gtest.h>

#include <assimp/Importer.hpp>
#include <map>
#include <string>
#include <tuple>

#include "solver/export/export.h"
#include "solver/render/brdf.h"
#include "solver/render/sampling.h"
#include "tests/export/export_test_scene.h"
#include "tests/temp_dir.h"
#include "tools/common/image.h"
#include "tools/common/json.h"

namespace igi::exporter {
namespace {

const aiNode* FindNode(const aiNode* node, const std::string& name) {
  if (name == node->mName.C_Str()) return node;
  for (unsigned i = 0; i < node->mNumChildren; ++i) {
    if (const aiNode* found = FindNode(node->mChildren[i], name)) return found;
  }
  return nullptr;
}

// The scene's materials by name, leaving out the default material Assimp's glTF importer adds.
std::map<std::string, const aiMaterial*> Materials(const aiScene* ai) {
  std::map<std::string, const aiMaterial*> out;
  for (unsigned i = 0; i < ai->mNumMaterials; ++i) {
    const std::string name = ai->mMaterials[i]->GetName().C_Str();
    if (!name.empty() && name != AI_DEFAULT_MATERIAL_NAME) out[name] = ai->mMaterials[i];
  }
  return out;
}

TEST(ExportGltf, RadianceRoomLoadsInAssimp) {
  const recon::Scene scene = test::LoadRadianceRoom();
  const auto dir = test::UniqueTempDir("igi_export_gltf") / "out";
  ExportScene(scene, dir, {.format = ExportFormat::kGltf});
  Assimp::Importer importer;
  const aiScene* ai = importer.ReadFile((dir / "scene.gltf").string(), 0);
  ASSERT_NE(ai, nullptr) << importer.GetErrorString();
  EXPECT_EQ(ai->mNumMeshes, 8u);
  EXPECT_EQ(Materials(ai).size(), 8u);
  EXPECT_EQ(Materials(ai).count("glossy_box"), 1u);
  EXPECT_EQ(ai->mNumCameras, 3u);
  EXPECT_EQ(ai->mNumLights, 2u);  // both sphere lamps, as point lights

  // Every region's vertices, in order of first use by its triangles, as in the scene's mesh.
  size_t vertices = 0, faces = 0;
  for (unsigned i = 0; i < ai->mNumMeshes; ++i) {
    const aiMesh* mesh = ai->mMeshes[i];
    vertices += mesh->mNumVertices;
    faces += mesh->mNumFaces;
    const int region = scene.FindMaterial(mesh->mName.C_Str());
    ASSERT_GE(region, 0) << mesh->mName.C_Str();
    size_t t = 0;
    while (scene.mesh.triangle_region[t] != region) ++t;
    const Eigen::Vector3f first = scene.mesh.positions[scene.mesh.triangles[t][0]];
    EXPECT_EQ(mesh->mVertices[0].x, first.x());
    EXPECT_EQ(mesh->mVertices[0].y, first.y());
    EXPECT_EQ(mesh->mVertices[0].z, first.z());
    ASSERT_TRUE(mesh->HasNormals());
  }
  EXPECT_EQ(faces, scene.mesh.num_triangles());
  EXPECT_LE(vertices, 3 * scene.mesh.num_triangles());

  // cam0: at (2, 0.3, 1.5), yfov 46.83°, aspect 4:3.
  const aiCamera* cam = ai->mCameras[0];
  EXPECT_STREQ(cam->mName.C_Str(), "cam0");
  EXPECT_NEAR(cam->mAspect, 4.0 / 3.0, 1e-5);
  const aiNode* node = FindNode(ai->mRootNode, "cam0");
  ASSERT_NE(node, nullptr);
  const aiMatrix4x4& m = node->mTransformation;
  EXPECT_NEAR(m.a4, 2.0, 1e-5);
  EXPECT_NEAR(m.b4, 0.3, 1e-5);
  EXPECT_NEAR(m.c4, 1.5, 1e-5);
  // The glTF camera looks along its node's -z: world (0, 0.98, -0.196) for cam0.
  EXPECT_NEAR(-m.b3, 0.980580676, 1e-5);
  EXPECT_NEAR(-m.c3, -0.196116135, 1e-5);

  // The lamp: a point light of intensity radiance·π r² = 31.4159.
  const aiLight* lamp = ai->mLights[0];
  EXPECT_EQ(lamp->mType, aiLightSource_POINT);
  EXPECT_NEAR(lamp->mColorDiffuse.r, 1000 * render::kPi * 0.01, 1e-3);
}

TEST(ExportGltf, EveryLightTypeAndTexture) {
  recon::Scene scene = test::SyntheticScene();
  const auto dir = test::UniqueTempDir("igi_export_gltf");
  // A 4x2 albedo map on "matte": linear 0.5 grey.
  Image texture;
  texture.width = 4, texture.height = 2, texture.channels = 3;
  texture.pixels.assign(4 * 2 * 3, 0.5f);
  WriteImage(dir / "matte.exr", texture);
  scene.materials[0].rho_d_map = dir / "matte.exr";
  ExportScene(scene, dir / "out", {.format = ExportFormat::kGltf});
  Assimp::Importer importer;
  const aiScene* ai = importer.ReadFile((dir / "out" / "scene.gltf").string(), 0);
  ASSERT_NE(ai, nullptr) << importer.GetErrorString();
  EXPECT_EQ(ai->mNumMeshes, 5u + 1u);  // regions + the area light's mesh
  EXPECT_EQ(Materials(ai).size(), 6u);
  EXPECT_EQ(ai->mNumCameras, 1u);
  EXPECT_EQ(ai->mNumLights, 4u);  // point, spot, directional, sphere-as-point
  int spots = 0, directional = 0;
  for (unsigned i = 0; i < ai->mNumLights; ++i) {
    spots += ai->mLights[i]->mType == aiLightSource_SPOT;
    directional += ai->mLights[i]->mType == aiLightSource_DIRECTIONAL;
  }
  EXPECT_EQ(spots, 1);
  EXPECT_EQ(directional, 1);
  // The texture: sRGB-encoded 8-bit PNG (linear 0.5 -> 0.7354 -> 188/255).
  const Image png = ReadImage(dir / "out" / "textures" / "matte.png", 3);
  EXPECT_NEAR(png.pixels[0], 188.0 / 255.0, 1e-6);
  aiString path;
  ASSERT_EQ(Materials(ai).at("matte")->GetTexture(aiTextureType_DIFFUSE, 0, &path),
            aiReturn_SUCCESS);
  EXPECT_STREQ(path.C_Str(), "textures/matte.png");
}

// glTF 2.0's metal (Appendix B of its specification), written here from the specification:
// F_schlick(baseColor, v·h)·D_ggx·V_smith_correlated with α = roughness².
Eigen::Vector3d GltfMetal(const Eigen::Vector3d& base_color, double roughness,
                          const Eigen::Vector3d& wo, const Eigen::Vector3d& wi) {
  const Eigen::Vector3d h = (wo + wi).normalized();
  const double a2 = std::pow(roughness, 4), nh = h.z(), nl = wi.z(), nv = wo.z();
  const double d = a2 / (render::kPi * std::pow(nh * nh * (a2 - 1) + 1, 2));
  const double v =
      0.5 / (nl * std::sqrt(nv * nv * (1 - a2) + a2) + nv * std::sqrt(nl * nl * (1 - a2) + a2));
  const Eigen::Vector3d f =
      base_color + (Eigen::Vector3d::Ones() - base_color) * std::pow(1 - wo.dot(h), 5);
  return f * d * v;
}

// ggx is glTF's own lobe: with ρd 0 it becomes a metal whose BRDF, read back from the file and
// evaluated by the specification's formula, equals igi's renderer's; with ρd > 0 the lobe's
// roughness and F0 are written as they are, not fitted.
TEST(ExportGltf, GgxIsWrittenExactly) {
  recon::Scene scene = test::SyntheticScene();
  recon::Material& metal = scene.materials[1];
  metal.brdf = recon::BrdfModel::kGgx;
  metal.rho_d = Eigen::Vector3d::Zero(), metal.rho_s = Eigen::Vector3d(0.9, 0.6, 0.3);
  metal.alpha = 0.16;
  recon::Material& plastic = scene.materials[2];
  plastic.brdf = recon::BrdfModel::kGgx;
  plastic.rho_s = Eigen::Vector3d::Constant(0.05), plastic.alpha = 0.09;
  const auto dir = test::UniqueTempDir("igi_export_gltf_ggx") / "out";
  const ExportReport report = ExportScene(scene, dir, {.format = ExportFormat::kGltf});
  const Json doc = ReadJsonFile(dir / "scene.gltf");
  std::map<std::string, Json> materials;
  for (const Json& m : doc.at("materials")) materials[m.at("name")] = m;

  const Json& gold = materials.at("gold").at("pbrMetallicRoughness");
  EXPECT_EQ(gold.at("metallicFactor").get<double>(), 1.0);
  const double roughness = gold.at("roughnessFactor");
  const Eigen::Vector3d base(gold.at("baseColorFactor")[0], gold.at("baseColorFactor")[1],
                             gold.at("baseColorFactor")[2]);
  render::BrdfParams igi;
  igi.model = recon::BrdfModel::kGgx;
  igi.rho_s = *metal.rho_s, igi.alpha = igi.alpha_x = igi.alpha_y = *metal.alpha;
  for (double theta_o : {0.1, 0.6, 1.2}) {
    for (double theta_i : {0.05, 0.5, 1.0, 1.4}) {
      for (double phi : {0.0, 1.0, 3.0}) {
        const Eigen::Vector3d wo(std::sin(theta_o), 0, std::cos(theta_o));
        const Eigen::Vector3d wi(std::sin(theta_i) * std::cos(phi),
                                 std::sin(theta_i) * std::sin(phi), std::cos(theta_i));
        const Eigen::Vector3d want = render::EvalBrdf(igi, wo, wi);
        const Eigen::Vector3d got = GltfMetal(base, roughness, wo, wi);
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], want[c], 1e-6 * want[c]);
      }
    }
  }
  bool exact_reported = false;
  for (const auto& a : report.approximations) {
    exact_reported |= a.item == "materials.gold" && a.relative_error == 0.0;
  }
  EXPECT_TRUE(exact_reported);

  const Json& old = materials.at("old_ward");
  EXPECT_EQ(old.at("pbrMetallicRoughness").at("metallicFactor").get<double>(), 0.0);
  EXPECT_NEAR(old.at("pbrMetallicRoughness").at("roughnessFactor").get<double>(), 0.3, 1e-12);
  const Json& specular = old.at("extensions").at("KHR_materials_specular");
  EXPECT_EQ(specular.at("specularFactor").get<double>(), 1.0);
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(0.04 * specular.at("specularColorFactor")[c].get<double>(), 0.05, 1e-12);
  }
}

// No target has Oren–Nayar's or the coated base's diffuse term: each is written as Lambert's with
// the same ρd, and the report names it with what is left out: the darkening at normal viewing,
// 1 − A(σ), or the coat's two mean transmittances, 1 − (20/21)².
TEST(ExportGltf, DiffuseShapesAreReportedAsLambert) {
  for (const auto& [shape, name, error] :
       {std::tuple{recon::DiffuseShape::kOrenNayar, "oren_nayar", 1 - render::OrenNayarA(0.3)},
        std::tuple{recon::DiffuseShape::kCoated, "coated", 1 - 400.0 / 441.0}}) {
    recon::Scene scene = test::SyntheticScene();
    scene.materials[0].diffuse = shape;
    if (shape == recon::DiffuseShape::kOrenNayar) scene.materials[0].sigma = 0.3;
    const auto dir = test::UniqueTempDir(std::string("igi_export_gltf_") + name) / "out";
    const ExportReport report = ExportScene(scene, dir, {.format = ExportFormat::kGltf});
    bool reported = false;
    for (const auto& a : report.approximations) {
      if (a.item != "materials.matte" || a.description.find(name) == std::string::npos) continue;
      reported = true;
      ASSERT_TRUE(a.relative_error.has_value());
      EXPECT_NEAR(*a.relative_error, error, 1e-12) << name;
    }
    EXPECT_TRUE(reported) << name;
    const Json doc = ReadJsonFile(dir / "scene.gltf");
    for (const Json& m : doc.at("materials")) {
      if (m.at("name") != "matte") continue;
      EXPECT_NEAR(m.at("pbrMetallicRoughness").at("baseColorFactor")[0].get<double>(), 0.5, 1e-12);
    }
  }
}

}  // namespace
}  // namespace igi::exporter
