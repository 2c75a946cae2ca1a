#include "solver/diagnose/texture_evidence.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <unordered_map>

namespace igi::diagnose {
namespace {

using CellKey = int64_t;

CellKey KeyOf(int ix, int iy, int iz) {
  constexpr int64_t kOffset = int64_t(1) << 20;  // cells within ±2^20 of the origin
  return ((int64_t(ix) + kOffset) << 42) | ((int64_t(iy) + kOffset) << 21) |
         (int64_t(iz) + kOffset);
}

struct CellSum {
  Eigen::Vector3i cell = Eigen::Vector3i::Zero();  // integer cell coordinates
  double sum = 0;
  int n = 0;
  double Mean() const { return sum / n; }
};

// The cells' ratio sums of one photo set (photo parity `parity`) for region `region`.
struct CellGrid {
  std::unordered_map<CellKey, CellSum> cells;
};

double Ratio(const PixelRecord& r) {
  const double sim = r.sim.sum(), rec = r.recorded.sum();
  if (!(sim > 1e-9) || !std::isfinite(rec)) return NAN;
  return std::clamp(rec / sim, 0.0, 4.0);
}

// The mean of the neighbours (26-neighbourhood) that have at least `min_n` records, or NaN when
// fewer than 3 do.
double NeighbourMean(const CellGrid& g, const Eigen::Vector3i& c, int min_n) {
  double sum = 0;
  int count = 0;
  for (int dz = -1; dz <= 1; ++dz) {
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        if (dx == 0 && dy == 0 && dz == 0) continue;
        const auto it = g.cells.find(KeyOf(c.x() + dx, c.y() + dy, c.z() + dz));
        if (it == g.cells.end() || it->second.n < min_n) continue;
        sum += it->second.Mean();
        ++count;
      }
    }
  }
  return count >= 3 ? sum / count : NAN;
}

// Ranks 0..n-1 (ties share their mean rank).
std::vector<double> Ranks(const std::vector<double>& v) {
  std::vector<size_t> order(v.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return v[a] < v[b]; });
  std::vector<double> rank(v.size());
  for (size_t i = 0; i < order.size();) {
    size_t j = i;
    while (j + 1 < order.size() && v[order[j + 1]] == v[order[i]]) ++j;
    for (size_t k = i; k <= j; ++k) rank[order[k]] = 0.5 * double(i + j);
    i = j + 1;
  }
  return rank;
}

// Spearman's rank correlation of a and b (0 when either is constant).
double RankCorrelation(const std::vector<double>& a, const std::vector<double>& b) {
  const std::vector<double> ra = Ranks(a), rb = Ranks(b);
  const double mean = 0.5 * double(a.size() - 1);
  double ab = 0, aa = 0, bb = 0;
  for (size_t i = 0; i < ra.size(); ++i) {
    ab += (ra[i] - mean) * (rb[i] - mean);
    aa += (ra[i] - mean) * (ra[i] - mean);
    bb += (rb[i] - mean) * (rb[i] - mean);
  }
  return aa > 0 && bb > 0 ? ab / std::sqrt(aa * bb) : 0.0;
}

// The median over the cells either photo set holds of the smaller set's record count.
double MedianRecords(const CellGrid& a, const CellGrid& b) {
  std::vector<int> n;
  auto count = [](const CellGrid& g, CellKey key) {
    const auto it = g.cells.find(key);
    return it == g.cells.end() ? 0 : it->second.n;
  };
  for (const auto& [key, c] : a.cells) n.push_back(std::min(c.n, count(b, key)));
  for (const auto& [key, c] : b.cells) {
    if (!a.cells.count(key)) n.push_back(0);
  }
  if (n.empty()) return 0;
  std::nth_element(n.begin(), n.begin() + n.size() / 2, n.end());
  return n[n.size() / 2];
}

