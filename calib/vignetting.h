#pragma once
// A camera's vignetting — the fall-off of recorded radiance toward the image corners — as the
// radial polynomial igi-render and igi-diagnose apply (docs/scene-format.md, a camera's
// "vignetting"):
//
//   V(r) = 1 + k1 r² + k2 r⁴,   r = |pixel − principal point| / (half the image diagonal)
//
// measured two ways:
//
// - Flat fields: photos of a uniformly lit diffuse target (or a light box) filling the frame.
//   Each photo is reduced to means over blocks of pixels (FlatFieldReducer, one row at a time so
//   that a 24 MP photo is never held whole), then all photos are fitted at once (FitFlatFields):
//       ln value = ln L_i(u, v) + ln V(r)
//   where L_i, photo i's illumination of the target, is exp of a polynomial in the image
//   coordinates (u, v) — relative to the principal point, in half diagonals — that holds every
//   term up to the third degree except the radially symmetric ones (a constant and
//   u, v, u² − v², uv, u³, u²v, uv², v³). Those terms take up a light's gradients and its
//   elongated fall-off exactly, whatever they are; the radially symmetric part of a photo's
//   illumination cannot be told apart from vignetting within one photo, and averages out over
//   photos with the target moved between them.
// - Overlap: photos of the scene itself, registered, where the same surface point is seen at
//   different image radii by photos under the same lighting. For a diffuse surface both record
//   the same radiance, so for every pair
//       ln value_a − ln V(r_a) − s_a = ln value_b − ln V(r_b) − s_b
//   with s a photo's exposure. Radiance maps of one camera at one setting share it (s = 0 for
//   all, the default: k1 and k2 are then fixed by the values themselves); photos of different
//   exposures each get their own s (the first photo's fixed at 0), fitted with k1 and k2, which
//   leaves only the differences within each photo to measure V. FitOverlap fits them to the pairs
//   (solver/inverse/vignetting_overlap.h collects them) with a Cauchy loss, so that glossy surfaces
//   and occlusion mistakes do not pull the fit.
//
// Both fits run through Ceres (Levenberg–Marquardt, automatic derivatives).

#include <cstdint>
#include <string>
#include <vector>

namespace igi::calib {

struct Vignetting {
  double k1 = 0;
  double k2 = 0;

  // V at normalised squared radius r2.
  double Factor(double r2) const { return 1.0 + k1 * r2 + k2 * r2 * r2; }
};

// r² at continuous pixel (x, y) (COLMAP's convention: the top-left pixel's centre is (0.5,
// 0.5)) of a width × height image whose principal point is (cx, cy), in half diagonals.
double VignettingRadius2(double x, double y, double cx, double cy, int width, int height);

// One block of a flat field: its centre (continuous pixels) and the mean linear luminance of
// its usable pixels.
struct FlatFieldBlock {
  double x = 0;
  double y = 0;
  double value = 0;
};

struct FlatField {
  std::string name;  // the photo, for messages
  int width = 0;
  int height = 0;
  std::vector<FlatFieldBlock> blocks;
  int64_t unusable_pixels = 0;  // pixels left out (clipped, dark, not finite)
};

// Reduces a flat-field photo, fed one row at a time, to the means of square blocks of
// `block_px` pixels (the rows and columns past the last whole block are left out).
class FlatFieldReducer {
 public:
  // The largest share of a photo's pixels that may be unusable before it is refused.
  static constexpr double kMaxUnusableShare = 1e-4;
  // A block whose mean is below this share of the photo's median block is refused as dark.
  static constexpr double kDarkShareOfMedian = 0.05;

  FlatFieldReducer(std::string name, int width, int height, int block_px);

  // Row y's linear luminance, and per pixel whether the recorded value is usable (neither
  // clipped nor black in any channel). Rows may come in any order, each once.
  void AddRow(int y, const float* luminance, const uint8_t* usable);
  // The blocks. Throws InputError "NAME: pixel (x, y): VALUE: RULE" when more than
  // kMaxUnusableShare of the pixels were unusable (naming the first), or a block is dark.
  FlatField Finish();

 private:
  std::string name_;
  int width_, height_, block_px_, cols_, rows_;
  std::vector<double> sum_;
  std::vector<int> count_;
  int64_t unusable_ = 0;
  int first_bad_x_ = -1, first_bad_y_ = -1;
  float first_bad_value_ = 0;
};

// The blocks' side for a width × height photo: about 48 blocks along the longer side.
int FlatFieldBlockSize(int width, int height);

// One surface point seen by two photos of the same lighting: their normalised squared radii and
// the ln of their linear luminance there.
struct OverlapPair {
  int photo_a = 0;
  int photo_b = 0;
  double r2_a = 0;
  double r2_b = 0;
  double ln_a = 0;
  double ln_b = 0;
};

struct VignettingFit {
  Vignetting vignetting;
  double rms_ln = 0;  // RMS of the fitted residuals (ln units), before the robust loss
  int samples = 0;    // blocks (flat fields) or pairs (overlap) fitted
  int photos = 0;
  std::vector<double> exposures_ln;  // overlap: each photo's s (0 for photos in no pair)
};

// Fits k1, k2 to flat fields of one camera with principal point (cx, cy). Throws InputError
// when there are no photos, they differ in size, or the blocks do not reach r² ≥ 0.25.
VignettingFit FitFlatFields(const std::vector<FlatField>& fields, double cx, double cy);

// Fits k1, k2 (and with `free_exposures` the photos' exposures) to overlap pairs of `photos`
// photos. Throws InputError with fewer than 100 pairs or when the pairs' radii do not differ
// enough to separate V.
VignettingFit FitOverlap(const std::vector<OverlapPair>& pairs, int photos,
                         bool free_exposures = false);

}  // namespace igi::calib
