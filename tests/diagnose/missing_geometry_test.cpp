// missing_geometry's pieces on synthetic cameras with known truth: residual blobs (coherent
// regions, not fireflies), carving a box seen by four cameras out of their blob images, telling it
// from its shadow (a blob on the modelled floor), and projecting it back as a mask.
#include "solver/diagnose/missing_geometry.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>

#include "solver/render/sampling.h"

namespace igi::diagnose {
namespace {

constexpr int kW = 160, kH = 120;

// A pinhole camera at `eye` looking at `target` (z up in the world; image y down).
recon::Camera LookAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& target) {
  recon::Camera c;
  c.width = kW;
  c.height = kH;
  c.params = {138.56, 138.56, 80.0, 60.0};
  const Eigen::Vector3d z = (target - eye).normalized();
  const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Matrix3d r;  // rows: the camera axes in the world
  r.row(0) = x;
  r.row(1) = y;
  r.row(2) = z;
  const Eigen::Quaterniond q(r);
  c.cam_from_world = Rigid3d(q, -(q * eye));
  return c;
}

// Ray / axis-aligned box: entry distance or infinity.
double HitBox(const Eigen::Vector3d& o, const Eigen::Vector3d& d, const Eigen::AlignedBox3d& b) {
  double t0 = 0, t1 = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 3; ++k) {
    const double a = (b.min()[k] - o[k]) / d[k], c = (b.max()[k] - o[k]) / d[k];
    t0 = std::max(t0, std::min(a, c));
    t1 = std::min(t1, std::max(a, c));
  }
  return t0 <= t1 ? t0 : std::numeric_limits<double>::infinity();
}

struct Truth {
  Eigen::AlignedBox3d object{Eigen::Vector3d(2.3, 1.3, 0.0), Eigen::Vector3d(2.7, 1.7, 0.4)};
  Eigen::AlignedBox2d shadow{Eigen::Vector2d(2.7, 1.2), Eigen::Vector2d(3.2, 1.8)};  // on z = 0
  bool with_object = true;
};

// The views of a 4 × 4 m floor (z = 0; the model has nothing else) from four cameras at the
// corners; blob = the ray meets the object, or the floor inside the shadow rectangle.
std::vector<CarveView> Views(const Truth& truth) {
  const Eigen::Vector3d target(2.2, 1.8, 0.2);
  std::vector<CarveView> views;
  const Eigen::Vector3d eyes[] = {
      {0.3, 0.3, 2.4}, {3.7, 0.3, 2.2}, {3.7, 3.7, 2.5}, {0.3, 3.7, 2.3}};
  for (int k = 0; k < 4; ++k) {
    CarveView v;
    v.camera = LookAt(eyes[k], target);
    v.camera_id = k;
    v.depth_m = Image(kW, kH, 1);
    v.state = Image(kW, kH, 1);
    const Eigen::Vector3d o = v.camera.CenterInWorld();
    for (int y = 0; y < kH; ++y) {
      for (int x = 0; x < kW; ++x) {
        const Eigen::Vector3d d = v.camera.WorldRayFromImg(Eigen::Vector2d(x + 0.5, y + 0.5));
        const double t_floor = d.z() < 0 ? -o.z() / d.z() : std::numeric_limits<double>::infinity();
        v.depth_m.at(x, y) = float(t_floor);
        const double t_obj = truth.with_object ? HitBox(o, d, truth.object)
                                               : std::numeric_limits<double>::infinity();
        const Eigen::Vector3d p = o + t_floor * d;
        const bool shadow = std::isfinite(t_floor) && truth.shadow.contains(p.head<2>());
        v.state.at(x, y) = t_obj < t_floor || shadow ? 1.0f : 0.0f;
      }
    }
    views.push_back(std::move(v));
  }
  return views;
}

recon::TriangleMesh Floor() {
  recon::TriangleMesh m;
  m.positions = {{0, 0, 0}, {4, 0, 0}, {4, 4, 0}, {0, 4, 0}};
  m.triangles = {{0, 1, 2}, {0, 2, 3}};
  return m;
}

VoxelGrid Grid() {
  return VoxelGrid::Over(
      Eigen::AlignedBox3d(Eigen::Vector3d(-0.05, -0.05, -0.05), Eigen::Vector3d(4.05, 4.05, 2.55)),
      0.05);
}