TextureEvidence Evaluate(const std::string& name, const CellGrid& a, const CellGrid& b,
                         const TextureEvidenceOptions& o) {
  TextureEvidence e;
  e.region = name;
  std::vector<double> products, high_a, high_b;
  double mean_sum = 0;
  int agree = 0;
  for (const auto& [key, ca] : a.cells) {
    const auto it = b.cells.find(key);
    if (ca.n < o.min_records_per_cell || it == b.cells.end() ||
        it->second.n < o.min_records_per_cell) {
      continue;
    }
    const Eigen::Vector3i& c = ca.cell;
    const double na = NeighbourMean(a, c, o.min_records_per_cell);
    const double nb = NeighbourMean(b, c, o.min_records_per_cell);
    if (!std::isfinite(na) || !std::isfinite(nb)) continue;
    const double ha = ca.Mean() - na, hb = it->second.Mean() - nb;
    products.push_back(ha * hb);
    high_a.push_back(ha);
    high_b.push_back(hb);
    agree += ha * hb > 0;
    mean_sum += 0.5 * (ca.Mean() + it->second.Mean());
  }
  e.cells = int(products.size());
  if (e.cells == 0) return e;
  e.agreement = double(agree) / e.cells;
  e.sign_z = (e.agreement - 0.5) * 2 * std::sqrt(double(e.cells));
  e.rank_correlation = RankCorrelation(high_a, high_b);
  e.z = e.rank_correlation * std::sqrt(double(e.cells - 1));
  // Trimmed: the largest tenth of the products (sharp edges: a shadow, a highlight) left out.
  std::sort(products.begin(), products.end());
  const size_t keep = products.size() - products.size() / 10;
  double sum = 0;
  for (size_t i = 0; i < keep; ++i) sum += products[i];
  const double mean_ratio = mean_sum / e.cells;
  e.amplitude = mean_ratio > 0 ? std::sqrt(std::max(0.0, sum / double(keep))) / mean_ratio : 0;
  e.textured = e.cells >= o.min_cells && e.agreement >= o.min_agreement && e.z >= o.min_z &&
               e.amplitude >= o.min_amplitude;
  return e;
}

}  // namespace

std::vector<TextureEvidence> FindTexturedRegions(const recon::Scene& model,
                                                 const std::vector<PixelRecord>& records,
                                                 const std::vector<bool>& solved,
                                                 const TextureEvidenceOptions& options) {
  const int regions = int(model.materials.size());
  std::vector<std::optional<TextureEvidence>> best{size_t(regions)};
  const std::vector<double> scales =
      options.scales.empty() ? std::vector<double>{1.0} : options.scales;
  std::vector<bool> dense(size_t(regions), false);  // the scales so far had records enough
  for (const double scale : scales) {
    const double cell_m = options.cell_m * scale;
    std::vector<CellGrid> grids(2 * size_t(regions));  // [region * 2 + photo parity]
    for (const PixelRecord& r : records) {
      if (r.held_out || r.outlier || r.region < 0 || r.region >= regions) continue;
      if (r.region >= int(solved.size()) || !solved[r.region]) continue;
      const double q = Ratio(r);
      if (!std::isfinite(q)) continue;
      const Eigen::Vector3i c = (r.position.cast<double>() / cell_m).array().floor().cast<int>();
      CellGrid& g = grids[size_t(r.region) * 2 + (r.photo & 1)];
      const CellKey key = KeyOf(c.x(), c.y(), c.z());
      CellSum& s = g.cells[key];
      s.cell = c;
      s.sum += q;
      ++s.n;
    }
    for (int r = 0; r < regions; ++r) {
      const CellGrid& a = grids[size_t(r) * 2];
      const CellGrid& b = grids[size_t(r) * 2 + 1];
      if (a.cells.empty() || b.cells.empty() || dense[size_t(r)]) continue;
      dense[size_t(r)] = MedianRecords(a, b) >= options.dense_records;
      TextureEvidence e = Evaluate(model.materials[r].name, a, b, options);
      e.cell_m = cell_m;
      std::optional<TextureEvidence>& kept = best[size_t(r)];
      if (!kept || (!kept->textured && (e.textured || e.z > kept->z))) kept = e;
    }
  }
  std::vector<TextureEvidence> out;
  for (const std::optional<TextureEvidence>& e : best) {
    if (e) out.push_back(*e);
  }
  return out;
}

}  // namespace igi::diagnose
