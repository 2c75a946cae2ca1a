#include "solver/inverse/patches.h"

#include <algorithm>
#include <cmath>

namespace igi::solver {
namespace {

// Sub-triangles of a k-grid, numbered row by row (i = floor(b1·k)): row i holds k−i "up" cells
// and k−i−1 "down" cells, interleaved (up j → 2j, down j → 2j+1); rows before i hold i(2k−i).
int CellIndex(int k, int i, int j, bool down) { return i * (2 * k - i) + 2 * j + (down ? 1 : 0); }

}  // namespace

int PatchSet::PatchOf(int triangle, double b1, double b2) const {
  const int k = triangle_k[triangle];
  const double x = std::clamp(b1, 0.0, 1.0) * k, y = std::clamp(b2, 0.0, 1.0) * k;
  int i = std::min(static_cast<int>(x), k - 1);
  int j = std::min(static_cast<int>(y), k - 1 - i);
  j = std::max(j, 0);
  const double fi = x - i, fj = y - j;
  const bool down = fi + fj > 1.0 && i + j <= k - 2;
  return triangle_first[triangle] + CellIndex(k, i, j, down);
}

PatchSet BuildPatches(const recon::TriangleMesh& mesh, double patch_size_m) {
  PatchSet set;
  const int n = static_cast<int>(mesh.num_triangles());
  set.triangle_first.resize(n + 1);
  set.triangle_k.resize(n);
  int total = 0;
  for (int t = 0; t < n; ++t) {
    const Eigen::Vector3i& tri = mesh.triangles[t];
    double edge = 0;
    for (int e = 0; e < 3; ++e) {
      edge = std::max(edge, double((mesh.positions[tri[e]] - mesh.positions[tri[(e + 1) % 3]])
                                       .norm()));
    }
    const int k = std::clamp(static_cast<int>(std::ceil(edge / patch_size_m)), 1, 64);
    set.triangle_k[t] = k;
    set.triangle_first[t] = total;
    total += k * k;
  }
  set.triangle_first[n] = total;
  set.patch_triangle.resize(total);
  set.patch_region.resize(total);
  set.center.resize(total);
  set.normal.resize(total);
  set.center_bary.resize(total);
  set.area.resize(total);
  for (int t = 0; t < n; ++t) {
    const Eigen::Vector3i& tri = mesh.triangles[t];
    const int k = set.triangle_k[t];
    const float area = static_cast<float>(mesh.TriangleArea(t) / (double(k) * k));
    const Eigen::Vector3f face = mesh.FaceNormal(t);
    for (int i = 0; i < k; ++i) {
      for (int j = 0; j < k - i; ++j) {
        for (int d = 0; d < 2; ++d) {
          if (d == 1 && i + j > k - 2) continue;
          const float off = d == 0 ? 1.0f / 3 : 2.0f / 3;
          const float b1 = (i + off) / k, b2 = (j + off) / k, b0 = 1 - b1 - b2;
          const int p = set.triangle_first[t] + CellIndex(k, i, j, d == 1);
          set.patch_triangle[p] = t;
          set.patch_region[p] = mesh.triangle_region[t];
          set.center[p] = b0 * mesh.positions[tri[0]] + b1 * mesh.positions[tri[1]] +
                          b2 * mesh.positions[tri[2]];
          Eigen::Vector3f nrm = (b0 * mesh.normals[tri[0]] + b1 * mesh.normals[tri[1]] +
                                 b2 * mesh.normals[tri[2]]);
          if (!(nrm.squaredNorm() > 0) || nrm.dot(face) <= 0) nrm = face;
          set.normal[p] = nrm.normalized();
          set.center_bary[p] = Eigen::Vector2f(b1, b2);
          set.area[p] = area;
        }
      }
    }
  }
  return set;
}

}  // namespace igi::solver
