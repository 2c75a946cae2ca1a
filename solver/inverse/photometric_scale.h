#pragma once
// Internal to igi_solver: the photos' absolute photometric scale from a reference of known
// reflectance (SolveOptions::photo_scale = PhotoScaleMode::kSolve).
//
// Radiance maps assembled from brackets through a recovered response are known only up to a
// constant factor k (Debevec–Malik's g carries a free additive constant), while the lights are
// given in absolute units. Left alone, k goes into every albedo and weakens the interreflections
// the solver computes. The reference is what a photographer puts in the scene for this (a grey
// card, a painted wall whose reflectance was measured): a region whose material is given in
// full and diffuse (Lambertian, or ρs = 0).
//
// With the paper's image-based gathering the light arriving at a point from the other surfaces
// comes from the photos, in the photos' units, and only the direct light is absolute. At a
// reference observation the photo therefore reads
//     P = k·ρd/π·E_direct + ρd/π·G        (G: the gathered indirect irradiance, photo units)
// which is linear in k: k = Σ(P − ρd/π·G)/Σ(ρd/π·E_direct) over every reference observation and
// channel (a ratio of sums, which a noisy albedo lookup on a textured reference does not bias as
// it does least squares; surface patches whose own ratio is beyond 4 robust standard deviations
// of the others' are left out, then it is solved again: RobustPhotoScale). The estimate is taken
// after the paper's stage has converged, so that the patches no photo sees radiate with their
// region's fitted albedo (which follows the photos' units) rather than a placeholder; the photos
// are divided by k and the stage is run again, until k changes by less than 0.1 %. What stays
// outside the photos' units is the light from regions no photo sees at all (their albedo is a
// placeholder): the estimate is exact only as far as the reference's light comes from the lamps and
// from seen surfaces.

#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

namespace igi::solver {

struct SolverState;

struct PhotoScaleEstimate {
  double scale = 1;  // k: photo value = k × radiance in the scene's units (all photos)
  double sigma = 0;  // its standard error (from the residual scatter)
  Eigen::Vector3d rgb = Eigen::Vector3d::Ones();  // k fitted per channel (a colour cast check)
  std::vector<std::string> reference_regions;     // the regions of known reflectance used
  int samples = 0;          // reference observations × channels in the final fit
  int rejected = 0;         // left out as outliers
  int rounds = 0;           // estimate-rescale rounds
  double direct_share = 0;  // mean share of the reference's light that arrives directly
};

// One reference sample: photo value P = k·a + b for one channel of one observation (a: the
// direct light's part ρd/π·E_direct, b: the gathered part ρd/π·G), on the surface patch `group`
// (0-based).
struct PhotoScaleSample {
  double p = 0, a = 0, b = 0;
  int group = 0;
};

// k = Σ(P − b)/Σa over the samples, with the patches (groups of at least 8 observations' samples)
// whose own ratio is beyond 4 robust standard deviations of the others' left out; its standard
// error from the patches' residual sums. `rejected`: the samples left out.
std::pair<double, double> RobustPhotoScale(const std::vector<PhotoScaleSample>& samples,
                                           int* rejected);

// The reference regions of `state` (observed, reflectance given in full, diffuse). Throws
// InputError naming the scene file when there is none.
std::vector<std::string> PhotoScaleReferenceRegions(const SolverState& state);

// The paper's stage (SolverState::RunStage1) with the photos' scale k solved as above: every
// photo and observation ends divided by k. Throws InputError when there is no reference or the
// direct light on it is too weak to measure k.
PhotoScaleEstimate RunStage1WithPhotoScale(SolverState* state);

}  // namespace igi::solver
