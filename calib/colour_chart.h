#pragma once
// Colour calibration from a photographed ColorChecker (the classic 24-patch chart, 6 columns ×
// 4 rows, dark skin at one corner and black at the opposite one): find the chart in a linear
// camera-RGB image, read the patch means, fit the 3×3 matrix camera RGB → linear sRGB (D65) that
// brings them closest to the chart's reference values in CIEDE2000, and write it to colour.json
// (docs/file-formats.md). Also the colour science it needs: XYZ ↔ CIELAB ↔ linear sRGB, Bradford
// adaptation and ΔE2000.
//
// Reference values come from an ArgyllCMS CGATS file (.cie: XYZ and/or L*a*b* per patch, D50,
// 2° observer), as ArgyllCMS and X-Rite ship them. The fitted matrix maps camera RGB to linear
// sRGB in which the chart's D50 white is adapted (Bradford) to sRGB's D65 white.
//
// Bad input (a file that is not CGATS, a chart that is not found, a chart too small to sample,
// a bad colour.json) is an InputError naming the file, key or pixel and the rule.

#include <Eigen/Core>
#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "tools/common/image.h"

namespace igi::calib {

// ---- Colour science (CIE 15:2004, IEC 61966-2-1) -------------------------------------------

// CIE XYZ of the reference whites (2° observer), Y = 1.
Eigen::Vector3d WhiteD50();
Eigen::Vector3d WhiteD65();

// Linear sRGB (D65 white, [1,1,1] = white with Y = 1) ↔ CIE XYZ (Y = 1 for white).
Eigen::Vector3d XyzFromLinearSrgb(const Eigen::Vector3d& rgb);
Eigen::Vector3d LinearSrgbFromXyz(const Eigen::Vector3d& xyz);
// CIELAB relative to `white` (XYZ, Y = 1); L* in [0, 100] for XYZ with 0 ≤ Y ≤ 1.
Eigen::Vector3d LabFromXyz(const Eigen::Vector3d& xyz, const Eigen::Vector3d& white);
Eigen::Vector3d XyzFromLab(const Eigen::Vector3d& lab, const Eigen::Vector3d& white);
// The Bradford chromatic adaptation matrix taking XYZ under `from_white` to XYZ under `to_white`.
Eigen::Matrix3d BradfordAdaptation(const Eigen::Vector3d& from_white,
                                   const Eigen::Vector3d& to_white);
// Linear sRGB → CIELAB D50 (XYZ D65 adapted to D50 by Bradford), the space the chart's
// reference values and every ΔE2000 here are in; and back.
Eigen::Vector3d LabD50FromLinearSrgb(const Eigen::Vector3d& rgb);
Eigen::Vector3d LinearSrgbFromLabD50(const Eigen::Vector3d& lab);

// CIEDE2000 colour difference (CIE 142-2001, kL = kC = kH = 1), as Sharma, Wu & Dalal (2005)
// state it, between two CIELAB colours.
double DeltaE2000(const Eigen::Vector3d& lab1, const Eigen::Vector3d& lab2);

// ---- Chart reference values ----------------------------------------------------------------

// The 24 patches of a ColorChecker, in the chart's reading order: dark skin, light skin, …,
// bluish green (first row), orange … (second), blue … (third), white … black (fourth).
struct ChartReference {
  std::string file;                      // the .cie file read
  std::vector<std::string> names;        // the file's patch names, e.g. "A1" … "D6"
  std::vector<Eigen::Vector3d> lab_d50;  // CIELAB D50 of each patch
};

// Reads an ArgyllCMS CGATS file of a ColorChecker (ColorChecker.cie: 24 sets named A01 … D06;
// ColorCheckerPassport.cie: 50 sets of which A1 … D6 are the classic 24). Rows A … D are the
// chart's rows, columns 1 … 6 its columns. L*a*b* is taken when the file has LAB_L/LAB_A/LAB_B,
// else XYZ_X/XYZ_Y/XYZ_Z (0 … 100, D50). Throws InputError naming the file, line and rule.
ChartReference ReadChartReference(const std::filesystem::path& path);

// ---- Finding and reading the chart ---------------------------------------------------------

// Where the chart's patch grid is in the image: the outer corners of the four corner patches in
// continuous pixel coordinates (the centre of the top-left pixel is (0.5, 0.5)), in the order
// dark skin, bluish green, black, white (so going round the grid).
struct ChartLocation {
  std::array<Eigen::Vector2d, 4> corners;
};

// Finds a ColorChecker in a linear RGB image with OpenCV's mcc detector (MCC24). The image's
// scale and white balance do not matter (it is balanced and tone-mapped for the detector).
// nullopt when no chart is found, or when what the detector found is no chart: its patches
// cannot be read (SamplePatches' defaults) or its grey row does not darken from white to black.
std::optional<ChartLocation> FindColourChart(const Image& linear_rgb);

struct PatchSamplingOptions {
  // Side of the square sampled at each patch's centre, as a fraction of the patch's side, (0, 1].
  double inner_fraction = 0.5;
  // Fraction of the sampled values dropped at each end per channel before averaging, [0, 0.5).
  double trim_fraction = 0.1;
  // Fewest pixels a sampled square may hold, >= 1.
  int min_pixels = 16;

