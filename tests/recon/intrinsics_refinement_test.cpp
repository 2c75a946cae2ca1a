// The principal point and aspect ratio refinement on synthetic models with known truth: recovered
// where the views determine them, left as they were where they do not.
#include "recon/intrinsics_refinement.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>

#include "recon/camera.h"
#include "recon/registration.h"
#include "tools/common/error.h"

namespace igi::recon {
namespace {

using Eigen::Vector3d;

constexpr int kWidth = 1000, kHeight = 700;
// The true camera: OPENCV fx, fy, cx, cy, k1, k2, p1, p2 (principal point 20 px right of and 15
// px below the centre, fy / fx = 1.002).
const std::vector<double> kTruth = {1000, 1002, 520, 365, -0.05, 0, 0, 0};

struct SyntheticView {
  Eigen::Quaterniond cam_from_world;
  Vector3d centre;
};

// A façade-like point cloud (a plane at z = 10 with a recess and a protrusion) and views of it.
// `varied`: the views are spread along x and turned to look at the middle (as Herz-Jesu's);
// otherwise all look straight down +z from one plane and every point lies on z = 10 (the
// principal point then trades exactly with the points' position).
ColmapModel SyntheticModel(bool varied, int views, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uniform(-1, 1);
  std::normal_distribution<double> noise(0, 0.3);  // px, SIFT-like
  std::vector<Vector3d> points;
  for (int i = 0; i < 1500; ++i) {
    Vector3d x(4 * uniform(rng), 3 * uniform(rng), 10);
    if (varied && std::abs(x.x()) < 1.5) x.z() += x.y() > 0 ? 1.5 : -1.0;
    points.push_back(x);
  }
  Camera truth;
  truth.model = CameraModel::kOpenCv;
  truth.width = kWidth;
  truth.height = kHeight;
  truth.params = kTruth;
  ColmapModel model;
  model.cameras[1] = {1, "SIMPLE_RADIAL", kWidth, kHeight, {1000, 500, 350, -0.05}};
  for (int v = 0; v < views; ++v) {
    const double s = views > 1 ? -1 + 2.0 * v / (views - 1) : 0;
    const Vector3d centre(3 * s, varied ? 0.8 * std::sin(3.0 * v) : 0, varied ? 1.5 * s * s : 0);
    Eigen::Quaterniond world_from_cam = Eigen::Quaterniond::Identity();
    if (varied) {  // look at the façade's middle, with some roll
      const Vector3d forward = (Vector3d(0, 0, 10) - centre).normalized();
      const Vector3d right = Vector3d::UnitY().cross(forward).normalized();
      Eigen::Matrix3d r;
      r.col(0) = right;
      r.col(1) = forward.cross(right);
      r.col(2) = forward;
      world_from_cam = Eigen::Quaterniond(r) * Eigen::AngleAxisd(0.1 * v, Vector3d::UnitZ());
    }
    truth.cam_from_world =
        Rigid3d(world_from_cam.conjugate(), -(world_from_cam.conjugate() * centre));
    ColmapImage image;
    image.image_id = static_cast<uint32_t>(v + 1);
    image.camera_id = 1;
    image.name = "view" + std::to_string(v) + ".png";
    const Eigen::Quaterniond q = truth.cam_from_world.rotation;
    image.qvec = Eigen::Vector4d(q.w(), q.x(), q.y(), q.z());
    image.tvec = truth.cam_from_world.translation;
    for (size_t p = 0; p < points.size(); ++p) {
      const auto px = truth.ImgFromWorld(points[p]);
      if (!px || px->x() < 0 || px->y() < 0 || px->x() > kWidth || px->y() > kHeight) continue;
      const uint32_t idx = static_cast<uint32_t>(image.points2d.size());
      image.points2d.push_back(
          {*px + Eigen::Vector2d(noise(rng), noise(rng)), static_cast<int64_t>(p + 1)});
      auto& point = model.points3d[p + 1];
      point.point3d_id = p + 1;
      point.xyz = points[p];
      point.track.push_back({image.image_id, idx});
    }
    model.images[image.image_id] = image;
  }
  std::erase_if(model.points3d, [](const auto& p) { return p.second.track.size() < 2; });
  for (auto& [id, image] : model.images) {
    for (ColmapPoint2D& p : image.points2d) {
      if (model.points3d.count(static_cast<uint64_t>(p.point3d_id)) == 0) p.point3d_id = -1;
    }
  }
  return model;
}

TEST(IntrinsicsRefinementTest, RecoversPrincipalPointAndAspectFromVariedViews) {
  ColmapModel model = SyntheticModel(true, 8, 1);
  IntrinsicsRefinementOptions options;
  const IntrinsicsRefinementSummary s = RefineSelfCalibratedIntrinsics(&model, options);
  ASSERT_EQ(s.KeptFor(1), "principal_point+aspect") << s.adjustments.at(0).cameras.at(0).verdict;
  const ColmapCamera& camera = model.cameras.at(1);
  ASSERT_EQ(camera.model, "OPENCV");
  const CameraIntrinsicsFit& fit = s.adjustments.back().cameras.at(0);
  std::printf("pp %.2f %.2f (sigma %.2f %.2f) aspect %.5f (sigma %.5f) f %.2f\n", camera.params[2],
              camera.params[3], fit.principal_point_sigma_px[0], fit.principal_point_sigma_px[1],
              camera.params[1] / camera.params[0], fit.aspect_sigma, camera.params[0]);
  // Within 4 standard deviations, and the deviations small enough to be kept.
  EXPECT_NEAR(camera.params[2], kTruth[2], 4 * fit.principal_point_sigma_px[0]);
  EXPECT_NEAR(camera.params[3], kTruth[3], 4 * fit.principal_point_sigma_px[1]);
  EXPECT_NEAR(camera.params[1] / camera.params[0], kTruth[1] / kTruth[0], 4 * fit.aspect_sigma);
  EXPECT_NEAR(camera.params[4], kTruth[4], 0.005);
  EXPECT_DOUBLE_EQ(camera.params[5], 0);  // SIMPLE_RADIAL has no k2, p1, p2: held at zero
  EXPECT_DOUBLE_EQ(camera.params[6], 0);
}

// Views that all look the same way at one plane: the principal point trades with the points'
// position, so nothing is kept and the model is COLMAP's.
TEST(IntrinsicsRefinementTest, KeepsColmapsCameraWhenViewsDoNotDetermineIt) {
  ColmapModel model = SyntheticModel(false, 6, 2);
  const ColmapModel before = model;
  const IntrinsicsRefinementSummary s = RefineSelfCalibratedIntrinsics(&model, {});
  EXPECT_EQ(s.KeptFor(1), "none");
  ASSERT_EQ(s.adjustments.size(), 1u);
  const CameraIntrinsicsFit& fit = s.adjustments[0].cameras.at(0);
  std::printf("%s\n", fit.verdict.c_str());
  EXPECT_NE(fit.verdict, "kept");
  EXPECT_EQ(model, before);
  // kOn keeps the adjustment regardless.
  IntrinsicsRefinementOptions on;
  on.mode = PrincipalPointRefinement::kOn;
  EXPECT_EQ(RefineSelfCalibratedIntrinsics(&model, on).KeptFor(1), "principal_point+aspect");
  EXPECT_EQ(model.cameras.at(1).model, "OPENCV");
}

TEST(IntrinsicsRefinementTest, OffLeavesTheModelAndBadOptionsAreRefused) {
  ColmapModel model = SyntheticModel(true, 4, 3);
  const ColmapModel before = model;
  IntrinsicsRefinementOptions off;
  off.mode = PrincipalPointRefinement::kOff;
  const IntrinsicsRefinementSummary s = RefineSelfCalibratedIntrinsics(&model, off);
  EXPECT_EQ(s.KeptFor(1), "none");
  EXPECT_TRUE(s.adjustments.empty());
  EXPECT_EQ(model, before);
  IntrinsicsRefinementOptions bad;
  bad.max_principal_point_offset = 0.7;
  EXPECT_THROW(RefineSelfCalibratedIntrinsics(&model, bad), InputError);
  EXPECT_EQ(PrincipalPointRefinementFromName("auto"), PrincipalPointRefinement::kAuto);
  EXPECT_EQ(PrincipalPointRefinementName(PrincipalPointRefinement::kOff), "off");
  EXPECT_FALSE(PrincipalPointRefinementFromName("yes").has_value());
}

}  // namespace
}  // namespace igi::recon
