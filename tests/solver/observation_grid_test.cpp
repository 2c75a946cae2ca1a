// The observation grid's nearest-neighbour query (solver/inverse/observation_grid.h) against a
// brute-force search on random points: two regions, four photos under two lightings, normals that
// fail the 25° test, grouped by lighting and by photo.
#include "solver/inverse/observation_grid.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace igi::solver {
namespace {

// The nearest observation of `region` with group(o) == g to p, normal within the test; -1 if none.
template <class Group>
int BruteForceNearest(const ObservationSet& obs, int g, int region, const Eigen::Vector3d& p,
                      const Eigen::Vector3d& n, Group group, double* distance) {
  int best = -1;
  double best_d2 = INFINITY;
  for (size_t i = 0; i < obs.size(); ++i) {
    const Observation& o = obs[i];
    if (o.region != region || group(o) != g || o.normal.cast<double>().dot(n) < 0.9) continue;
    const double d2 = (o.position.cast<double>() - p).squaredNorm();
    if (d2 < best_d2) best_d2 = d2, best = int(i);
  }
  *distance = std::sqrt(best_d2);
  return best;
}

TEST(ObservationGrid, TheNearestIsTheNearestOfItsLightingOrOfItsPhoto) {
  recon::Scene scene;
  for (int k = 0; k < 4; ++k) {
    recon::Photo photo;
    photo.lighting = k % 2;
    scene.photos.push_back(photo);
  }
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  ObservationSet obs;
  for (int i = 0; i < 3000; ++i) {
    Observation o;
    o.photo = int(u01(rng) * 4);
    o.region = u01(rng) < 0.5 ? 0 : 1;
    o.position = Eigen::Vector3f(float(u01(rng)), float(u01(rng)), float(0.1 * u01(rng)));
    // A tenth of the normals tilted 40°: never a neighbour of an upward query.
    o.normal = u01(rng) < 0.1 ? Eigen::Vector3f(std::sin(0.7f), 0, std::cos(0.7f))
                              : Eigen::Vector3f(0, 0, 1);
    obs.items.push_back(o);
  }
  const double cell = 0.05;
  const std::vector<char> regions = {1, 1};
  const ObservationGrid by_lighting(scene, obs, regions, cell);
  const ObservationGrid by_photo(scene, obs, regions, cell, true);
  const auto lighting_of = [&](const Observation& o) { return scene.photos[o.photo].lighting; };
  const auto photo_of = [](const Observation& o) { return o.photo; };
  const Eigen::Vector3d up(0, 0, 1);
  int checked = 0;
  // The grid's nearest of group g against the brute force's: equal when that lies within a cell
  // of p (then among the 27 cells searched), and never of another group or region.
  const auto check = [&](const ObservationGrid& grid, int g, int region, const Eigen::Vector3d& p,
                         auto group_of, int q) {
    double d = 0;
    const int want = BruteForceNearest(obs, g, region, p, up, group_of, &d);
    const int got = grid.Nearest(g, region, p, up);
    if (d < cell) {
      EXPECT_EQ(got, want) << "query " << q;
      ++checked;
    }
    if (got >= 0) {
      EXPECT_EQ(group_of(obs[got]), g);
      EXPECT_EQ(obs[got].region, region);
    }
  };
  for (int q = 0; q < 500; ++q) {
    const Eigen::Vector3d p(u01(rng), u01(rng), 0.05);
    const int region = q % 2;
    check(by_lighting, q % 2, region, p, lighting_of, q);
    check(by_photo, q % 4, region, p, photo_of, q);
  }
  EXPECT_GT(checked, 400);
}

}  // namespace
}  // namespace igi::solver