// The carved box's centre comes within two voxels (0.1 m) of the truth (measured: 0.075, its top
// raised by the hull); its base reaches the floor it stands on; the shadow patch is told apart.
TEST(MissingGeometryTest, CarvesTheObjectAndTellsItFromItsShadow) {
  const Truth truth;
  const std::vector<CarveView> views = Views(truth);
  const VoxelGrid grid = Grid();
  const std::vector<uint8_t> carved = CarveVoxels(views, grid, 2);
  const std::vector<uint8_t> carved_object =
      CarveVoxels(WithoutSurfaceBlobs(views, grid.voxel_m), grid, 2);
  const std::vector<uint8_t> near = NearSurfaceVoxels(Floor(), grid);
  const std::vector<CarvedObject> objects = CarvedObjects(carved_object, carved, near, grid, 8);
  ASSERT_EQ(objects.size(), 1u);
  const CarvedObject& o = objects[0];
  EXPECT_LT((o.center - truth.object.center()).norm(), 0.1)
      << o.center.transpose() << " vs " << truth.object.center().transpose();
  // Four silhouettes bound the object by its visual hull: the box covers the object (within a
  // voxel) and exceeds it by the hull's corners, here 0.3 m at most (measured 0.3, 0.3, 0.15).
  for (int k = 0; k < 3; ++k) {
    EXPECT_GE(o.size_m[k], truth.object.sizes()[k] - 0.05 - 1e-9) << o.size_m.transpose();
    EXPECT_LE(o.size_m[k], truth.object.sizes()[k] + 0.3 + 1e-9) << o.size_m.transpose();
  }
  EXPECT_LE(o.center.z() - 0.5 * o.size_m.z(), 0.05);  // down to the floor
  // The shadow: surface voxels, on the floor, beside the object.
  ASSERT_GT(o.shadow_voxels.size(), 20u);
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (int64_t i : o.shadow_voxels) {
    const Eigen::Vector3d c = grid.Center(i);
    EXPECT_LT(std::abs(c.z()), 0.11);
    mean += c / double(o.shadow_voxels.size());
  }
  EXPECT_GT(mean.x(), 2.75);  // the shadow rectangle spans x 2.7..3.2 (measured 2.88)
  // Projected back, the object covers its silhouette in every view (dilated 2 px).
  for (const CarveView& v : views) {
    const Image mask = ProjectVoxels(v, grid, o.box_voxels, 2);
    int object_px = 0, covered = 0;
    const Eigen::Vector3d c = v.camera.CenterInWorld();
    for (int y = 0; y < kH; ++y) {
      for (int x = 0; x < kW; ++x) {
        const Eigen::Vector3d d = v.camera.WorldRayFromImg(Eigen::Vector2d(x + 0.5, y + 0.5));
        if (!std::isfinite(HitBox(c, d, truth.object))) continue;
        ++object_px;
        covered += mask.at(x, y) > 0.5f;
      }
    }
    ASSERT_GT(object_px, 30);
    EXPECT_EQ(covered, object_px);
  }
}

// A blob on the floor alone (a shadow, a stain) lies on the modelled surface: no object.
TEST(MissingGeometryTest, ABlobOnTheSurfaceIsNoObject) {
  Truth truth;
  truth.with_object = false;
  const VoxelGrid grid = Grid();
  const std::vector<CarveView> views = Views(truth);
  const std::vector<uint8_t> carved = CarveVoxels(views, grid, 2);
  const std::vector<uint8_t> carved_object =
      CarveVoxels(WithoutSurfaceBlobs(views, grid.voxel_m), grid, 2);
  const std::vector<uint8_t> near = NearSurfaceVoxels(Floor(), grid);
  EXPECT_TRUE(CarvedObjects(carved_object, carved, near, grid, 8).empty());
  // From every blob the patch raises a phantom volume above the floor; the object blobs do not.
  EXPECT_FALSE(CarvedObjects(carved, carved, near, grid, 8).empty());
}

