#pragma once
// The samples igi-diagnose studies: for every valid residual pixel of every photo, what the
// photo recorded, what the model predicts, and where the pixel lies in each frame where a kind
// of physics shows itself (image position, surface, region, light directions).

#include <Eigen/Core>
#include <cmath>
#include <vector>

#include "recon/scene.h"
#include "solver/diagnose/diagnose_options.h"
#include "solver/inverse/photo_model.h"
#include "tools/common/image.h"

namespace igi::diagnose {

// One light sample at a record's surface point: direction to the light and the irradiance it
// brings (value·cos/pdf, divided by the sample count), unoccluded samples only.
struct RecordLightSample {
  int light = -1;  // index into Scene::lights
  Eigen::Vector3f wi = Eigen::Vector3f::Zero();
  Eigen::Vector3f irradiance = Eigen::Vector3f::Zero();
  float distance = 0;
};

struct PixelRecord {
  int photo = 0, x = 0, y = 0;
  bool held_out = false;
  // A residual far in the tail (Monte Carlo fireflies, a hidden object's edge): left out of the
  // candidates' fits and scores, so that a handful of pixels cannot steer them.
  bool outlier = false;
  Eigen::Vector3f recorded = Eigen::Vector3f::Zero();  // the photo's value
  Eigen::Vector3f sim = Eigen::Vector3f::Zero();       // the model's prediction of it
  // The Monte Carlo variance of `sim` (SimulatePhotos' estimate; zero when unknown).
  Eigen::Vector3f sim_var = Eigen::Vector3f::Zero();
  int region = -1;
  Eigen::Vector3f position = Eigen::Vector3f::Zero();
  Eigen::Vector3f normal = Eigen::Vector3f::Zero();  // shading normal, toward the camera
  Eigen::Vector3f view = Eigen::Vector3f::Zero();    // unit, toward the camera
  // On a region with a specular lobe: the spread of the shading normals over the pixel, added
  // to α² wherever the record's lobe is evaluated (Observation::lobe_blur2,
  // solver/inverse/observations.h).
  float lobe_blur2 = 0;
  float r2 = 0;  // (distance to the principal point / half the image diagonal)²
  Eigen::Vector3f albedo = Eigen::Vector3f::Zero();     // the model's ρd at the point
  Eigen::Vector3f point_cam = Eigen::Vector3f::Zero();  // the point in the camera frame
  // The model image's gradient at the pixel (Prewitt: a 3×3-smoothed central difference), per
  // channel: d sim / dx, d sim / dy.
  Eigen::Matrix<float, 3, 2> sim_gradient = Eigen::Matrix<float, 3, 2>::Zero();
  std::vector<RecordLightSample> lights;  // direct light at the point
  // On a region with a specular lobe: the light the rest of the scene reflects onto the point,
  // as kRoomSamples directions about the view's mirror (a mixture of cosine and Ward lobes of the
  // region's roughness, each weighted by its density: RecordLightSample::irradiance is the model's
  // reflected radiance along it times cos/(pdf·n), light = -1). A lobe's reflection of the room
  // is Σ lobe·irradiance over them, as its reflection of the lights is over `lights`.
  std::vector<RecordLightSample> room;
  static constexpr int kRoomSamples = 16;
};

// Recorded photos of a scene (loaded once) and their valid-pixel masks.
struct PhotoSet {
  std::vector<Image> recorded;
  std::vector<Image> valid;  // 1 = a residual sample may come from this pixel
};

// Whether pixel (x, y) of a photo holds a usable value: inside its mask (when it has one), and
// every channel finite and below the photo's clip level (AutoSaturation).
inline bool UsablePixel(const Image& photo, const Image* mask, double clip, int x, int y) {
  if (mask && !(mask->at(x, y, 0) > 0.5f)) return false;
  for (int c = 0; c < 3; ++c) {
    const float v = photo.at(x, y, c);
    if (!std::isfinite(v) || !(v < clip)) return false;
  }
  return true;
}

// Reads every photo; a pixel is valid when finite, below the photo's clip level, inside its mask,
// and its footprint (centre and four corners) lies on one reflective region.
PhotoSet LoadPhotoSet(const recon::Scene& scene);

// Per photo, one value per pixel (row-major): nonzero where a simulation renders the pixel.
using PixelMasks = std::vector<std::vector<uint8_t>>;

// Re-renders of the photos (SimulatePhotos), possibly of some pixels only (the others NaN).
struct Simulation {
  std::vector<Image> sims;
  // Per pixel and channel, an estimate of the Monte Carlo variance of sims (see SimulatePhotos);
  // zero where unknown.
  std::vector<Image> variance;
  std::vector<Image> raw_variance;  // the same before its 5 × 5 mean
  PixelMasks rendered;              // per photo: what is rendered; an empty list: every pixel
  bool Complete() const { return rendered.empty(); }
};

// Renders every photo's camera under its lighting and applies the photo model (scale, response).
// Each render is the mean of two independent renders of half the paths, and the variance holds,
// per pixel and channel, an unbiased estimate of the Monte Carlo variance of sims[i] from their
// difference, (h1 − h2)² / (spp (1/spp1 + 1/spp2)), averaged over a 5 × 5 window (zero when spp
// is 1). A model whose render is less noisy (an exact ambient term, lower albedos) has a lower
// residual² against the photos for that reason alone; the held-out gains subtract this variance.
// With `only`, just the pixels it marks are rendered; a later call (with `only` or without)
// renders those of its pixels that `sim` lacks, and the result equals, bit for bit, one call for
// them all (each pixel's paths have their own random streams). The variance's window reads
// unrendered pixels as 0: it is exact where the 5 × 5 window around a pixel is rendered.
void SimulatePhotos(const recon::Scene& model, const DiagnoseOptions& options, uint64_t seed,
                    Simulation* sim, const PixelMasks* only = nullptr);

// The pixels a step's held-out test reads (HeldOutGain): the held-out blocks widened by the
// variance's window (2 pixels), and every `grid`-th pixel in x and y (for an estimate of the
// fitted pixels' residual).
PixelMasks HeldOutTestMasks(const recon::Scene& model, const solver::PixelHoldout& holdout,
                            int grid);

// The residual samples of `model` (a complete scene): every pixel_stride-th valid pixel, with the
// renders' variance per pixel when `variance` is given (SimulatePhotos'). `sims` complete.
std::vector<PixelRecord> BuildRecords(const recon::Scene& model, const PhotoSet& photos,
                                      const std::vector<Image>& sims,
                                      const DiagnoseOptions& options,
                                      const std::vector<Image>* variance = nullptr);

// Marks the records whose residual lies far in the tail (see PixelRecord::outlier).
void FlagOutliers(std::vector<PixelRecord>* records);

// The residual of diagnosis.json (docs/file-formats.md) over records (held_out selects the set).
struct ResidualSums {
  double sq_err = 0, sq_photo = 0;
  double Relative() const { return sq_photo > 0 ? std::sqrt(sq_err / sq_photo) : 0; }
  // Adds pixel (x, y) of photo `rec` against the simulation `sim` (channels where it is finite).
  void AddPixel(const Image& rec, const Image& sim, int x, int y) {
    for (int c = 0; c < 3; ++c) {
      const double p = rec.at(x, y, c), m = sim.at(x, y, c);
      if (!std::isfinite(m)) continue;
      sq_err += (m - p) * (m - p);
      sq_photo += p * p;
    }
  }
};
ResidualSums Residual(const std::vector<PixelRecord>& records, bool held_out);

// Residual over every valid pixel of the photos (not only the records' stride).
ResidualSums ResidualOverPhotos(const PhotoSet& photos, const std::vector<Image>& sims,
                                const solver::PixelHoldout& holdout, bool held_out);

}  // namespace igi::diagnose
