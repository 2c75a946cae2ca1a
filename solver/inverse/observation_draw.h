#pragma once
// Internal to igi_solver: drawing the photos' observations to a budget as they are collected.
//
// A photo of 24 MP at pixel stride 2 offers 6 M observations and a room of 30 such photos 180 M;
// each stored observation costs kilobytes with its gathered light. The solver therefore decides,
// before any photo is read, with which probability each class of pixel is kept, and keeps a pixel
// when a hash of its photo and pixel falls under its class's probability:
//  - a census traces the centre rays of a coarse grid of every photo's pixels (geometry only) and
//    estimates, per region, how many pixels at the stride see it near a possible highlight
//    (tanθh < 0.6 toward a light of the photo's lighting; those carry a lobe's ρs and α) and how
//    many elsewhere;
//  - every region's other pixels are kept up to max_fit_samples and its highlight candidates up
//    to SolveOptions::max_highlight_samples (what its fit needs), together within kNeedsShare of
//    the budget (the highlight candidates give way first), and the rest of the budget is shared
//    evenly: one probability for every other pixel, found by bisection. The even share is what
//    covers every surface with observations, whose patches send the gathered light; where the
//    needs took the whole budget (4 glossy regions' highlight candidates in photos of 24 MP),
//    many of a textured floor's patches had no observation and were modelled at the floor's mean
//    albedo, and the light they sent a red wall beside them was 15 % too high.
// The hash is a property of each pixel alone, so the draw is reproducible and a change to one
// photo (its mask, its pose) does not redraw another's pixels; the fit's own subset
// (SolverState::SelectFitSamples) is drawn with the same hash, nested inside this draw.
// When every photo's pixels at the stride fit the budget, every probability is 1 and nothing is
// traced for the census: small captures are collected exactly as without a budget.
//
// Blocks: a class kept with probability p keeps one pixel in about 1/p, spaced 1/√p stride cells
// apart. Rather than one pixel there, each such observation is the mean of a block of b × b
// stride cells (b = ⌊1/√p⌋, at most max_block), every pixel of the block counted, and blocks are
// kept with probability p·b²: as many observations, at the same spacing, each averaging b²·stride²
// pixels of the photo's noise instead of one (what a user's downscaled photos would give, but
// only where the draw thins, and with every block checked to lie on one smooth surface). A block
// that does not (an edge, a mask, a clipped pixel within it) is replaced by its centre cell's
// pixel alone.

#include <Eigen/Core>
#include <algorithm>
#include <cstdint>
#include <vector>

#include "recon/scene.h"
#include "solver/render/ray_scene.h"

namespace igi::solver {

// The key of pixel (x, y) of photo `photo` for the hashed draws (sampling.h InHashedSubset); an
// observation's key is that of its top-left pixel (Observation::x, y).
inline uint64_t PixelKey(int photo, int x, int y) {
  return (uint64_t(photo) << 42) ^ (uint64_t(y) << 21) ^ uint64_t(x);
}

// Whether a surface point (world position, unit view toward the camera, unit shading normal) is
// near a possible highlight of a light of `lighting`: tanθh < 0.6 toward some non-ambient light.
bool NearHighlight(const render::RayScene& lighting, const Eigen::Vector3d& position,
                   const Eigen::Vector3d& view, const Eigen::Vector3d& normal);

// Per region: the estimated number of pixels at the stride that see it, near a highlight and not.
struct RegionPixelCensus {
  double near = 0, rest = 0;
};

// The keep probabilities per region and class, and what they were drawn from.
struct ObservationDraw {
  std::vector<double> p_near, p_rest;       // per region, in [0, 1]
  std::vector<int> block_near, block_rest;  // per region: block side in stride cells (>= 1)
  // Per region: whether its highlight candidates are a class of their own (a fitted lobe).
  std::vector<char> lobe_class;
  double budget = 0;     // observations allowed (infinity: no budget)
  double available = 0;  // pixels at the stride that see a reflective surface (census estimate)
  double expected = 0;   // observations the probabilities keep (census estimate)
  bool census = false;   // false: every pixel fits the budget and every probability is 1
  // The probability of a pixel of `region` (near a highlight or not): the observations' density
  // per stride cell.
  double Probability(int region, bool near) const {
    return near && lobe_class[region] ? p_near[region] : p_rest[region];
  }
  // The side, in stride cells, of the blocks of `region`'s class (1: single pixels).
  int Block(int region, bool near) const {
    return near && lobe_class[region] ? block_near[region] : block_rest[region];
  }
  // The probability with which a block of the class is kept (its key's hash under it).
  double Threshold(int region, bool near) const {
    const double b = Block(region, near);
    return std::min(1.0, Probability(region, near) * b * b);
  }
  // Whether the stride cell (pixel_stride `stride`) of `photo` whose sampled pixel (x, y) sees
  // `region` yields an observation: for single pixels, whether that pixel is drawn; for blocks,
  // whether the cell is its block's centre and the block is drawn. *x0, *y0, *size: the
  // observation's top-left pixel and side in pixels ((x, y) and 1 for single pixels).
  bool Draws(int photo, int x, int y, int stride, int region, bool near, int* x0, int* y0,
             int* size) const;
};

// The largest share of the budget the regions' needs (highlight candidates and fit samples) take;
// the rest is drawn evenly.
inline constexpr double kNeedsShare = 0.5;

struct ObservationDrawOptions {
  // Every pixel_stride-th pixel in x and y is a candidate (SolveOptions::pixel_stride).
  int pixel_stride = 2;
  double budget = 0;  // observations; 0 or infinity: no budget
  // Each region's needs, kept first: its highlight candidates up to max_highlight_samples and
  // its other pixels up to max_fit_samples (SolveOptions).
  int max_highlight_samples = 100000;
  int max_fit_samples = 6000;
  // Blocks (above): at most this many stride cells on a side (1: single pixels only).
  int max_block = 8;
  // Census grid: at most this many centre rays per photo.
  int census_rays_per_photo = 16384;
  // Worker threads; 0 = the process default.
  int num_threads = 0;
};

// Pixels of every photo at the stride (the observations there are at most).
double PixelsAtStride(const recon::Scene& scene, int pixel_stride);

// The census (above) of every photo; `lighting_scenes` per lighting (null: unused), `lobe_class`
// per region.
std::vector<RegionPixelCensus> CensusPixels(
    const recon::Scene& scene, const std::vector<const render::RayScene*>& lighting_scenes,
    const std::vector<char>& lobe_class, const ObservationDrawOptions& options);

// The probabilities (above) for `census`: each region's needs first (its highlight candidates up
// to max_highlight_samples, its other pixels up to max_fit_samples; within kNeedsShare of the
// budget, above), then one probability for every other pixel; each class's block side from its
// probability.
ObservationDraw PlanObservationDraw(const std::vector<RegionPixelCensus>& census,
                                    const std::vector<char>& lobe_class,
                                    const ObservationDrawOptions& options);

}  // namespace igi::solver
