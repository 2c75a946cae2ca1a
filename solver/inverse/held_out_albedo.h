#pragma once
// Per-texel diffuse albedo seen by the OTHER photos (Yu et al. 1999: a highlight's diffuse part
// is known from views where the same point shows no highlight). Observations off the highlights
// are accumulated per texel of a region's atlas and per photo; At(photo, point) reads the texels
// around a point with that photo's own sums taken out, so a highlight sample's albedo never comes
// from the highlight's own pixels (which would absorb part of the lobe into the albedo).
//
// Texel convention and splat weights are AlbedoMapBuilder's (solver/inverse/albedo_map.h): a sample
// adds to the 4 texels its bilinear lookup would read.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <unordered_map>

#include "solver/inverse/uv_charts.h"

namespace igi::solver {

class HeldOutAlbedo {
 public:
  // A texel counts when its held-out summed bilinear weight is at least this (≈ samples).
  static constexpr double kMinTexelWeight = 0.5;

  // Keeps a reference to `atlas`, which must outlive this.
  explicit HeldOutAlbedo(const RegionAtlas& atlas) : atlas_(&atlas) {}

  // One off-highlight sample of `photo` at barycentrics (b1, b2) of `triangle` (the atlas
  // region's): albedo = numerator / denominator per channel (e.g. π(L − specular) and E).
  // Non-finite samples are ignored. Not thread-safe.
  void Add(int photo, int triangle, double b1, double b2, const Eigen::Vector3d& numerator,
           const Eigen::Vector3d& denominator);

  // The albedo at the point from every photo but `photo`: the texels' held-out ratios,
  // interpolated bilinearly over the texels that count; NaN (all channels) when those carry
  // less than half of the bilinear weight.
  Eigen::Vector3d At(int photo, int triangle, double b1, double b2) const;

 private:
  using Sums = std::array<double, 7>;  // numerator (3), denominator (3), weight
  struct Splat {
    std::array<int64_t, 4> texel;
    std::array<double, 4> weight;
  };
  Splat SplatOf(int triangle, double b1, double b2) const;

  const RegionAtlas* atlas_;
  std::unordered_map<int64_t, Sums> total_;      // per texel
  std::unordered_map<int64_t, Sums> per_photo_;  // per (photo, texel)
};

}  // namespace igi::solver
