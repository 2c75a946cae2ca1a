#include "recon/camera.h"

#include <gtest/gtest.h>

namespace igi::recon {
namespace {

Camera MakeCamera(CameraModel model) {
  Camera cam;
  cam.model = model;
  cam.width = 320;
  cam.height = 240;
  cam.params = {277.1, 270.5, 160.0, 120.0};
  if (model == CameraModel::kOpenCv) cam.params.insert(cam.params.end(), {-0.2, 0.05, 0.001, -0.002});
  // Looking along world +y from (1, -2, 0.5): camera z = world y, camera y = -world z.
  Eigen::Matrix3d r;
  r << 1, 0, 0, 0, 0, -1, 0, 1, 0;
  cam.cam_from_world.rotation = Eigen::Quaterniond(r);
  cam.cam_from_world.translation = -(r * Eigen::Vector3d(1, -2, 0.5));
  return cam;
}

TEST(CameraTest, PixelConventionPutsPrincipalRayAtPrincipalPoint) {
  Camera cam = MakeCamera(CameraModel::kPinhole);
  // A point straight ahead projects to (cx, cy); pixel (0,0)'s centre is (0.5, 0.5).
  auto px = cam.ImgFromWorld(Eigen::Vector3d(1, 3, 0.5));
  ASSERT_TRUE(px);
  EXPECT_NEAR(px->x(), 160.0, 1e-9);
  EXPECT_NEAR(px->y(), 120.0, 1e-9);
  // A point above (world +z) lands above the centre (smaller y).
  EXPECT_LT(cam.ImgFromWorld(Eigen::Vector3d(1, 3, 1.0))->y(), 120.0);
  EXPECT_FALSE(cam.ImgFromWorld(Eigen::Vector3d(1, -5, 0.5)));  // behind
  EXPECT_NEAR((cam.CenterInWorld() - Eigen::Vector3d(1, -2, 0.5)).norm(), 0.0, 1e-12);
}

TEST(CameraTest, RayAndProjectionAreInverse) {
  for (CameraModel model : {CameraModel::kPinhole, CameraModel::kOpenCv}) {
    Camera cam = MakeCamera(model);
    for (double x : {0.5, 40.0, 160.0, 300.25}) {
      for (double y : {0.5, 100.0, 239.5}) {
        const Eigen::Vector3d ray = cam.WorldRayFromImg({x, y});
        EXPECT_NEAR(ray.norm(), 1.0, 1e-12);
        auto back = cam.ImgFromWorld(cam.CenterInWorld() + 3.0 * ray);
        ASSERT_TRUE(back);
        EXPECT_NEAR(back->x(), x, 1e-6) << int(model);
        EXPECT_NEAR(back->y(), y, 1e-6) << int(model);
      }
    }
  }
}

TEST(CameraTest, ColmapModelsConvertExactly) {
  auto simple = ConvertColmapCameraModel("SIMPLE_PINHOLE", {500, 320, 240});
  ASSERT_TRUE(simple);
  EXPECT_EQ(simple->first, CameraModel::kPinhole);
  EXPECT_EQ(simple->second, (std::vector<double>{500, 500, 320, 240}));
  auto radial = ConvertColmapCameraModel("RADIAL", {500, 320, 240, 0.1, -0.01});
  ASSERT_TRUE(radial);
  EXPECT_EQ(radial->second, (std::vector<double>{500, 500, 320, 240, 0.1, -0.01, 0, 0}));
  EXPECT_FALSE(ConvertColmapCameraModel("OPENCV_FISHEYE", {1, 1, 1, 1, 0, 0, 0, 0}));
  EXPECT_FALSE(ConvertColmapCameraModel("PINHOLE", {1, 1, 1}));
}

}  // namespace
}  // namespace igi::recon
