// Fitting sparse points to the scene mesh (recon/mesh_alignment.h) on synthetic data with known
// truth: points sampled on a room mesh, moved into another frame by a known similarity, with
// noise and outliers; and pose refinement against the mesh from perturbed poses.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>
#include <utility>

#include "recon/mesh_alignment.h"
#include "recon/mesh_closest_point.h"

namespace igi::recon {
namespace {

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

// An axis-aligned box [lo, hi] (both windings do for closest points).
void AddBox(const Vector3d& lo, const Vector3d& hi, TriangleMesh* mesh) {
  auto c = [&](int x, int y, int z) {
    return Vector3d(x ? hi.x() : lo.x(), y ? hi.y() : lo.y(), z ? hi.z() : lo.z());
  };
  AddQuad(c(0, 0, 0), c(1, 0, 0), c(1, 1, 0), c(0, 1, 0), mesh);
  AddQuad(c(0, 0, 1), c(1, 0, 1), c(1, 1, 1), c(0, 1, 1), mesh);
  AddQuad(c(0, 0, 0), c(1, 0, 0), c(1, 0, 1), c(0, 0, 1), mesh);
  AddQuad(c(0, 1, 0), c(1, 1, 0), c(1, 1, 1), c(0, 1, 1), mesh);
  AddQuad(c(0, 0, 0), c(0, 1, 0), c(0, 1, 1), c(0, 0, 1), mesh);
  AddQuad(c(1, 0, 0), c(1, 1, 0), c(1, 1, 1), c(1, 0, 1), mesh);
}

// A 4 x 4 x 3 m room with two boxes (they break the room's symmetries).
TriangleMesh Room() {
  TriangleMesh mesh;
  mesh.region_names = {"all"};
  AddBox({0, 0, 0}, {4, 4, 3}, &mesh);
  AddBox({2.5, 2.3, 0}, {3.4, 3.0, 0.6}, &mesh);
  AddBox({0.6, 2.8, 0}, {1.2, 3.4, 1.4}, &mesh);
  return mesh;
}

// Points on the mesh (area-uniform) with Gaussian noise `sigma_m`, plus `outliers` uniform in
// the room's box.
std::vector<Vector3d> PointsOnMesh(const TriangleMesh& mesh, int count, double sigma_m,
                                   int outliers, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::normal_distribution<double> n(0, sigma_m);
  std::vector<double> cdf;
  double total = 0;
  for (size_t t = 0; t < mesh.num_triangles(); ++t) cdf.push_back(total += mesh.TriangleArea(t));
  std::vector<Vector3d> points;
  for (int i = 0; i < count; ++i) {
    const size_t t =
        static_cast<size_t>(std::lower_bound(cdf.begin(), cdf.end(), u(rng) * total) - cdf.begin());
    const Eigen::Vector3i& tri = mesh.triangles[t];
    double a = u(rng), b = u(rng);
    if (a + b > 1) a = 1 - a, b = 1 - b;
    const Vector3d p0 = mesh.positions[tri[0]].cast<double>();
    const Vector3d p = p0 + a * (mesh.positions[tri[1]].cast<double>() - p0) +
                       b * (mesh.positions[tri[2]].cast<double>() - p0);
    points.push_back(p + Vector3d(n(rng), n(rng), n(rng)));
  }
  for (int i = 0; i < outliers; ++i) points.emplace_back(4 * u(rng), 4 * u(rng), 3 * u(rng));
  return points;
}

Similarity3d TrueSceneFromModel() {
  Similarity3d s;
  s.scale = 2.7;
  s.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(1.1, Vector3d(0.3, -0.5, 0.8).normalized()));
  s.translation = {1.5, -0.7, 0.4};
  return s;
}

std::vector<Vector3d> ToModel(const std::vector<Vector3d>& scene, const Similarity3d& s) {
  std::vector<Vector3d> out;
  for (const Vector3d& p : scene)
    out.push_back(s.rotation.conjugate() * (p - s.translation) / s.scale);
  return out;
}

double AngleDeg(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  return Eigen::AngleAxisd(a * b.conjugate()).angle() * 180.0 / M_PI;
}

TEST(MeshClosestPointTest, ClosestPointOnTriangleRegions) {
  const Vector3d a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  EXPECT_TRUE(ClosestPointOnTriangle({0.2, 0.3, 5}, a, b, c).isApprox(Vector3d(0.2, 0.3, 0)));
  EXPECT_TRUE(ClosestPointOnTriangle({-1, -1, 1}, a, b, c).isApprox(a));
  EXPECT_TRUE(ClosestPointOnTriangle({0.5, -2, 0}, a, b, c).isApprox(Vector3d(0.5, 0, 0)));
  EXPECT_TRUE(ClosestPointOnTriangle({1, 1, 0}, a, b, c).isApprox(Vector3d(0.5, 0.5, 0)));
}

// The BVH query agrees with brute force over every triangle (to float rounding of the BVH).
TEST(MeshClosestPointTest, MatchesBruteForce) {
  const TriangleMesh mesh = Room();
  const MeshClosestPoint closest(mesh);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1, 5);
  for (int i = 0; i < 300; ++i) {
    const Vector3d p(u(rng), u(rng), u(rng));
    double best = 1e30;
    for (const auto& t : mesh.triangles) {
      best = std::min(best, (ClosestPointOnTriangle(p, mesh.positions[t[0]].cast<double>(),
                                                    mesh.positions[t[1]].cast<double>(),
                                                    mesh.positions[t[2]].cast<double>()) -
                             p)
                                .norm());
    }
    const auto c = closest.Query(p);
    ASSERT_TRUE(c.has_value());
    EXPECT_NEAR(c->distance_m, best, 1e-6);
  }
  EXPECT_FALSE(closest.Query({2, 2, 1.5}, 0.1).has_value());  // 1.5 m from every face
}