// A texture on the floor near the blob threshold: every view shows the patch as a blob but misses
// a different quarter of it (the photo noise). Each blob pixel's surface point is then "clear" in
// one of the three other views and a blob in two: by most views it is still a change on the
// surface, no object. (With the unanimous rule of before, those pixels stayed object blobs and
// carved a phantom above the floor: the suite's control saw one, 10 voxels, 8 the minimum.)
TEST(MissingGeometryTest, ABlobThatOneViewPartlyMissesIsStillOnTheSurface) {
  Truth truth;
  truth.with_object = false;
  const VoxelGrid grid = Grid();
  std::vector<CarveView> views = Views(truth);
  const Eigen::Vector2d mid = truth.shadow.center();
  for (int k = 0; k < int(views.size()); ++k) {
    CarveView& v = views[size_t(k)];
    const Eigen::Vector3d o = v.camera.CenterInWorld();
    for (int y = 0; y < kH; ++y) {
      for (int x = 0; x < kW; ++x) {
        if (!(v.state.at(x, y) > 0.5f)) continue;
        const Eigen::Vector3d p =
            o + double(v.depth_m.at(x, y)) * v.camera.WorldRayFromImg(Eigen::Vector2d(x + 0.5, y + 0.5));
        const int quarter = (p.x() > mid.x() ? 1 : 0) + (p.y() > mid.y() ? 2 : 0);
        if (quarter == k) v.state.at(x, y) = 0.0f;  // missed here: clear
      }
    }
  }
  const std::vector<uint8_t> carved = CarveVoxels(views, grid, 2);
  const std::vector<CarveView> object_views = WithoutSurfaceBlobs(views, grid.voxel_m);
  const std::vector<uint8_t> near = NearSurfaceVoxels(Floor(), grid);
  EXPECT_TRUE(CarvedObjects(CarveVoxels(object_views, grid, 2), carved, near, grid, 8).empty());
  // Every blob pixel that the other views see became unknown.
  for (size_t k = 0; k < views.size(); ++k) {
    int blob = 0, unknown = 0;
    for (int y = 0; y < kH; ++y) {
      for (int x = 0; x < kW; ++x) {
        blob += views[k].state.at(x, y) > 0.5f;
        unknown += views[k].state.at(x, y) > 0.5f && object_views[k].state.at(x, y) < -0.5f;
      }
    }
    ASSERT_GT(blob, 50);
    EXPECT_GT(unknown, blob * 9 / 10) << "view " << k;
  }
}

// One camera alone cannot place a blob: with a single view nothing is carved.
TEST(MissingGeometryTest, OneViewCarvesNothing) {
  const std::vector<CarveView> views = Views(Truth{});
  const VoxelGrid grid = Grid();
  const std::vector<uint8_t> carved = CarveVoxels({views[0]}, grid, 2);
  for (uint8_t v : carved) ASSERT_EQ(v, 0);
}

// Blobs: a coherent 14×14 region 40% off is found; noise (2%) and 30 single-pixel fireflies
// (5× the value) are not; unusable pixels are unknown.
TEST(MissingGeometryTest, BlobsAreCoherentRegionsNotFireflies) {
  Image sim(kW, kH, 3), rec(kW, kH, 3), usable(kW, kH, 1, 1.0f);
  render::Pcg32 rng(7, 1);
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x) {
      for (int c = 0; c < 3; ++c) {
        sim.at(x, y, c) = 0.5f + 0.2f * float(x) / kW;
        rec.at(x, y, c) = sim.at(x, y, c) * (1 + 0.02f * float(rng.UniformDouble() - 0.5) * 3.4f);
      }
    }
  }
  for (int y = 50; y < 64; ++y) {
    for (int x = 100; x < 114; ++x) {
      for (int c = 0; c < 3; ++c) rec.at(x, y, c) *= 0.6f;
    }
  }
  for (int k = 0; k < 30; ++k) {
    const int x = 5 + (k * 37) % 80, y = 5 + (k * 23) % 40;
    for (int c = 0; c < 3; ++c) rec.at(x, y, c) *= 5;
  }
  for (int x = 0; x < kW; ++x) usable.at(x, 0) = 0;
  const Image state = FindResidualBlobs(rec, sim, usable, MissingGeometryOptions{});
  int blob = 0, inside = 0;
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x) {
      if (!(state.at(x, y) > 0.5f)) continue;
      ++blob;
      inside += x >= 99 && x <= 114 && y >= 49 && y <= 64;  // the region and its smoothing rim
    }
  }
  EXPECT_EQ(blob, inside);
  EXPECT_GE(blob, 14 * 14);
  EXPECT_EQ(state.at(3, 0), -1.0f);
  EXPECT_EQ(state.at(3, 1), 0.0f);
}

}  // namespace
}  // namespace igi::diagnose
