// The joint refinement of igi-register (recon/registration_refinement.h) on synthetic data with
// known truth: a room mesh, cameras inside it, sparse points on its surfaces observed exactly
// (tracks), and control points (the boxes' and the room's corners) observed exactly. The poses
// and points are then disturbed — a common similarity (what an imperfect marker / ICP fit leaves)
// plus independent errors per pose and point — and the refinement must give the truth back.
// Observations are exact, so the optimum is the truth: the tolerances (1e-3 degrees, 0.1 mm,
// 1e-4 px) only leave room for the solver's convergence tolerance, and are 100x below what the
// disturbance (0.3-0.8 degrees, 1-3 cm) would leave if the refinement did nothing.
#include "recon/registration_refinement.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>

#include "recon/camera.h"
#include "recon/registration.h"

namespace igi::recon {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

void AddQuad(const Vector3d& p0, const Vector3d& p1, const Vector3d& p2, const Vector3d& p3,
             TriangleMesh* mesh) {
  const int base = static_cast<int>(mesh->positions.size());
  for (const Vector3d& p : {p0, p1, p2, p3}) mesh->positions.push_back(p.cast<float>());
  mesh->triangles.emplace_back(base, base + 1, base + 2);
  mesh->triangles.emplace_back(base, base + 2, base + 3);
  mesh->triangle_region.push_back(0);
  mesh->triangle_region.push_back(0);
}

std::vector<Vector3d> BoxCorners(const Vector3d& lo, const Vector3d& hi) {
  std::vector<Vector3d> c;
  for (int i = 0; i < 8; ++i) {
    c.emplace_back(i & 1 ? hi.x() : lo.x(), i & 2 ? hi.y() : lo.y(), i & 4 ? hi.z() : lo.z());
  }
  return c;
}

void AddBox(const Vector3d& lo, const Vector3d& hi, TriangleMesh* mesh) {
  const std::vector<Vector3d> c = BoxCorners(lo, hi);
  AddQuad(c[0], c[1], c[3], c[2], mesh);
  AddQuad(c[4], c[5], c[7], c[6], mesh);
  AddQuad(c[0], c[1], c[5], c[4], mesh);
  AddQuad(c[2], c[3], c[7], c[6], mesh);
  AddQuad(c[0], c[2], c[6], c[4], mesh);
  AddQuad(c[1], c[3], c[7], c[5], mesh);
}

struct Truth {
  TriangleMesh mesh;
  std::vector<Camera> cameras;
  std::vector<Vector3d> points;  // sparse points on the mesh
  Markers markers;
  ColmapModel model;  // exact
};

Rigid3d LookAt(const Vector3d& center, const Vector3d& target) {
  const Vector3d f = (target - center).normalized();
  const Vector3d r = f.cross(Vector3d::UnitZ()).normalized();
  const Vector3d d = f.cross(r);
  Eigen::Matrix3d m;
  m.row(0) = r;
  m.row(1) = d;
  m.row(2) = f;
  const Eigen::Quaterniond q(m);
  return Rigid3d(q, -(q * center));
}

bool InFrame(const Camera& camera, const Vector3d& x, Vector2d* pixel) {
  const auto p = camera.ImgFromWorld(x);
  if (!p || p->x() < 0 || p->y() < 0 || p->x() > camera.width || p->y() > camera.height) {
    return false;
  }
  *pixel = *p;
  return true;
}

void BuildModel(Truth* t) {
  ColmapCamera cam{1, t->cameras[0].model == CameraModel::kOpenCv ? "OPENCV" : "PINHOLE",
                   t->cameras[0].width, t->cameras[0].height, t->cameras[0].params};
  t->model.cameras[1] = cam;
  for (size_t i = 0; i < t->cameras.size(); ++i) {
    ColmapImage image;
    image.image_id = static_cast<uint32_t>(i + 1);
    image.camera_id = 1;
    image.name = t->cameras[i].name;
    image.qvec = QvecFromQuaternion(t->cameras[i].cam_from_world.rotation);
    image.tvec = t->cameras[i].cam_from_world.translation;
    t->model.images[image.image_id] = image;
  }
  uint64_t next = 1;
  for (const Vector3d& x : t->points) {
    ColmapPoint3D point{next, x, {0, 0, 0}, 0, {}};
    for (auto& [id, image] : t->model.images) {
      Vector2d px;
      if (!InFrame(t->cameras[id - 1], x, &px)) continue;
      point.track.push_back({id, static_cast<uint32_t>(image.points2d.size())});
      image.points2d.push_back({px, static_cast<int64_t>(next)});
    }
    if (point.track.size() < 2) {  // keep no lone observations
      for (const ColmapTrackElement& e : point.track) {
        t->model.images.at(e.image_id).points2d.pop_back();
      }
      continue;
    }
    t->model.points3d[next++] = point;
  }
}

// 4 x 4 x 3 m room with two boxes, 8 cameras looking across it, 600 points on the surfaces.
Truth MakeTruth(bool distorted) {
  Truth t;
  t.mesh.region_names = {"all"};
  AddBox({0, 0, 0}, {4, 4, 3}, &t.mesh);
  AddBox({2.5, 2.3, 0}, {3.4, 3.0, 0.6}, &t.mesh);
  AddBox({0.6, 2.8, 0}, {1.2, 3.4, 1.4}, &t.mesh);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0, 1);
  for (int i = 0; i < 8; ++i) {
    const double a = 2 * M_PI * i / 8;
    Camera c;
    c.name = "cam" + std::to_string(i) + ".png";
    c.width = 640;
    c.height = 480;
    c.model = distorted ? CameraModel::kOpenCv : CameraModel::kPinhole;
    c.params = {500, 505, 321.5, 238.5};
    if (distorted) c.params.insert(c.params.end(), {-0.12, 0.03, 0.001, -0.002});
    const Vector3d center(2 + 1.3 * std::cos(a), 2 + 1.3 * std::sin(a), 1.2 + 0.4 * u(rng));
    const Vector3d target(2 - 1.5 * std::cos(a + 0.4), 2 - 1.5 * std::sin(a + 0.4), 0.8);
    c.cam_from_world = LookAt(center, target);
    t.cameras.push_back(c);
  }
  // Points on the four walls and the floor.
  for (int i = 0; i < 600; ++i) {
    const int face = i % 5;
    const double s = u(rng), r = u(rng);
    const Vector3d x = face == 0   ? Vector3d(4 * s, 4 * r, 0)
                       : face == 1 ? Vector3d(0, 4 * s, 3 * r)
                       : face == 2 ? Vector3d(4, 4 * s, 3 * r)
                       : face == 3 ? Vector3d(4 * s, 0, 3 * r)
                                   : Vector3d(4 * s, 4, 3 * r);
    t.points.push_back(x);
  }
  std::vector<Vector3d> corners = BoxCorners({0, 0, 0}, {4, 4, 3});
  for (const auto& c : BoxCorners({2.5, 2.3, 0}, {3.4, 3.0, 0.6})) corners.push_back(c);
  for (const auto& c : BoxCorners({0.6, 2.8, 0}, {1.2, 3.4, 1.4})) corners.push_back(c);
  for (size_t i = 0; i < corners.size(); ++i) {
    const std::string name = "corner" + std::to_string(i);
    t.markers.points[name] = corners[i];
    for (const Camera& camera : t.cameras) {
      Vector2d px;
      if (InFrame(camera, corners[i], &px)) t.markers.pixels[camera.name][name] = px;
    }
  }
  BuildModel(&t);
  return t;
}

