#pragma once
// TEMPORARY stub (the real module comes from the wt-albedo branch).
#include <Eigen/Core>
#include <array>
#include <filesystem>
#include <vector>

#include "recon/mesh.h"

namespace igi {
struct AtlasOptions {
  double texel_size_m = 0.01;
  int gutter_texels = 2;
  int max_size = 4096;
  double chart_angle_deg = 30;
  void Validate() const {}
};
struct RegionAtlas {
  int region = -1;
  int width = 0, height = 0;
  double texel_size_m = 0;
  bool generated = false;
  std::vector<std::array<Eigen::Vector2f, 3>> corner_uv;
  Eigen::Vector2d UvAt(int triangle, double b1, double b2) const {
    const auto& c = corner_uv[triangle];
    return ((1 - b1 - b2) * c[0] + b1 * c[1] + b2 * c[2]).cast<double>();
  }
};
RegionAtlas BuildRegionAtlas(const TriangleMesh& mesh, int region, const AtlasOptions& options);
void WriteObjWithAtlases(const TriangleMesh& mesh, const std::vector<RegionAtlas>& atlases,
                         const std::filesystem::path& path);
}  // namespace igi
