#pragma once
// The bilinear footprint of a surface point in its region's albedo atlas: the four texels around
// the point's UV (wrapped as the renderer wraps it, v up, texel centres at half-integers) and
// their weights. Shared by the albedo map builder and the held-out albedo.

#include <algorithm>
#include <cmath>

#include "solver/inverse/uv_charts.h"

namespace igi::solver {

struct TexelSplat {
  int x[4] = {0, 0, 0, 0}, y[4] = {0, 0, 0, 0};  // clamped texel columns and rows
  double weight[4] = {0, 0, 0, 0};               // bilinear weights, summing to 1
};

inline TexelSplat BilinearTexelSplat(const RegionAtlas& atlas, int triangle, double b1, double b2) {
  Eigen::Vector2d uv = atlas.UvAt(triangle, b1, b2);
  for (int k = 0; k < 2; ++k) {  // wrapped as the renderer does
    if (uv[k] < 0.0 || uv[k] > 1.0) uv[k] -= std::floor(uv[k]);
  }
  const int width = atlas.width, height = atlas.height;
  const double x = uv.x() * width - 0.5, y = (1.0 - uv.y()) * height - 0.5;
  const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
  const double fx = x - x0, fy = y - y0;
  TexelSplat s;
  for (int k = 0; k < 4; ++k) {
    const int dx = k & 1, dy = k >> 1;
    s.x[k] = std::clamp(x0 + dx, 0, width - 1);
    s.y[k] = std::clamp(y0 + dy, 0, height - 1);
    s.weight[k] = (dx ? fx : 1 - fx) * (dy ? fy : 1 - fy);
  }
  return s;
}

}  // namespace igi::solver