// Rays against the BVH: the hit's point (from t and from the barycentrics) lies on the mesh at
// the first triangle along the ray; t_min and t_max bound it; a ray from outside the closed
// room pointing away from it misses.
TEST(MeshClosestPointTest, IntersectFindsTheFirstTriangle) {
  const TriangleMesh mesh = Room();
  const MeshClosestPoint bvh(mesh);
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> u(0.5, 3.5), d(-1, 1);
  int hits = 0;
  for (int i = 0; i < 200; ++i) {
    const Vector3d origin(u(rng), u(rng), 0.5 * u(rng));
    const Vector3d dir = Vector3d(d(rng), d(rng), d(rng)).normalized();
    const auto hit = bvh.Intersect(origin, dir);
    if (!hit) continue;
    ++hits;
    const Vector3d p = origin + hit->t * dir;
    const auto& t = mesh.triangles[hit->triangle];
    const Vector3d from_bary = (1 - hit->b1 - hit->b2) * mesh.positions[t[0]].cast<double>() +
                               hit->b1 * mesh.positions[t[1]].cast<double>() +
                               hit->b2 * mesh.positions[t[2]].cast<double>();
    EXPECT_LT((p - from_bary).norm(), 1e-4);
    EXPECT_LT(bvh.Query(p)->distance_m, 1e-4);
    // Nothing closer: the hit point is the first mesh point along the ray.
    for (double s = 0.02; s < hit->t - 0.02; s += 0.02) {
      ASSERT_GT(bvh.Query(origin + s * dir)->distance_m, 1e-5) << "ray " << i << " at " << s;
    }
    EXPECT_FALSE(bvh.Intersect(origin, dir, 0, hit->t - 1e-3).has_value());
    const auto beyond = bvh.Intersect(origin, dir, hit->t + 1e-3);
    if (beyond) {
      EXPECT_GT(beyond->t, hit->t);
    }
  }
  EXPECT_EQ(hits, 200);  // the room is closed
  EXPECT_FALSE(bvh.Intersect({-1, 2, 1}, {-1, 0, 0}).has_value());
  const auto in = bvh.Intersect({-1, 2, 1}, {1, 0, 0});
  ASSERT_TRUE(in.has_value());
  EXPECT_NEAR(in->t, 1.0, 1e-5);  // the wall x = 0
}

// From a start 5 degrees, 10 % scale and 0.3 m off, with 5 mm noise and 10 % outliers: the
// recovered similarity is within 0.05 degrees, 0.1 % scale and 5 mm (noise averaged over
// thousands of points leaves far less).
TEST(MeshAlignmentTest, IcpFromRoughStartRecoversSimilarity) {
  const TriangleMesh mesh = Room();
  const Similarity3d truth = TrueSceneFromModel();
  const auto points = ToModel(PointsOnMesh(mesh, 4000, 0.005, 400, 1), truth);
  Similarity3d start = truth;
  start.scale *= 1.1;
  start.rotation =
      Eigen::AngleAxisd(5 * M_PI / 180, Vector3d(1, 1, 0).normalized()) * start.rotation;
  start.translation += Vector3d(0.3, -0.2, 0.1);
  const MeshAlignmentSummary s = AlignPointsToMesh(points, mesh, start);
  EXPECT_LT(AngleDeg(s.scene_from_model.rotation, truth.rotation), 0.05);
  EXPECT_NEAR(s.scene_from_model.scale / truth.scale, 1.0, 1e-3);
  EXPECT_LT((s.scene_from_model.translation - truth.translation).norm(), 0.005);
  EXPECT_NEAR(s.inlier_fraction, 4000.0 / 4400, 0.05);
  EXPECT_LT(s.rms_m, 0.012);  // 5 mm per axis: the normal component's RMS, with a 3-sigma cut
  EXPECT_GT(s.iterations, 1);
  EXPECT_EQ(s.start, "given");
}