// A common similarity (0.5 degrees, 1 % scale, 3 cm) and independent errors (0.3 degrees and
// 1 cm per pose, 1 cm per point).
void Disturb(ColmapModel* model) {
  Similarity3d common;
  common.scale = 1.01;
  common.rotation = Eigen::AngleAxisd(0.5 * M_PI / 180, Vector3d(0.2, 0.9, -0.4).normalized());
  common.translation = {0.03, -0.01, 0.02};
  TransformModel(common, model);
  std::mt19937_64 rng(9);
  std::normal_distribution<double> n(0, 1);
  for (auto& [id, image] : model->images) {
    const Eigen::Quaterniond dq(
        Eigen::AngleAxisd(0.3 * M_PI / 180, Vector3d(n(rng), n(rng), n(rng)).normalized()));
    image.qvec = QvecFromQuaternion(dq * QuaternionFromQvec(image.qvec));
    image.tvec += 0.01 * Vector3d(n(rng), n(rng), n(rng));
  }
  for (auto& [id, p] : model->points3d) p.xyz += 0.01 * Vector3d(n(rng), n(rng), n(rng));
}

struct Errors {
  double rotation_deg = 0;
  double position_m = 0;
};

Errors MaxPoseErrors(const Truth& t, const ColmapModel& model) {
  Errors e;
  for (const Camera& truth : t.cameras) {
    const ColmapImage* image = model.FindImageByName(truth.name);
    EXPECT_NE(image, nullptr) << truth.name;
    if (image == nullptr) continue;
    const Camera c = CameraOfImage(model, *image);
    const double angle =
        Eigen::AngleAxisd(c.cam_from_world.rotation * truth.cam_from_world.rotation.conjugate())
            .angle();
    e.rotation_deg = std::max(e.rotation_deg, angle * 180 / M_PI);
    e.position_m = std::max(e.position_m, (c.CenterInWorld() - truth.CenterInWorld()).norm());
  }
  return e;
}

