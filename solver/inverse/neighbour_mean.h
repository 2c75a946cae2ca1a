#pragma once
// The mean of per-point values over each point's neighbours on the same surface: same region,
// normals within ~25° (dot >= 0.9), within a radius, and optionally from the same photo. The
// solver smooths its gathered indirect irradiance with it (solver/inverse/paper_stage.cpp).

#include <Eigen/Core>
#include <vector>

namespace igi::solver {

struct NeighbourPoint {
  Eigen::Vector3f position = Eigen::Vector3f::Zero();
  Eigen::Vector3f normal = Eigen::Vector3f::UnitZ();  // unit
  int region = -1;
  int photo = -1;
};

// For each i in `subset` (indices into `points` and `values`): the mean of values[j] over the
// j in `subset` with points[j] of the same region, |p_j − p_i| <= radius, n_j·n_i >= 0.9 and,
// when `same_photo`, the same photo (i itself always counts). Writes out[i] for i in `subset`;
// `out` must have values.size() elements. Exact (every neighbour counts); a uniform grid of
// cells of the radius, points sorted by (region, cell); per cell, the points of its 27 cells in
// flat arrays tested and summed without branches (vectorised).
// With `point_radius` (per point, each <= radius), point i's neighbours are those within
// point_radius[i] instead.
void NeighbourMean(const std::vector<NeighbourPoint>& points,
                   const std::vector<Eigen::Vector3d>& values, const std::vector<int>& subset,
                   double radius, bool same_photo, int num_threads,
                   std::vector<Eigen::Vector3d>* out,
                   const std::vector<float>* point_radius = nullptr);

}  // namespace igi::solver
