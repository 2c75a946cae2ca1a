#include "recon/mesh.h"

#include <gtest/gtest.h>

#include <filesystem>

namespace igi::recon {
namespace {

const std::filesystem::path kMini = std::filesystem::path(IGI_SOURCE_DIR) / "tests/data/scenes/mini";

TEST(MeshTest, ReadsRegionsUvsAndNormalsFromObj) {
  ProblemList problems;
  MeshLoadSummary summary;
  TriangleMesh mesh = LoadMesh(kMini / "geometry/room.obj", &problems, &summary);
  ASSERT_TRUE(problems.empty()) << problems.problems().front();
  EXPECT_EQ(mesh.num_triangles(), 12u);
  EXPECT_TRUE(summary.has_normals);
  EXPECT_TRUE(summary.has_uvs);
  EXPECT_EQ(mesh.region_names, (std::vector<std::string>{"floor", "ceiling", "walls"}));
  // The floor (first two triangles) faces up, its normals too, and its UVs span [0, 1].
  EXPECT_EQ(mesh.triangle_region[0], 0);
  EXPECT_NEAR(mesh.FaceNormal(0).z(), 1.0f, 1e-6f);
  EXPECT_NEAR(mesh.normals[mesh.triangles[0][0]].z(), 1.0f, 1e-6f);
  const Eigen::Vector2f uv2 = mesh.uvs[mesh.triangles[0][2]];
  EXPECT_EQ(uv2, Eigen::Vector2f(1, 1));
  EXPECT_NEAR(mesh.TriangleArea(0) + mesh.TriangleArea(1), 4.0, 1e-9);
}

TEST(MeshTest, FileWithoutNormalsIsShadedFlat) {
  ProblemList problems;
  MeshLoadSummary summary;
  TriangleMesh box = LoadMesh(kMini / "geometry/box.obj", &problems, &summary);
  ASSERT_TRUE(problems.empty());
  EXPECT_FALSE(summary.has_normals);
  EXPECT_FALSE(box.has_uvs());
  ASSERT_EQ(box.normals.size(), box.positions.size());
  for (size_t t = 0; t < box.num_triangles(); ++t) {
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR((box.normals[box.triangles[t][k]] - box.FaceNormal(t)).norm(), 0.0f, 1e-6f);
    }
  }
}

TEST(MeshTest, AppendMergesRegionsAndPadsUvs) {
  ProblemList problems;
  TriangleMesh room = LoadMesh(kMini / "geometry/room.obj", &problems);
  TriangleMesh box = LoadMesh(kMini / "geometry/box.obj", &problems);
  TriangleMesh again = LoadMesh(kMini / "geometry/room.obj", &problems);
  room.Append(box);
  room.Append(again);
  EXPECT_EQ(room.region_names, (std::vector<std::string>{"floor", "ceiling", "walls", "box"}));
  EXPECT_EQ(room.num_triangles(), 12u + 10u + 12u);
  EXPECT_EQ(room.uvs.size(), room.positions.size());
  EXPECT_EQ(room.normals.size(), room.positions.size());
  EXPECT_EQ(room.triangle_region.back(), 2);  // the second room's walls map onto "walls"
}

TEST(MeshTest, RealSceneMeshesLoad) {
  const std::filesystem::path data(IGI_SHARED_DATA_DIR);
  ProblemList problems;
  MeshLoadSummary summary;
  TriangleMesh ball = LoadMesh(data / "real/diligent_ball/geometry/ball.obj", &problems, &summary);
  ASSERT_TRUE(problems.empty());
  EXPECT_EQ(summary.num_triangles, 20480u);
  EXPECT_EQ(summary.num_vertices, 10242u);  // identical vertices joined (README: 10,242)
  EXPECT_TRUE(summary.has_normals);
  // Smooth normals of a unit sphere equal the positions.
  for (size_t v = 0; v < ball.positions.size(); v += 97) {
    EXPECT_NEAR((ball.normals[v] - ball.positions[v]).norm(), 0.0f, 1e-5f);
  }
  TriangleMesh room = LoadMesh(data / "reference/radiance_room/geometry/room.obj", &problems);
  ASSERT_TRUE(problems.empty());
  EXPECT_EQ(room.num_triangles(), 36u);
  EXPECT_EQ(room.region_names.size(), 8u);
}

TEST(MeshTest, ProblemsNameTheFile) {
  const std::filesystem::path res =
      std::filesystem::path(IGI_SOURCE_DIR) / "tests/data/scenes/broken/res";
  for (const char* name : {"empty.obj", "nan.obj", "missing.obj", "bad.exr"}) {
    ProblemList problems;
    LoadMesh(res / name, &problems);
    ASSERT_EQ(problems.size(), 1u) << name;
    EXPECT_NE(problems.problems()[0].find(name), std::string::npos) << problems.problems()[0];
  }
}

}  // namespace
}  // namespace igi::recon