constexpr double kRotationTolDeg = 1e-3;
constexpr double kPositionTolM = 1e-4;

void ExpectRecovered(const Truth& t, const ColmapModel& model, const BundleRefinementSummary& s) {
  const Errors e = MaxPoseErrors(t, model);
  EXPECT_LT(e.rotation_deg, kRotationTolDeg);
  EXPECT_LT(e.position_m, kPositionTolM);
  double point_error = 0;
  for (const auto& [id, p] : model.points3d) {
    point_error = std::max(point_error, (p.xyz - t.model.points3d.at(id).xyz).norm());
  }
  EXPECT_LT(point_error, kPositionTolM);
  EXPECT_LT(s.rms_after_px, 1e-4);
  EXPECT_LT(s.marker_rms_after_px, 1e-4);
  EXPECT_GT(s.rms_before_px, 1.0);  // the disturbance was real
  EXPECT_EQ(s.images, static_cast<int>(t.cameras.size()));
  EXPECT_EQ(s.points, static_cast<int>(t.model.points3d.size()));
  ASSERT_EQ(s.per_image.size(), t.cameras.size());
  for (const ImageRefinement& r : s.per_image) {
    EXPECT_GT(r.observations, 20) << r.name;
    EXPECT_LT(r.rms_after_px, 1e-4) << r.name;
  }
}

TEST(RegistrationRefinementTest, DisturbanceIsLargeWithoutRefinement) {
  const Truth t = MakeTruth(false);
  ColmapModel model = t.model;
  Disturb(&model);
  const Errors e = MaxPoseErrors(t, model);
  EXPECT_GT(e.rotation_deg, 100 * kRotationTolDeg);
  EXPECT_GT(e.position_m, 100 * kPositionTolM);
}

TEST(RegistrationRefinementTest, RecoversPosesAndPointsWithMarkersAndMesh) {
  const Truth t = MakeTruth(false);
  ASSERT_GT(t.model.points3d.size(), 300u);
  ColmapModel model = t.model;
  Disturb(&model);
  BundleRefinementOptions options;
  options.mesh_sigma_m = 0.005;
  options.mesh_max_distance_m = 0.1;
  const BundleRefinementSummary s = RefineBundle(&t.markers, &t.mesh, &model, options);
  ExpectRecovered(t, model, s);
  EXPECT_GT(s.mesh_points, 300);
  EXPECT_LT(s.mesh_rms_after_m, 1e-5);
  EXPECT_GT(s.marker_observations, 30);
}

TEST(RegistrationRefinementTest, MarkersAloneFixTheFrameWithDistortion) {
  const Truth t = MakeTruth(true);
  ColmapModel model = t.model;
  Disturb(&model);
  BundleRefinementOptions options;
  options.use_mesh = false;
  const BundleRefinementSummary s = RefineBundle(&t.markers, &t.mesh, &model, options);
  EXPECT_EQ(s.mesh_points, 0);
  ExpectRecovered(t, model, s);
}