// No start at all: the principal-axes hypotheses find the same fit.
TEST(MeshAlignmentTest, CoarseStartFromPrincipalAxes) {
  const TriangleMesh mesh = Room();
  const Similarity3d truth = TrueSceneFromModel();
  const auto points = ToModel(PointsOnMesh(mesh, 4000, 0.005, 200, 2), truth);
  const MeshAlignmentSummary s = AlignPointsToMeshCoarse(points, mesh);
  EXPECT_EQ(s.start, "pca");
  EXPECT_EQ(s.hypotheses, 224);
  EXPECT_LT(AngleDeg(s.scene_from_model.rotation, truth.rotation), 0.05);
  EXPECT_NEAR(s.scene_from_model.scale / truth.scale, 1.0, 1e-3);
  EXPECT_LT((s.scene_from_model.translation - truth.translation).norm(), 0.005);
}

// Poses 1 degree and 5 cm off are brought back by the snapped points (exact projections).
TEST(MeshAlignmentTest, RefinePosesAgainstMesh) {
  const TriangleMesh mesh = Room();
  const auto points = PointsOnMesh(mesh, 3000, 0.0, 0, 4);
  ColmapModel model;
  model.cameras[1] = {1, "PINHOLE", 640, 480, {500, 500, 320, 240}};
  const std::vector<Vector3d> centers = {{1, 1, 1.5}, {3, 1.2, 1.6}, {2, 3.5, 1.2}};
  const std::vector<Vector3d> targets = {{3, 3, 1}, {0.5, 3, 1}, {2, 0, 1.5}};
  for (size_t p = 0; p < points.size(); ++p) {
    model.points3d[p + 1].point3d_id = p + 1;
    model.points3d[p + 1].xyz = points[p];
  }
  std::vector<Rigid3d> truth;
  for (uint32_t i = 0; i < centers.size(); ++i) {
    const Vector3d z = (targets[i] - centers[i]).normalized();
    const Vector3d x = z.cross(Vector3d::UnitZ()).normalized();
    Eigen::Matrix3d r;
    r.row(0) = x;
    r.row(1) = z.cross(x);
    r.row(2) = z;
    ColmapImage image;
    image.image_id = i + 1;
    image.camera_id = 1;
    image.name = std::string("view") + char('0' + i);
    image.qvec = QvecFromQuaternion(Eigen::Quaterniond(r));
    image.tvec = -(r * centers[i]);
    truth.push_back(Rigid3d(Eigen::Quaterniond(r), image.tvec));
    model.images[i + 1] = image;
    const Camera camera = CameraOfImage(model, image);
    for (const auto& [id, p] : std::as_const(model.points3d)) {
      const auto px = camera.ImgFromWorld(p.xyz);
      if (!px || px->x() < 0 || px->y() < 0 || px->x() > 640 || px->y() > 480) continue;
      const auto index = static_cast<uint32_t>(model.images[i + 1].points2d.size());
      model.images[i + 1].points2d.push_back({*px, static_cast<int64_t>(id)});
      model.points3d[id].track.push_back({i + 1, index});
    }
    // Perturb.
    const Eigen::Quaterniond off(Eigen::AngleAxisd(M_PI / 180, Vector3d(0, 1, 1).normalized()));
    model.images[i + 1].qvec = QvecFromQuaternion(off * Eigen::Quaterniond(r));
    model.images[i + 1].tvec += Vector3d(0.05, -0.03, 0.02);
  }
  const PoseRefinementSummary s = RefinePosesAgainstMesh(mesh, 0.01, &model);
  EXPECT_EQ(s.images, 3);
  EXPECT_GT(s.rms_before_px, 5.0);
  EXPECT_LT(s.rms_after_px, 1e-6);
  for (uint32_t i = 0; i < truth.size(); ++i) {
    const ColmapImage& image = model.images.at(i + 1);
    EXPECT_LT(AngleDeg(QuaternionFromQvec(image.qvec), truth[i].rotation), 1e-6);
    EXPECT_LT((image.tvec - truth[i].translation).norm(), 1e-6);
  }
}

}  // namespace
}  // namespace igi::recon
