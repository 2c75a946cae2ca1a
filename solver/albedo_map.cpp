// TEMPORARY stub (the real module comes from the wt-albedo branch).
#include "solver/albedo_map.h"

#include <cmath>

namespace igi {
RegionAtlas BuildRegionAtlas(const TriangleMesh& mesh, int region, const AtlasOptions& options) {
  RegionAtlas a;
  a.region = region;
  a.width = a.height = 64;
  a.texel_size_m = options.texel_size_m;
  a.corner_uv.resize(mesh.num_triangles());
  if (mesh.has_uvs()) {
    for (size_t t = 0; t < mesh.num_triangles(); ++t) {
      for (int k = 0; k < 3; ++k) a.corner_uv[t][k] = mesh.uvs[mesh.triangles[t][k]];
    }
  }
  return a;
}
void WriteObjWithAtlases(const TriangleMesh&, const std::vector<RegionAtlas>&,
                         const std::filesystem::path&) {}
AlbedoMapBuilder::AlbedoMapBuilder(const RegionAtlas& atlas)
    : atlas_(&atlas), num_(size_t(atlas.width) * atlas.height * 3), den_(num_.size()) {}
void AlbedoMapBuilder::Add(int triangle, double b1, double b2, const Eigen::Vector3d& n,
                           const Eigen::Vector3d& d) {
  const Eigen::Vector2d uv = atlas_->UvAt(triangle, b1, b2);
  const int x = std::clamp(int(uv.x() * atlas_->width), 0, atlas_->width - 1);
  const int y = std::clamp(int((1 - uv.y()) * atlas_->height), 0, atlas_->height - 1);
  for (int c = 0; c < 3; ++c) {
    num_[(size_t(y) * atlas_->width + x) * 3 + c] += n[c];
    den_[(size_t(y) * atlas_->width + x) * 3 + c] += d[c];
  }
}
void AlbedoMapBuilder::Merge(const AlbedoMapBuilder& o) {
  for (size_t i = 0; i < num_.size(); ++i) num_[i] += o.num_[i], den_[i] += o.den_[i];
}
Image AlbedoMapBuilder::Finish(const Eigen::Vector3d& fallback) const {
  Image img(atlas_->width, atlas_->height, 3);
  for (size_t i = 0; i < num_.size(); ++i) {
    img.pixels[i] = den_[i] > 0 ? float(num_[i] / den_[i]) : float(fallback[i % 3]);
  }
  return img;
}
double AlbedoMapBuilder::Coverage() const { return 0; }
double AlbedoPsnr(const Image&, const Image&, double) { return 0; }
}  // namespace igi
