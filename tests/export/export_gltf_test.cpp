// glTF 2.0 export, validated by loading it back with Assimp's glTF importer: counts of meshes,
// materials, cameras and lights, vertex positions, and the camera and light placement.
#include "solver/export/export_gltf.h"

#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <gtest/gtest.h>

#include <assimp/Importer.hpp>
#include <map>

#include "solver/export/export.h"
#include "solver/render/sampling.h"
#include "tests/export/export_test_scene.h"
#include "tests/temp_dir.h"
#include "tools/common/image.h"

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

}  // namespace
}  // namespace igi::exporter
