// Marker-based alignment on a synthetic model with known truth: cameras and control points in a
// scene frame, the model in another frame (a known similarity away); the alignment must recover
// the poses to rounding error since the pixels are exact projections.
#include "recon/registration.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "tests/temp_dir.h"
#include "tools/common/error.h"

namespace igi::recon {
namespace {

namespace fs = std::filesystem;

// A camera at `center` looking at the origin (z forward, y down roughly along -up).
ColmapImage LookAtOrigin(uint32_t id, const Eigen::Vector3d& center) {
  const Eigen::Vector3d z = -center.normalized();
  const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Matrix3d r;
  r.row(0) = x;
  r.row(1) = y;
  r.row(2) = z;
  ColmapImage image;
  image.image_id = id;
  image.camera_id = 1;
  image.name = "view" + std::to_string(id) + ".png";
  const Eigen::Quaterniond q(r);
  image.qvec = QvecFromQuaternion(q.normalized());
  image.tvec = -(r * center);
  return image;
}

struct Truth {
  ColmapModel scene_model;  // poses in the scene frame
  Markers markers;
};

Truth MakeTruth() {
  Truth truth;
  truth.scene_model.cameras[1] = {1, "PINHOLE", 640, 480, {500, 500, 320, 240}};
  const std::vector<Eigen::Vector3d> centers = {{4, 0.5, 1.5}, {0.3, 4, 1.2}, {-3, 2.5, 2}};
  for (uint32_t i = 0; i < centers.size(); ++i) {
    truth.scene_model.images[i + 1] = LookAtOrigin(i + 1, centers[i]);
  }
  truth.markers.points = {{"a", {0.5, 0.2, 0.1}},
                          {"b", {-0.4, 0.6, 0.3}},
                          {"c", {0.1, -0.5, 0.8}},
                          {"d", {-0.3, -0.2, -0.4}},
                          {"e", {0.7, 0.7, 0.0}}};
  for (const auto& [id, image] : truth.scene_model.images) {
    const Camera camera = CameraOfImage(truth.scene_model, image);
    for (const auto& [name, p] : truth.markers.points) {
      truth.markers.pixels[image.name][name] = *camera.ImgFromWorld(p);
    }
  }
  return truth;
}

TEST(RegistrationTest, MarkersRecoverKnownSimilarity) {
  const Truth truth = MakeTruth();
  // The model COLMAP would give: the scene seen in another frame, at another scale.
  Similarity3d model_from_scene;
  model_from_scene.scale = 0.37;
  model_from_scene.rotation = Eigen::AngleAxisd(0.8, Eigen::Vector3d(1, 2, 3).normalized());
  model_from_scene.translation = {1.5, -2, 0.7};
  ColmapModel model = truth.scene_model;
  TransformModel(model_from_scene, &model);

  const MarkerAlignment alignment = AlignByMarkers(model, truth.markers);
  EXPECT_EQ(alignment.used.size(), 5u);
  EXPECT_NEAR(alignment.scene_from_model.scale, 1 / 0.37, 1e-9);
  EXPECT_LT(alignment.rms_residual_m, 1e-9);  // exact pixels: rounding error only
  EXPECT_LT(alignment.rms_reprojection_px, 1e-6);
  TransformModel(alignment.scene_from_model, &model);
  for (const auto& [id, image] : model.images) {
    const ColmapImage& expected = truth.scene_model.images.at(id);
    const double angle =
        QuaternionFromQvec(image.qvec).angularDistance(QuaternionFromQvec(expected.qvec));
    EXPECT_LT(angle, 1e-9) << image.name;
    EXPECT_LT((image.tvec - expected.tvec).norm(), 1e-9) << image.name;
  }
}

TEST(RegistrationTest, TooFewMarkersIsAnError) {
  Truth truth = MakeTruth();
  truth.markers.points.erase("d");
  truth.markers.points.erase("e");
  truth.markers.points.erase("c");
  for (auto& [photo, seen] : truth.markers.pixels) {
    seen.erase("c");
    seen.erase("d");
    seen.erase("e");
  }
  EXPECT_THROW(AlignByMarkers(truth.scene_model, truth.markers), Error);
}

TEST(RegistrationTest, MarkersFileNamingUnknownPointIsRejected) {
  const fs::path dir = test::UniqueTempDir("igi_markers");
  std::ofstream(dir / "markers.json") << R"({"format": "igi-markers", "version": 1,
    "points": {"a": [0, 0, 0]},
    "pixels": {"view1.png": {"a": [10, 20], "ghost": [30, 40]}}})";
  try {
    ReadMarkers(dir / "markers.json");
    FAIL() << "unknown marker accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("ghost"), std::string::npos) << e.what();
  }
  std::ofstream(dir / "good.json") << R"({"format": "igi-markers", "version": 1,
    "points": {"a": [0, 0, 1]}, "pixels": {"view1.png": {"a": [10, 20]}}})";
  const Markers markers = ReadMarkers(dir / "good.json");
  EXPECT_EQ(markers.points.at("a"), Eigen::Vector3d(0, 0, 1));
  EXPECT_EQ(markers.pixels.at("view1.png").at("a"), Eigen::Vector2d(10, 20));
  fs::remove_all(dir);
}

TEST(RegistrationTest, ReprojectionErrorOfExactModelIsZero) {
  Truth truth = MakeTruth();
  ColmapModel& model = truth.scene_model;
  // One 3D point seen by every image at its exact projection.
  ColmapPoint3D point;
  point.point3d_id = 1;
  point.xyz = {0.1, 0.2, 0.3};
  for (auto& [id, image] : model.images) {
    const Camera camera = CameraOfImage(model, image);
    image.points2d.push_back({*camera.ImgFromWorld(point.xyz), 1});
    point.track.push_back({id, 0});
  }
  model.points3d[1] = point;
  for (const ImageReprojection& r : ReprojectionErrors(model)) {
    EXPECT_EQ(r.observations, 1);
    EXPECT_LT(r.rms_px, 1e-9);
  }
}

}  // namespace
}  // namespace igi::recon
