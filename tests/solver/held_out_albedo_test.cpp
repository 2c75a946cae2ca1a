// The held-out per-texel albedo (solver/inverse/held_out_albedo.h): a point's albedo comes from the
// other photos only, so a photo whose samples carry a highlight never lends it to its own samples.
#include "solver/inverse/held_out_albedo.h"

#include <gtest/gtest.h>

#include <cmath>

namespace igi::solver {
namespace {

// A 1 × 1 m square in z = 0 with UVs [0,1]², two triangles, region 0.
recon::TriangleMesh Square() {
  recon::TriangleMesh mesh;
  mesh.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  mesh.normals.assign(4, Eigen::Vector3f::UnitZ());
  mesh.uvs = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  mesh.triangle_region = {0, 0};
  mesh.region_names = {"floor"};
  return mesh;
}

// Triangle 0 has corners (0,0), (1,0), (1,1): barycentrics (b1, b2) give x = b1 + b2, y = b2.
struct Point {
  double b1, b2;
};
Point At(double x, double y) { return {x - y, y}; }

TEST(HeldOutAlbedo, EachPhotoReadsTheOtherPhotosOnly) {
  const recon::TriangleMesh mesh = Square();
  AtlasOptions options;
  options.texel_size_m = 0.1;  // 10 × 10 texels
  const RegionAtlas atlas = BuildRegionAtlas(mesh, 0, options);
  HeldOutAlbedo held(atlas);
  // Photo 0 sees albedo 0.5 everywhere in triangle 0 (x > y), photo 1 sees 0.8 where x > 0.6,
  // with irradiance 2 (numerator π·L = albedo·E).
  for (int i = 0; i < 100; ++i) {
    for (int j = 0; j < 100; ++j) {
      const double x = (i + 0.5) / 100, y = (j + 0.5) / 100;
      if (x <= y) continue;
      const Point p = At(x, y);
      held.Add(0, 0, p.b1, p.b2, Eigen::Vector3d::Constant(0.5 * 2), Eigen::Vector3d::Constant(2));
      if (x > 0.6) {
        held.Add(1, 0, p.b1, p.b2, Eigen::Vector3d(0.8, 0.7, 0.6) * 2,
                 Eigen::Vector3d::Constant(2));
      }
    }
  }
  const Point inside = At(0.8, 0.3), left = At(0.35, 0.1);
  EXPECT_TRUE(held.At(1, 0, inside.b1, inside.b2).isApprox(Eigen::Vector3d::Constant(0.5), 1e-9));
  EXPECT_TRUE(held.At(0, 0, inside.b1, inside.b2).isApprox(Eigen::Vector3d(0.8, 0.7, 0.6), 1e-9));
  EXPECT_TRUE(held.At(1, 0, left.b1, left.b2).isApprox(Eigen::Vector3d::Constant(0.5), 1e-9));
  // Only photo 0 saw this point: its own samples are left out, nothing remains.
  EXPECT_FALSE(held.At(0, 0, left.b1, left.b2).allFinite());
  // A third photo reads everything: the weighted mean of both where both saw the point.
  const Eigen::Vector3d both = held.At(2, 0, inside.b1, inside.b2);
  EXPECT_NEAR(both[0], 0.65, 1e-9);
  EXPECT_NEAR(both[2], 0.55, 1e-9);
}

}  // namespace
}  // namespace igi::solver
