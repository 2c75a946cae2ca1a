#pragma once
// TEMPORARY stub (the real module comes from the wt-albedo branch).
#include <Eigen/Core>

#include "solver/uv_charts.h"
#include "tools/common/image.h"

namespace igi {
class AlbedoMapBuilder {
 public:
  explicit AlbedoMapBuilder(const RegionAtlas& atlas);
  void Add(int triangle, double b1, double b2, const Eigen::Vector3d& numerator,
           const Eigen::Vector3d& denominator);
  void Merge(const AlbedoMapBuilder& other);
  Image Finish(const Eigen::Vector3d& fallback) const;
  double Coverage() const;

 private:
  const RegionAtlas* atlas_;
  std::vector<double> num_, den_;
};
double AlbedoPsnr(const Image& estimate, const Image& truth, double peak);
}  // namespace igi