// A mismatched feature (50 px off) is dropped from the model after the first solve; the rest
// comes back exactly.
TEST(RegistrationRefinementTest, DropsOutlierObservations) {
  const Truth t = MakeTruth(false);
  ColmapModel model = t.model;
  ColmapImage& image = model.images.begin()->second;
  size_t bad = 0;
  while (image.points2d[bad].point3d_id < 0) ++bad;
  image.points2d[bad].xy += Vector2d(50, -20);
  const uint64_t point_id = static_cast<uint64_t>(image.points2d[bad].point3d_id);
  const size_t track_size = model.points3d.at(point_id).track.size();
  Disturb(&model);
  BundleRefinementOptions options;
  options.use_mesh = false;
  const BundleRefinementSummary s = RefineBundle(&t.markers, nullptr, &model, options);
  EXPECT_EQ(s.outliers, 1);
  EXPECT_EQ(model.images.begin()->second.points2d[bad].point3d_id, -1);
  if (track_size > 2) {
    EXPECT_EQ(model.points3d.at(point_id).track.size(), track_size - 1);
  } else {
    EXPECT_EQ(model.points3d.count(point_id), 0u);
  }
  const Errors e = MaxPoseErrors(t, model);
  EXPECT_LT(e.rotation_deg, kRotationTolDeg);
  EXPECT_LT(e.position_m, kPositionTolM);
  EXPECT_LT(s.rms_after_px, 1e-4);
}

// A photo posed 20 degrees off (as COLMAP has posed a close-up from wrong matches) misses its
// markers: it is posed from them again and its track observations leave the model. The others
// are left alone.
TEST(RegistrationRefinementTest, RePosesPhotoThatMissesItsMarkers) {
  const Truth t = MakeTruth(false);
  ColmapModel model = t.model;
  ColmapImage& image = model.images.at(4);
  ASSERT_GE(t.markers.pixels.at(image.name).size(), 4u);
  image.qvec = QvecFromQuaternion(Eigen::AngleAxisd(20 * M_PI / 180, Vector3d::UnitY()) *
                                  QuaternionFromQvec(image.qvec));
  const auto reposed = RePoseImagesFromMarkers(t.markers, &model);
  ASSERT_EQ(reposed.size(), 1u);
  EXPECT_EQ(reposed[0].name, image.name);
  EXPECT_GT(reposed[0].rms_before_px, 10);
  EXPECT_LT(reposed[0].rms_px, 1e-6);
  const Errors e = MaxPoseErrors(t, model);
  EXPECT_LT(e.rotation_deg, 1e-6);
  EXPECT_LT(e.position_m, 1e-8);
  for (const ColmapPoint2D& p : model.images.at(4).points2d) EXPECT_EQ(p.point3d_id, -1);
  for (const auto& [id, p] : model.points3d) {
    EXPECT_GE(p.track.size(), 2u);
    for (const ColmapTrackElement& el : p.track) EXPECT_NE(el.image_id, 4u);
  }
  EXPECT_TRUE(RePoseImagesFromMarkers(t.markers, &model).empty());  // all agree now
}

TEST(RegistrationRefinementTest, NeedsMarkersOrMesh) {
  const Truth t = MakeTruth(false);
  ColmapModel model = t.model;
  EXPECT_THROW(RefineBundle(nullptr, nullptr, &model, {}), Error);
  BundleRefinementOptions bad;
  bad.track_sigma_px = 0;
  EXPECT_THROW(RefineBundle(&t.markers, nullptr, &model, bad), Error);
}

// A photo the model lacks is posed from its markers (PnP + LM) and then refined with the rest.
TEST(RegistrationRefinementTest, PosesPhotoFromMarkersAlone) {
  const Truth t = MakeTruth(false);
  ColmapModel model = t.model;
  const std::string name = t.cameras[3].name;
  ASSERT_GE(t.markers.pixels.at(name).size(), 6u);
  const uint32_t id = model.FindImageByName(name)->image_id;
  for (auto& [pid, p] : model.points3d)
    std::erase_if(p.track, [&](auto& e) { return e.image_id == id; });
  model.images.erase(id);
  std::erase_if(model.points3d, [](const auto& p) { return p.second.track.size() < 2; });
  const auto added = PoseImagesFromMarkers(t.markers, {name, "other.png"}, &model);
  ASSERT_EQ(added.size(), 1u);
  EXPECT_EQ(added[0].name, name);
  EXPECT_LT(added[0].rms_px, 1e-6);
  ASSERT_NE(model.FindImageByName(name), nullptr);
  EXPECT_TRUE(model.FindImageByName(name)->points2d.empty());
  const Errors e = MaxPoseErrors(t, model);
  EXPECT_LT(e.rotation_deg, 1e-6);
  EXPECT_LT(e.position_m, 1e-8);
  // Fewer markers than asked: not posed.
  model.images.erase(model.FindImageByName(name)->image_id);
  EXPECT_TRUE(PoseImagesFromMarkers(t.markers, {name}, &model, 100).empty());
}

}  // namespace
}  // namespace igi::recon
