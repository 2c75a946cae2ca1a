// The solver's neighbour mean (solver/inverse/neighbour_mean.h) against a brute-force O(n²)
// reference on random points: two regions, a plane and a curved surface (normals that fail the 25°
// test), several photos, points on cell boundaries, and a subset (one lighting's observations).
#include "solver/inverse/neighbour_mean.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace igi::solver {
namespace {

std::vector<Eigen::Vector3d> BruteForce(const std::vector<NeighbourPoint>& pts,
                                        const std::vector<Eigen::Vector3d>& values,
                                        const std::vector<int>& subset, double radius,
                                        bool same_photo,
                                        const std::vector<float>* point_radius = nullptr) {
  std::vector<Eigen::Vector3d> out(values.size(), Eigen::Vector3d::Zero());
  for (int i : subset) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    int count = 0;
    const float r = point_radius ? (*point_radius)[i] : float(radius);
    for (int j : subset) {
      const NeighbourPoint &a = pts[i], &b = pts[j];
      if (a.region != b.region || (a.position - b.position).squaredNorm() > r * r ||
          a.normal.dot(b.normal) < 0.9f || (same_photo && a.photo != b.photo)) {
        continue;
      }
      sum += values[j];
      ++count;
    }
    out[i] = sum / count;
  }
  return out;
}

struct Points {
  std::vector<NeighbourPoint> pts;
  std::vector<Eigen::Vector3d> values;
};

Points RandomPoints(int n, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  Points p;
  for (int i = 0; i < n; ++i) {
    NeighbourPoint q;
    q.photo = i % 3;
    if (i % 2 == 0) {  // region 0: the floor z = 0, x, y in [0, 0.5], some on the cell grid
      q.region = 0;
      const float x = i % 10 == 0 ? 0.1f * float(i % 5) : 0.5f * u(rng);
      q.position = {x, 0.5f * u(rng), 0.0f};
      q.normal = Eigen::Vector3f::UnitZ();
    } else {  // region 1: a cylinder of radius 0.1 around the y axis at z = 0.2
      q.region = 1;
      const float a = 3.0f * u(rng);
      q.normal = {std::sin(a), 0.0f, std::cos(a)};
      q.position = Eigen::Vector3f(0.0f, 0.5f * u(rng), 0.2f) + 0.1f * q.normal;
    }
    p.pts.push_back(q);
    p.values.emplace_back(u(rng), 2.0 * u(rng), -u(rng));
  }
  return p;
}

TEST(NeighbourMeanTest, MatchesBruteForce) {
  const Points p = RandomPoints(3000, 5);
  std::vector<int> subset;
  for (int i = 0; i < 3000; ++i) {
    if (i % 7 != 3) subset.push_back(i);  // the others belong to another lighting
  }
  for (bool same_photo : {false, true}) {
    for (double radius : {0.03, 0.1}) {
      std::vector<Eigen::Vector3d> fast(p.values.size(), Eigen::Vector3d::Constant(-99));
      NeighbourMean(p.pts, p.values, subset, radius, same_photo, 2, &fast);
      const auto slow = BruteForce(p.pts, p.values, subset, radius, same_photo);
      for (int i = 0; i < 3000; ++i) {
        if (i % 7 == 3) {  // not in the subset: untouched
          EXPECT_EQ(fast[i], Eigen::Vector3d::Constant(-99));
          continue;
        }
        // Same neighbours, summed in another order: equal to rounding.
        ASSERT_LT((fast[i] - slow[i]).norm(), 1e-9) << "point " << i << " radius " << radius;
      }
    }
  }
}

// The adaptive smoothing's per-point radii (each within the cell size).
TEST(NeighbourMeanTest, PerPointRadiiMatchBruteForce) {
  const Points p = RandomPoints(3000, 9);
  std::vector<int> subset(3000);
  for (int i = 0; i < 3000; ++i) subset[i] = i;
  std::vector<float> radii(3000);
  for (int i = 0; i < 3000; ++i) radii[i] = 0.01f + 0.09f * float((i * 37) % 100) / 99.0f;
  for (bool same_photo : {false, true}) {
    std::vector<Eigen::Vector3d> fast(p.values.size());
    NeighbourMean(p.pts, p.values, subset, 0.1, same_photo, 2, &fast, &radii);
    const auto slow = BruteForce(p.pts, p.values, subset, 0.1, same_photo, &radii);
    const auto fixed = BruteForce(p.pts, p.values, subset, 0.1, same_photo);
    int differ = 0;
    for (int i = 0; i < 3000; ++i) {
      ASSERT_LT((fast[i] - slow[i]).norm(), 1e-9) << "point " << i;
      differ += (slow[i] - fixed[i]).norm() > 1e-6;
    }
    EXPECT_GT(differ, 1000);  // the radii matter
  }
}

TEST(NeighbourMeanTest, AnIsolatedPointKeepsItsValue) {
  std::vector<NeighbourPoint> pts(2);
  pts[0].position = {0, 0, 0};
  pts[1].position = {1, 0, 0};
  pts[0].region = pts[1].region = 0;
  const std::vector<Eigen::Vector3d> values = {{1, 2, 3}, {4, 5, 6}};
  std::vector<Eigen::Vector3d> out(2);
  NeighbourMean(pts, values, {0, 1}, 0.1, false, 1, &out);
  EXPECT_EQ(out[0], values[0]);
  EXPECT_EQ(out[1], values[1]);
}

}  // namespace
}  // namespace igi::solver
