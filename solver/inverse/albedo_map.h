#pragma once
// Per-texel diffuse albedo maps: the solver's per-point albedo estimates, accumulated
// into the texels of a region's atlas (solver/inverse/uv_charts.h) and turned into a linear RGB
// image.
//
// Texel convention = the renderer's lookup (solver/render/render.cpp SampleTexture): a UV (u right,
// v up) sits at x = u·W − 0.5, y = (1 − v)·H − 0.5 in texel units (row 0 = top), and reads the four
// nearest texels bilinearly, indices clamped to the image. Add() splats with exactly those
// weights (the adjoint of the lookup), so a texel's value is the weighted ratio of the samples
// whose lookups would read it.

#include <Eigen/Core>
#include <functional>
#include <memory>
#include <vector>

#include "solver/inverse/uv_charts.h"
#include "tools/common/image.h"

namespace igi::solver {

class AlbedoMapBuilder {
 public:
  // A texel is estimated directly when its summed bilinear weight (≈ samples that read it) is at
  // least this and its denominator is positive; the others are filled from their neighbours.
  static constexpr double kDefaultMinTexelWeight = 0.5;

  // Keeps a reference to `atlas`, which must outlive the builder. Storage is allocated in tiles
  // of 16×16 texels on first touch, so sparse builders (one per thread) stay small.
  explicit AlbedoMapBuilder(const RegionAtlas& atlas,
                            double min_texel_weight = kDefaultMinTexelWeight);
  ~AlbedoMapBuilder();
  AlbedoMapBuilder(AlbedoMapBuilder&&) noexcept;
  AlbedoMapBuilder& operator=(AlbedoMapBuilder&&) noexcept;

  // One sample at a surface point (barycentrics b1, b2 of corners 1, 2 of `triangle`, which must
  // be the atlas region's): albedo = numerator / denominator per channel (the solver adds
  // numerator = w·π·(L_observed − specular), denominator = w·E, E the irradiance). Splat
  // bilinearly into the 4 nearest texels. Samples with a non-finite value are ignored. Not
  // thread-safe: use one builder per thread and Merge().
  void Add(int triangle, double b1, double b2, const Eigen::Vector3d& numerator,
           const Eigen::Vector3d& denominator);
  // Every texel whose centre lies inside one of the atlas region's triangles and that is not yet
  // estimated directly in every channel: value(triangle, b1, b2) at that centre, as one sample
  // of weight 1 (numerator value, denominator 1). For a quantity known everywhere on the
  // surface, such as the fit's per-patch albedos, in place of the push-pull fill; non-finite
  // values are left out.
  void FillTexelCentres(
      const std::function<Eigen::Vector3d(int triangle, double b1, double b2)>& value);
  // Adds another builder's sums (same atlas size; throws igi::Error otherwise).
  void Merge(const AlbedoMapBuilder& other);

  // The map: linear RGB Image (width×height of the atlas, row 0 = top = v 1), each texel
  // numerator/denominator where the weight is enough; the other texels (holes, gutters, the
  // space between charts) are filled by push-pull over the whole atlas (per channel: texels keep
  // their direct value, holes get the weighted average of ever coarser neighbourhoods,
  // interpolated back bilinearly). A channel that nothing was added to is `fallback` everywhere.
  Image Finish(const Eigen::Vector3d& fallback) const;

  // Fraction of the region's texels (centres inside one of its triangles) that are estimated
  // directly (see kDefaultMinTexelWeight); 0 when the region covers no texel centre.
  double Coverage() const;

  // Which texels are estimated directly (1) rather than filled (0): a one-channel image of the
  // atlas's size, row 0 = top like Finish()'s. Texels seen by no photo are 0.
  Image DirectMask() const;

  int64_t num_samples() const { return num_samples_; }  // samples added (incl. merged)

 private:
  struct Tile;
  static constexpr int kTile = 16;
  Tile* TileAt(int x, int y);  // allocates
  const Tile* TileAt(int x, int y) const;
  bool Direct(int x, int y, int channel) const;
  // Calls f for every texel centre inside one of the atlas region's triangles, with the
  // barycentrics of that centre (a texel on an edge shared by two triangles: for each).
  void ForEachTexelCentre(
      const std::function<void(int triangle, int x, int y, double b1, double b2)>& f) const;

  const RegionAtlas* atlas_;
  double min_texel_weight_;
  int tiles_x_ = 0, tiles_y_ = 0;
  std::vector<std::unique_ptr<Tile>> tiles_;
  int64_t num_samples_ = 0;
};

// PSNR in dB, 10·log10(peak² / MSE), over all texels and channels (+infinity when equal). Throws
// igi::Error when the sizes or channel counts differ, the images are empty, or peak <= 0.
double AlbedoPsnr(const Image& estimate, const Image& truth, double peak);

// An albedo map against a true texture on the same UVs, possibly of another size: the estimate
// is looked up bilinearly (the renderer's convention) at each true texel's centre. With `seen`
// (AlbedoMapBuilder::DirectMask()), only the true texels whose lookup reads seen texels alone
// (of those with a non-zero bilinear weight) are compared.
struct AlbedoComparison {
  double psnr_db = 0;   // 10·log10(peak² / MSE) over the compared texels and channels
  double rms = 0;       // √MSE
  double compared = 0;  // fraction of the true texels compared
};
// Throws igi::Error when an image is empty, `seen` differs in size from `estimate`, peak <= 0,
// or no texel is compared.
AlbedoComparison CompareAlbedoMaps(const Image& estimate, const Image* seen, const Image& truth,
                                   double peak);

// The map's mean RGB over the texels `seen` marks (> 0.5; one channel, the map's size); NaN when
// none is. A 1-channel map is grey.
Eigen::Vector3d SeenTexelMean(const Image& map, const Image& seen);

// The mean RGB of `texture` (any resolution, on the same UV square as `seen`) over the texels of
// `seen` marked seen: each texture texel counts where its centre falls, so at equal resolution it
// is SeenTexelMean(texture, seen). The truth SeenTexelMean of an estimated map is compared with.
// NaN when no texel falls in a seen one.
Eigen::Vector3d TextureMeanOverSeenTexels(const Image& texture, const Image& seen);

// The albedo detail two maps of one region share, finer than the gathered irradiance's errors.
// `a` and `b` are estimated from disjoint halves of the photos (independent noise, the same
// texture); `both` lists the texels (y·width + x) both estimate directly. Each map less its local
// mean over the shared texels of the (2k+1)² window, k = kTexelDetailHalfWidth: the irradiance's
// errors are patch-sized and cancel there, a texture finer than the window does not. The
// detail's variance is the two deviations' covariance summed over the channels, relative to the
// channels' summed mean² (a texture multiplies every channel alike, while a lobe's error is grey
// and would dominate a dark channel's relative variance).
struct TexelDetail {
  double variation = NAN;  // sqrt(max(0, covariance) / mean²): the relative standard deviation
  // The covariance over its standard error, tiles of kTexelDetailTile² texels taken as the
  // independent samples (the local means correlate neighbours): a photo's noise with a heavy
  // tail (a few paths per pixel) makes a sizeable covariance from few texels by chance, a
  // texture makes it from many.
  double z = NAN;
};
inline constexpr int kTexelDetailHalfWidth = 3;  // 7 × 7 texels
inline constexpr int kTexelDetailTile = 16;
// NaN (both fields) when fewer than 64 texels are shared or a channel's mean is not positive.
TexelDetail SharedTexelDetail(const Image& a, const Image& b, const std::vector<int>& both);

}  // namespace igi::solver
