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
//  - every region's highlight candidates are kept up to SolveOptions::max_highlight_samples and
//    its other pixels up to max_fit_samples (what its fit needs), and the rest of the budget is
//    shared evenly: one probability for every other pixel, found by bisection.
// The hash is a property of each pixel alone, so the draw is reproducible and a change to one
// photo (its mask, its pose) does not redraw another's pixels; the fit's own subset
// (SolverState::SelectFitSamples) is drawn with the same hash, nested inside this draw.
// When every photo's pixels at the stride fit the budget, every probability is 1 and nothing is
// traced for the census: small captures are collected exactly as without a budget.

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "recon/scene.h"
#include "solver/render_internal.h"

namespace igi {

// The key of pixel (x, y) of photo `photo` for the hashed draws (sampling.h InHashedSubset).
inline uint64_t PixelKey(int photo, int x, int y) {
  return (uint64_t(photo) << 42) ^ (uint64_t(y) << 21) ^ uint64_t(x);
}

// Whether a surface point (world position, unit view toward the camera, unit shading normal) is
// near a possible highlight of a light of `lighting`: tanθh < 0.6 toward some non-ambient light.
bool NearHighlight(const Renderer::Impl& lighting, const Eigen::Vector3d& position,
                   const Eigen::Vector3d& view, const Eigen::Vector3d& normal);

// Per region: the estimated number of pixels at the stride that see it, near a highlight and not.
struct RegionPixelCensus {
  double near = 0, rest = 0;
};

// The keep probabilities per region and class, and what they were drawn from.
struct ObservationDraw {
  std::vector<double> p_near, p_rest;  // per region, in [0, 1]
  // Per region: whether its highlight candidates are a class of their own (a fitted lobe).
  std::vector<char> lobe_class;
  double budget = 0;     // observations allowed (infinity: no budget)
  double available = 0;  // pixels at the stride that see a reflective surface (census estimate)
  double expected = 0;   // observations the probabilities keep (census estimate)
  bool census = false;   // false: every pixel fits the budget and every probability is 1
  // The probability of a pixel of `region` (near a highlight or not).
  double Probability(int region, bool near) const {
    return near && lobe_class[region] ? p_near[region] : p_rest[region];
  }
  bool Keeps(int photo, int x, int y, int region, bool near) const;
};

struct ObservationDrawOptions {
  int pixel_stride = 2;
  double budget = 0;  // observations; 0 or infinity: no budget
  int max_highlight_samples = 100000;
  int max_fit_samples = 6000;
  // Census grid: at most this many centre rays per photo.
  int census_rays_per_photo = 16384;
  int num_threads = 0;
};

// Pixels of every photo at the stride (the observations there are at most).
double PixelsAtStride(const Scene& scene, int pixel_stride);

// The census (above) of every photo; `lighting_scenes` per lighting (null: unused), `lobe_class`
// per region.
std::vector<RegionPixelCensus> CensusPixels(
    const Scene& scene, const std::vector<const Renderer::Impl*>& lighting_scenes,
    const std::vector<char>& lobe_class, const ObservationDrawOptions& options);

// The probabilities (above) for `census`: each region's needs first (its highlight candidates up
// to max_highlight_samples, its other pixels up to max_fit_samples; scaled down together when
// they alone exceed the budget), then one probability for every other pixel.
ObservationDraw PlanObservationDraw(const std::vector<RegionPixelCensus>& census,
                                    const std::vector<char>& lobe_class,
                                    const ObservationDrawOptions& options);

}  // namespace igi
