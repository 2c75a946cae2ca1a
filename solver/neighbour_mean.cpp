#include "solver/neighbour_mean.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>

#include "tools/common/parallel.h"

namespace igi {
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

// The points of one call in (region, cell) order, in flat arrays that the inner loop reads
// sequentially.
struct SortedPoints {
  std::vector<int> index;          // original index
  std::vector<Eigen::Vector3f> p;  // position
  std::vector<Eigen::Vector3f> n;  // normal
  std::vector<int> photo;
  std::vector<Eigen::Vector3d> value;
  std::unordered_map<CellKey, std::pair<int, int>, CellKeyHash> cells;  // [begin, end)
};

}  // namespace

void NeighbourMean(const std::vector<NeighbourPoint>& points,
                   const std::vector<Eigen::Vector3d>& values, const std::vector<int>& subset,
                   double radius, bool same_photo, int num_threads,
                   std::vector<Eigen::Vector3d>* out) {
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
  SortedPoints s{
      std::vector<int>(n), std::vector<Eigen::Vector3f>(n), std::vector<Eigen::Vector3f>(n),
      std::vector<int>(n), std::vector<Eigen::Vector3d>(n), {}};
  s.cells.reserve(n / 4 + 1);
  for (size_t k = 0; k < n; ++k) {
    const int i = keyed[k].second;
    s.index[k] = i;
    s.p[k] = points[i].position;
    s.n[k] = points[i].normal;
    s.photo[k] = points[i].photo;
    s.value[k] = values[i];
    if (k == 0 || !(keyed[k].first == keyed[k - 1].first)) {
      s.cells[keyed[k].first] = {int(k), int(k)};
    }
    s.cells[keyed[k].first].second = int(k) + 1;
  }
  const float r2 = float(radius * radius);
  ParallelFor(
      0, int64_t(n),
      [&](int64_t k) {
        const CellKey c = keyed[k].first;
        const Eigen::Vector3f& p = s.p[k];
        const Eigen::Vector3f& nk = s.n[k];
        const int photo = s.photo[k];
        Eigen::Vector3d sum = Eigen::Vector3d::Zero();
        int count = 0;
        for (int64_t dx = -1; dx <= 1; ++dx) {
          for (int64_t dy = -1; dy <= 1; ++dy) {
            for (int64_t dz = -1; dz <= 1; ++dz) {
              const auto it = s.cells.find(CellKey{c.region, c.x + dx, c.y + dy, c.z + dz});
              if (it == s.cells.end()) continue;
              for (int j = it->second.first; j < it->second.second; ++j) {
                if ((s.p[j] - p).squaredNorm() > r2 || s.n[j].dot(nk) < 0.9f ||
                    (same_photo && s.photo[j] != photo)) {
                  continue;
                }
                sum += s.value[j];
                ++count;
              }
            }
          }
        }
        (*out)[s.index[k]] = count > 0 ? Eigen::Vector3d(sum / count) : s.value[k];
      },
      num_threads);
}

}  // namespace igi
