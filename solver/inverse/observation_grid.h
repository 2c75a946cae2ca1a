#pragma once
// Internal to igi_solver: the solver's observations by lighting, region and cell of a uniform
// grid, for the queries that look at an observation's neighbours on the same surface (the albedo
// maps' own pass, the smoothing radius where the observations were drawn).

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "recon/scene.h"
#include "solver/inverse/observation_set.h"

namespace igi::solver {

class ObservationGrid {
 public:
  // The observations of the regions r with regions[r] nonzero, in cells of `cell` metres, grouped
  // by their photo's lighting or (by_photo) by their photo. `scene` is the observations' (for
  // their photos' lightings); both must outlive the grid.
  ObservationGrid(const recon::Scene& scene, const ObservationSet& obs,
                  const std::vector<char>& regions, double cell, bool by_photo = false)
      : scene_(scene), obs_(obs), cell_(cell), by_photo_(by_photo) {
    for (size_t i = 0; i < obs.size(); ++i) {
      const Observation& o = obs[i];
      if (!regions[o.region]) continue;
      cells_[Key(GroupOf(o), o.region, CellOf(o.position.cast<double>()))].push_back(int(i));
    }
  }

  // Calls f(i) for every observation i of `region` in group `g` (a lighting, or a photo when
  // grouped by photo) in the cells within `reach` cells of p's ((2·reach + 1)³ cells: all those
  // within reach cells of p, and some farther).
  template <class F>
  void ForEachNear(int g, int region, const Eigen::Vector3d& p, F&& f, int reach = 1) const {
    const Eigen::Vector3i c = CellOf(p);
    for (int dz = -reach; dz <= reach; ++dz) {
      for (int dy = -reach; dy <= reach; ++dy) {
        for (int dx = -reach; dx <= reach; ++dx) {
          const auto it = cells_.find(Key(g, region, c + Eigen::Vector3i(dx, dy, dz)));
          if (it == cells_.end()) continue;
          for (int i : it->second) {
            const Observation& o = obs_[i];  // (keys of other cells may collide)
            if (o.region == region && GroupOf(o) == g) f(i);
          }
        }
      }
    }
  }

  // The nearest observation of `region` in group `g` to `p` with its normal within ~25° of n
  // (dot >= 0.9), within the 27 cells around p's; -1 when none.
  int Nearest(int g, int region, const Eigen::Vector3d& p, const Eigen::Vector3d& n) const {
    int best = -1;
    double best_d2 = INFINITY;
    ForEachNear(g, region, p, [&](int i) {
      const Observation& o = obs_[i];
      if (o.normal.cast<double>().dot(n) < 0.9) return;
      const double d2 = (o.position.cast<double>() - p).squaredNorm();
      if (d2 < best_d2) best_d2 = d2, best = i;
    });
    return best;
  }

 private:
  int GroupOf(const Observation& o) const {
    return by_photo_ ? o.photo : scene_.photos[o.photo].lighting;
  }
  Eigen::Vector3i CellOf(const Eigen::Vector3d& p) const {
    return (p / cell_).array().floor().cast<int>();
  }
  static uint64_t Key(int g, int region, const Eigen::Vector3i& c) {
    const auto u = [](int v) { return uint64_t(uint32_t(v) & 0xfffff); };
    return (uint64_t(g & 0xff) << 56) ^ (uint64_t(region & 0xfff) << 44) ^
           (u(c.x()) << 24 | u(c.y()) << 4) ^ (u(c.z()) * 0x9e3779b1ULL);
  }
  const recon::Scene& scene_;
  const ObservationSet& obs_;
  double cell_;
  bool by_photo_;
  std::unordered_map<uint64_t, std::vector<int>> cells_;
};

}  // namespace igi::solver
