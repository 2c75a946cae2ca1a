#pragma once
// The principal point and the aspect ratio (fy / fx) of a camera that COLMAP self-calibrated,
// refined after its mapping and kept only where the photos determine them.
//
// COLMAP 3.8 self-calibrates the focal length (one, except for PINHOLE and OPENCV) and the
// distortion with the principal point held at the image centre. A principal point d px away from
// the centre turns every recovered camera by about atan(d / f): 0.5 degrees for the Herz-Jesu
// photos' 23 px at f = 2760 px. This is a bundle adjustment (Ceres) of every registered pose, every
// point of 2+ observations and each camera's intrinsics [f, a = fy / fx, cx, cy, k1, k2, p1, p2]
// (fx = f, fy = a f; OPENCV's distortion), whose free terms are f, the distortion terms of the
// model COLMAP calibrated (SIMPLE_RADIAL: k1; RADIAL: k1, k2; OPENCV: all four), a when that model
// has two focal lengths, and the terms under test: the principal point, and a when the model has
// one focal length. The frame is held by the photo with the most observations and the scale by one
// coordinate of the translation of the photo farthest from it. The intrinsics' covariance (Ceres,
// sparse QR, scaled by the residuals' variance) says how well the photos fix them.
//
// It is igi's own adjustment rather than COLMAP's bundle_adjuster because COLMAP 3.8 has no model
// with fx != fy and radial distortion but no tangential terms (OPENCV's p1, p2 trade with the
// principal point: on Herz-Jesu they moved cx 8.6 px off K.txt's and left 0.20 degrees of rotation
// error), its bundle_adjuster frees all of a model's distortion terms together, and it reports no
// uncertainty to decide by.
//
// kAuto keeps a term under test only where the photos determine it: the principal point when the
// covariance can be computed (the Jacobian has full rank), its offset from the image centre is at
// least min_significance standard deviations (Mahalanobis distance with its 2×2 covariance) and
// at most max_principal_point_offset of the image's width and height; the aspect ratio when |a - 1|
// is at least min_significance standard deviations and at most max_aspect_offset. A camera's terms
// that fail are held (the principal point at the centre, a at COLMAP's) and the adjustment is
// solved again with the rest, until every free term passes; a camera left with no term under test
// keeps COLMAP's intrinsics, and a model with none keeps COLMAP's poses and points too. A centred
// principal point (synthetic photos) therefore stays exactly where COLMAP put it, up to the test's
// false alarms (about 1 % at 3 standard deviations). kOn keeps both terms of every camera from one
// adjustment without the tests.
//
// A refined camera leaves as PINHOLE (from a pinhole model) or OPENCV (from a distorted one).

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "recon/colmap_model.h"

namespace igi::recon {

// When the principal point and aspect ratio of a self-calibrated camera are refined.
enum class PrincipalPointRefinement {
  kOff,   // COLMAP's: the principal point at the image centre, fx = fy (one-focal models)
  kAuto,  // refined, each kept only where the photos determine it
  kOn,    // refined and kept
};
// "off", "auto", "on".
std::string_view PrincipalPointRefinementName(PrincipalPointRefinement mode);
std::optional<PrincipalPointRefinement> PrincipalPointRefinementFromName(std::string_view name);

struct IntrinsicsRefinementOptions {
  PrincipalPointRefinement mode = PrincipalPointRefinement::kAuto;
  // A term under test is kept (kAuto) when its offset from COLMAP's value (the image centre,
  // a = 1) is at least this many standard deviations; > 0.
  double min_significance = 3.0;
  // Largest offset of the principal point from the image centre kept (kAuto), per axis as a
  // fraction of that image side, in (0, 0.5]. Lenses and sensor mounts put it within a few
  // percent; a fit farther off is taken as degenerate (a photo cropped off-centre is not refined).
  double max_principal_point_offset = 0.1;
  double max_aspect_offset = 0.05;  // largest |fy / fx - 1| kept (kAuto), in (0, 1)
  double track_sigma_px = 1.0;      // accuracy of a feature position: residuals / this; > 0
  double huber_sigmas = 2.0;        // Huber threshold of every residual, in its sigmas; > 0
  int max_iterations = 100;         // per adjustment; >= 1
  int threads = 1;                  // Ceres threads (values below 1 count as 1)

  void Validate() const;  // throws igi::InputError naming the field
};

// One camera in one adjustment.
struct CameraIntrinsicsFit {
  uint32_t camera_id = 0;
  int images = 0;              // registered photos of this camera
  std::string model_before;    // COLMAP's model name
  std::string tested;          // the terms under test freed: "principal_point+aspect", … or ""
  double focal_before_px = 0;  // fx before
  double focal_px = 0;         // fx = f after
  double focal_sigma_px = 0;   // its standard deviation (0 when not computed)
  double aspect = 1;           // fy / fx after
  double aspect_sigma = 0;     // its standard deviation (0 when held)
  std::array<double, 2> principal_point_px{};        // cx, cy after
  std::array<double, 2> principal_point_sigma_px{};  // their standard deviations (0 when held)
  std::array<double, 2> offset_px{};                 // principal point - image centre
  double principal_point_significance = 0;  // the offset's Mahalanobis distance, in std devs
  double aspect_significance = 0;           // |a - a before| / its standard deviation
  std::string verdict;                      // "kept", or why a tested term is held
};

// One adjustment solved.
struct IntrinsicsAdjustment {
  int iterations = 0;
  std::string termination;  // Ceres's termination type, or why there is no usable solution
  double rms_before_px = 0, rms_after_px = 0;  // reprojection RMS of the observations used
  bool covariance = false;  // the intrinsics' covariance could be computed (full rank)
  std::vector<CameraIntrinsicsFit> cameras;
};

struct IntrinsicsRefinementSummary {
  PrincipalPointRefinement mode = PrincipalPointRefinement::kAuto;
  // Per camera id the terms kept ("principal_point+aspect", "principal_point", "aspect" or
  // "none").
  std::vector<std::pair<uint32_t, std::string>> kept;
  int images = 0, points = 0, observations = 0;
  std::string skipped;                            // why nothing was tried ("" when something was)
  std::vector<IntrinsicsAdjustment> adjustments;  // in the order solved

  // The terms kept for `camera_id` ("none" when absent).
  std::string KeptFor(uint32_t camera_id) const;
};

// Refines `model` in place as above (unchanged with kOff, or when nothing is kept). A model with
// fewer than 2 registered photos, or a camera model recon/camera.h cannot read, is left unchanged
// and `skipped` says why.
IntrinsicsRefinementSummary RefineSelfCalibratedIntrinsics(
    ColmapModel* model, const IntrinsicsRefinementOptions& options);

}  // namespace igi::recon
