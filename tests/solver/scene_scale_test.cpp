// The scene's length scale (solver/inverse/scene_scale.h): the mean free path from the surfaces the
// photos see against Cauchy's mean chord 4V/S of a convex room seen all round, and the scale
// that follows it.
#include "solver/inverse/scene_scale.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <string>

#include "tests/solver/test_scenes.h"

namespace igi::solver {
namespace {

// Closed boxes [x0, x0 + l] × [0, w] × [0, h], one after another along x (rooms of a building
// sharing their walls), region "room".
std::string BoxesObj(int rooms, double l, double w, double h) {
  std::string s = "usemtl room\n";
  int base = 0;
  for (int k = 0; k < rooms; ++k) {
    const double x0 = k * l, x1 = x0 + l;
    for (double z : {0.0, h}) {
      for (auto [x, y] : {std::pair{x0, 0.0}, {x1, 0.0}, {x1, w}, {x0, w}}) {
        s += "v " + std::to_string(x) + " " + std::to_string(y) + " " + std::to_string(z) + "\n";
      }
    }
    const int f[12][3] = {{1, 3, 2}, {1, 4, 3}, {5, 6, 7}, {5, 7, 8}, {1, 2, 6}, {1, 6, 5},
                          {2, 3, 7}, {2, 7, 6}, {3, 4, 8}, {3, 8, 7}, {4, 1, 5}, {4, 5, 8}};
    for (const auto& t : f) {
      s += "f " + std::to_string(base + t[0]) + " " + std::to_string(base + t[1]) + " " +
           std::to_string(base + t[2]) + "\n";
    }
    base += 8;
  }
  return s;
}

// Six square cameras of 90° at `eye`, looking along ±x, ±y, ±z: together they see every
// direction once.
Json CubeCameras(const Eigen::Vector3d& eye, const std::string& prefix, Json cameras) {
  const Eigen::Vector3d axes[6] = {Eigen::Vector3d::UnitX(), -Eigen::Vector3d::UnitX(),
                                   Eigen::Vector3d::UnitY(), -Eigen::Vector3d::UnitY(),
                                   Eigen::Vector3d::UnitZ(), -Eigen::Vector3d::UnitZ()};
  for (int k = 0; k < 6; ++k) {
    const Eigen::Vector3d z = axes[k];
    const Eigen::Vector3d up =
        std::abs(z.z()) > 0.5 ? Eigen::Vector3d::UnitY() : Eigen::Vector3d::UnitZ();
    const Eigen::Vector3d x = (-up).cross(z).normalized();  // image y points down
    const Eigen::Vector3d y = z.cross(x);
    Eigen::Matrix3d r;
    r.row(0) = x;
    r.row(1) = y;
    r.row(2) = z;
    const Eigen::Quaterniond q(r);
    const Eigen::Vector3d t = -r * eye;
    cameras[prefix + std::to_string(k)] = {{"model", "PINHOLE"},
                                           {"width", 64},
                                           {"height", 64},
                                           {"params", {32, 32, 32, 32}},
                                           {"qvec", {q.w(), q.x(), q.y(), q.z()}},
                                           {"tvec", {t.x(), t.y(), t.z()}}};
  }
  return cameras;
}

recon::Scene BoxScene(const std::string& name, const std::string& obj, const Json& cameras) {
  const auto dir = test::TempSceneDir(name);
  test::WriteText(dir / "room.obj", obj);
  return test::LoadTestScene(
      dir, Json{{"format", "igi-scene"},
                {"version", 1},
                {"geometry", Json::array({Json{{"file", "room.obj"}}})},
                {"materials", {{"room", {{"brdf", "lambert"}, {"rho_d", {0.5, 0.5, 0.5}}}}}},
                {"lights",
                 {{"l", {{"type", "point"}, {"position", {0.5, 0.5, 0.5}}, {"intensity", 1}}}}},
                {"lightings", {{"L", {"l"}}}},
                {"cameras", cameras},
                {"photos", Json::array()}});
}

SceneScale Measure(const recon::Scene& scene) { return MeasureSceneScale(scene); }

TEST(SceneScale, TheFreePathOfAConvexRoomSeenAllRoundIsItsMeanChord) {
  const double l = 4, w = 3, h = 2.5;
  const recon::Scene scene = BoxScene("scale_box", BoxesObj(1, l, w, h),
                                      CubeCameras({1.3, 1.1, 1.4}, "c", Json::object()));
  const SceneScale s = Measure(scene);
  const double chord = 4 * l * w * h / (2 * (l * w + l * h + w * h));  // 2.03 m
  std::printf("free path %.3f m (4V/S %.3f m), diagonal %.3f m, rays hit %.3f\n", s.free_path_m,
              chord, s.diagonal_m, s.hit_fraction);
  EXPECT_NEAR(s.free_path_m / chord, 1.0, 0.03);
  EXPECT_DOUBLE_EQ(s.hit_fraction, 1.0);
  // A box room keeps its diagonal (2.7 free paths here).
  EXPECT_NEAR(s.diagonal_m, std::sqrt(l * l + w * w + h * h), 1e-6);
  EXPECT_DOUBLE_EQ(s.scale_m, s.diagonal_m);
}

TEST(SceneScale, ABuildingsRoomsSetItsScaleNotItsBoundingBox) {
  // Eight such rooms in a row, each photographed from inside: the diagonal grows eightfold, the
  // scale stays a room's.
  Json cameras = Json::object();
  for (int k = 0; k < 8; ++k)
    cameras = CubeCameras({4.0 * k + 1.3, 1.1, 1.4}, "r" + std::to_string(k) + "_", cameras);
  const recon::Scene scene = BoxScene("scale_building", BoxesObj(8, 4, 3, 2.5), cameras);
  const SceneScale s = Measure(scene);
  std::printf("free path %.3f m, diagonal %.3f m, scale %.3f m\n", s.free_path_m, s.diagonal_m,
              s.scale_m);
  EXPECT_NEAR(s.free_path_m / 2.034, 1.0, 0.03);
  EXPECT_GT(s.diagonal_m, 30);
  EXPECT_NEAR(s.scale_m, kDiagonalPerFreePath * s.free_path_m, 1e-9);
  EXPECT_LT(s.scale_m, 8.0);
}

TEST(SceneScale, AnOpenSceneKeepsItsDiagonal) {
  // A floor seen from above: every ray from it escapes.
  const recon::Scene scene = BoxScene("scale_open", test::SquareObj("room", 2.0),
                                      Json{{"cam", test::DownCamera(0, 0, 3, 64, 48, 40)}});
  const SceneScale s = Measure(scene);
  EXPECT_TRUE(std::isnan(s.free_path_m));
  EXPECT_EQ(s.hit_fraction, 0.0);
  EXPECT_DOUBLE_EQ(s.scale_m, s.diagonal_m);
}

}  // namespace
}  // namespace igi::solver
