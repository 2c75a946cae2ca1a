#include "solver/inverse/neighbour_mean.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>

#include "tools/common/parallel.h"

namespace igi::solver {
namespace {

struct CellKey {
  int region = 0;
  int64_t x = 0, y = 0, z = 0;
  bool operator==(const CellKey& o) const {
    return region == o.region && x == o.x && y == o.y && z == o.z;
  }
  bool operator<(const CellKey& o) const {
    if (region != o.region) return region < o.region;
    if (x != o.x) return x < o.x;
    if (y != o.y) return y < o.y;
    return z < o.z;
  }
};

struct CellKeyHash {
  size_t operator()(const CellKey& k) const {
    uint64_t h = uint64_t(k.region) * 0x9E3779B97F4A7C15ull;
    h ^= uint64_t(k.x) * 73856093ull + (h << 6) + (h >> 2);
    h ^= uint64_t(k.y) * 19349663ull + (h << 6) + (h >> 2);
    h ^= uint64_t(k.z) * 83492791ull + (h << 6) + (h >> 2);
    return size_t(h);
  }
};

// One cell's candidates (the points of its 27 cells, same region) in flat arrays that the inner
// loops read sequentially: a test pass writes each candidate's weight (1 or 0) for one point, a
// sum pass adds the weighted values; both free of branches, so the compiler vectorises them.
struct Candidates {
  std::vector<float> x, y, z, nx, ny, nz, weight;
  std::vector<int> photo;
  std::vector<double> vx, vy, vz;
  // weight[j] = 1 where candidate j is p's neighbour, else 0.
  void Weigh(const NeighbourPoint& p, float r2, bool same_photo) {
    const int m = int(x.size());
    const float px = p.position.x(), py = p.position.y(), pz = p.position.z();
    const float qx = p.normal.x(), qy = p.normal.y(), qz = p.normal.z();
    const int ph = same_photo ? p.photo : 0, any_photo = same_photo ? 0 : 1;
    WeighRange(x.data(), y.data(), z.data(), nx.data(), ny.data(), nz.data(), photo.data(), m, px,
               py, pz, qx, qy, qz, r2, ph, any_photo, weight.data());
  }
  static void WeighRange(const float* __restrict x, const float* __restrict y,
                         const float* __restrict z, const float* __restrict nx,
                         const float* __restrict ny, const float* __restrict nz,
                         const int* __restrict photo, int m, float px, float py, float pz, float qx,
                         float qy, float qz, float r2, int ph, int any_photo, float* __restrict w) {
    for (int j = 0; j < m; ++j) {
      const float ex = x[j] - px, ey = y[j] - py, ez = z[j] - pz;
      const float d2 = ex * ex + ey * ey + ez * ez;
      const float dot = nx[j] * qx + ny[j] * qy + nz[j] * qz;
      const int same = (photo[j] == ph) | any_photo;
      w[j] = float(int(d2 <= r2) & int(dot >= 0.9f) & same);
    }
  }
  // (Σ weight·value, Σ weight), in two-lane partial sums (SSE2 packets).
  Eigen::Vector4d WeightedSum() const {
    using A2 = Eigen::Array2d;
    using M2 = Eigen::Map<const A2>;
    A2 sx = A2::Zero(), sy = sx, sz = sx, count = sx;
    const int m = int(x.size());
    int j = 0;
    for (; j + 2 <= m; j += 2) {
      const A2 wj(weight[j], weight[j + 1]);
      sx += wj * M2(vx.data() + j), sy += wj * M2(vy.data() + j), sz += wj * M2(vz.data() + j);
      count += wj;
    }
    Eigen::Vector4d sum(sx.sum(), sy.sum(), sz.sum(), count.sum());
    for (; j < m; ++j) sum += double(weight[j]) * Eigen::Vector4d(vx[j], vy[j], vz[j], 1.0);
    return sum;
  }
  void Clear() {
    for (auto* v : {&x, &y, &z, &nx, &ny, &nz}) v->clear();
    photo.clear();
    vx.clear(), vy.clear(), vz.clear();
  }
};

}  // namespace

void NeighbourMean(const std::vector<NeighbourPoint>& points,
                   const std::vector<Eigen::Vector3d>& values, const std::vector<int>& subset,
                   double radius, bool same_photo, int num_threads,
                   std::vector<Eigen::Vector3d>* out, const std::vector<float>* point_radius) {
  if (subset.empty()) return;
  const double inv = 1.0 / radius;
  auto cell_of = [&](int i) {
    const Eigen::Vector3f& q = points[i].position;
    return CellKey{points[i].region, int64_t(std::floor(q.x() * inv)),
                   int64_t(std::floor(q.y() * inv)), int64_t(std::floor(q.z() * inv))};
  };
  std::vector<std::pair<CellKey, int>> keyed(subset.size());
  for (size_t k = 0; k < subset.size(); ++k) keyed[k] = {cell_of(subset[k]), subset[k]};
  std::sort(keyed.begin(), keyed.end(), [](const auto& a, const auto& b) {
    return a.first < b.first || (a.first == b.first && a.second < b.second);
  });
  const size_t n = keyed.size();
  // The cells in (region, cell) order: [begin, end) into `keyed`, and each key's cell.
  std::vector<std::pair<int, int>> cells;
  std::unordered_map<CellKey, int, CellKeyHash> cell_of_key;
  cell_of_key.reserve(n / 4 + 1);
  for (size_t k = 0; k < n; ++k) {
    if (k == 0 || !(keyed[k].first == keyed[k - 1].first)) {
      cell_of_key[keyed[k].first] = int(cells.size());
      cells.emplace_back(int(k), int(k));
    }
    cells.back().second = int(k) + 1;
  }
  const float r2 = float(radius * radius);
  ParallelFor(
      0, int64_t(cells.size()),
      [&](int64_t cell) {
        const CellKey c = keyed[cells[cell].first].first;
        thread_local Candidates cand;
        cand.Clear();
        for (int64_t dx = -1; dx <= 1; ++dx) {
          for (int64_t dy = -1; dy <= 1; ++dy) {
            for (int64_t dz = -1; dz <= 1; ++dz) {
              const auto it = cell_of_key.find(CellKey{c.region, c.x + dx, c.y + dy, c.z + dz});
              if (it == cell_of_key.end()) continue;
              for (int j = cells[it->second].first; j < cells[it->second].second; ++j) {
                const NeighbourPoint& q = points[keyed[j].second];
                const Eigen::Vector3d& v = values[keyed[j].second];
                cand.x.push_back(q.position.x()), cand.y.push_back(q.position.y());
                cand.z.push_back(q.position.z());
                cand.nx.push_back(q.normal.x()), cand.ny.push_back(q.normal.y());
                cand.nz.push_back(q.normal.z());
                cand.photo.push_back(q.photo);
                cand.vx.push_back(v.x()), cand.vy.push_back(v.y()), cand.vz.push_back(v.z());
              }
            }
          }
        }
        const int m = int(cand.x.size());
        cand.weight.resize(m);
        for (int k = cells[cell].first; k < cells[cell].second; ++k) {
          const int i = keyed[k].second;
          const NeighbourPoint& p = points[i];
          const float ri = point_radius ? std::min((*point_radius)[i], float(radius)) : 0.0f;
          cand.Weigh(p, point_radius ? ri * ri : r2, same_photo);
          const Eigen::Vector4d sum = cand.WeightedSum();
          const double count = sum[3];
          (*out)[i] = count > 0 ? Eigen::Vector3d(sum.head<3>() / count) : values[i];
        }
      },
      num_threads);
}

}  // namespace igi::solver