  void Validate() const;
};

// The 24 patch means (trimmed, per channel) of `linear_rgb` at `location`, in chart order.
// Throws InputError when a patch lies outside the image or holds fewer than min_pixels pixels.
std::vector<Eigen::Vector3d> SamplePatches(const Image& linear_rgb, const ChartLocation& location,
                                           const PatchSamplingOptions& options = {});

// ---- Fitting and evaluating ----------------------------------------------------------------

struct DeltaEStats {
  double mean = 0;
  double max = 0;
  std::vector<double> per_patch;  // chart order
};

// ΔE2000 (in CIELAB D50) of each corrected patch (linear sRGB) against the reference.
DeltaEStats EvaluateDeltaE(const std::vector<Eigen::Vector3d>& linear_srgb,
                           const ChartReference& reference);

// The exposure factor s > 0 that minimises the mean ΔE2000 of s × linear_srgb against the
// reference (golden-section search in log s, within a factor e of the grey patches' least-squares
// luminance scale): how a photo already in linear sRGB (a raw converter's own camera matrix) is
// compared fairly, its exposure being arbitrary.
double BestExposureScale(const std::vector<Eigen::Vector3d>& linear_srgb,
                         const ChartReference& reference);

// The raw decoder's own camera matrix at its best: `decoder_srgb` are the chart's patches in the
// decoder's linear sRGB output (any white balance), `camera_rgb` the same patches in its
// camera-RGB output without white balance. The matrix between the two (least squares over the
// patches the decoder did not clip at zero, scaled per column so that equal camera channels give
// sRGB white, as the decoder's rgb_cam does) is applied to camera RGB balanced so that the grey
// patches D2 … D5 have equal channels, as a grey-card white balance would. Returns linear sRGB
// per patch (exposure not yet matched).
std::vector<Eigen::Vector3d> GreyBalancedDecoderColour(
    const std::vector<Eigen::Vector3d>& camera_rgb,
    const std::vector<Eigen::Vector3d>& decoder_srgb);

struct ColourFitOptions {
  // A patch with a channel at or above this fraction of `clip_level` is left out of the fit
  // (clipped), (0, 1].
  double saturated_fraction = 0.98;
  // The level at which the input clips (1 for the raw decoder); 0 = unknown (nothing left out).
  double clip_level = 0;
  // Iterations of the ΔE2000 minimisation (Nelder–Mead), >= 1.
  int max_iterations = 5000;

  void Validate() const;
};

struct ColourFit {
  // Camera RGB → linear sRGB that reproduces the chart's reflectances (white patch ≈ 0.9).
  Eigen::Matrix3d matrix_absolute = Eigen::Matrix3d::Identity();
  // The same matrix divided by `exposure_scale`: the form colour.json stores.
  Eigen::Matrix3d matrix = Eigen::Matrix3d::Identity();
  // matrix_absolute = exposure_scale × matrix, with exposure_scale chosen so that on the chart's
  // neutral patches the corrected luminance equals the camera's green channel.
  double exposure_scale = 1;
  DeltaEStats delta_e2000;  // of matrix_absolute on the 24 patches
  int patches_used = 0;     // patches not clipped
  double rms_loss = 0;      // RMS ΔE2000 over the patches used, as the minimiser reports it
};

// Fits the 3×3 matrix camera RGB → linear sRGB: least squares in linear RGB, then minimising
// the sum of squared ΔE2000 (OpenCV's cv::ccm::ColorCorrectionModel, CCM_3x3, DISTANCE_CIE2000).
// Throws InputError when fewer than 9 patches are usable.
ColourFit FitColourMatrix(const std::vector<Eigen::Vector3d>& camera_rgb,
                          const ChartReference& reference, const ColourFitOptions& options = {});

// Applies `matrix` (camera RGB → linear sRGB) in place to `pixels` interleaved RGB triples.
void ApplyColourMatrix(float* rgb, size_t pixels, const Eigen::Matrix3d& matrix);

// ---- colour.json ---------------------------------------------------------------------------

// What the matrix expects as camera RGB: kCameraRaw, a raw file decoded linearly in the camera's
// own primaries without white balance (hdr::RawColor::kRaw, hdr::RawWhiteBalance::kNone);
// kLinear, a linear image as given (an EXR, or 8/16-bit levels linearised by a response curve).
enum class ColourInput { kCameraRaw, kLinear };
// "camera_raw", "linear".
std::string_view ColourInputName(ColourInput input);
std::optional<ColourInput> ColourInputFromName(std::string_view name);

// colour.json ("format": "igi-colour", "version": 1): see docs/file-formats.md.
struct ColourFile {
  Eigen::Matrix3d matrix = Eigen::Matrix3d::Identity();  // camera RGB → linear sRGB, row-major
  ColourInput input = ColourInput::kLinear;
  std::string chart;          // reference file name (.cie)
  std::string image;          // the chart photo
  double exposure_scale = 1;  // chart reflectance = exposure_scale × matrix × camera RGB
  DeltaEStats delta_e2000;    // of the fitted matrix over the 24 patches
  // Raw input: the raw decoder's own matrix, white-balanced on the chart's grey patches
  // (GreyBalancedDecoderColour), at its best exposure.
  std::optional<DeltaEStats> camera_matrix_delta_e2000;
  // Raw input: the raw decoder's linear sRGB output as shot (the camera's recorded white
  // balance and its own matrix), at its best exposure.
  std::optional<DeltaEStats> as_shot_delta_e2000;
};

// Writes atomically; throws InputError on a non-finite matrix or scale.
void WriteColourFile(const std::filesystem::path& path, const ColourFile& colour);
// Reads strictly: unknown keys, wrong types, wrong sizes are InputErrors naming file and key.
ColourFile ReadColourFile(const std::filesystem::path& path);

}  // namespace igi::calib
