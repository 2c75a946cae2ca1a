#pragma once
// pose_error (docs/diagnose-effects.md): a photo's camera pose is off. The photo is then the model
// seen from a slightly moved camera, so the residual follows the model image's gradient along the
// flow of a small rotation ω (camera frame) and translation δ: photo − sim ≈ −∇sim · J(ω, δ).
//
// FitPoseError fits that motion. Given the photos and the model's renders, it aligns them
// coarse to fine (both blurred, a Gaussian of 4, 2 and 1 pixels, Gauss–Newton on the render
// warped by each iterate), so that a pose error of a few pixels is within reach of the
// linearisation, which holds below the blur's width; from the records alone it is one linear
// step. RefinePose iterates it on re-renders — apply the step, re-render the camera's photos,
// rebuild the records, refit — because a warped render is not a render from the moved camera
// (occlusions, view-dependent shading).

#include <string>
#include <vector>

#include "recon/scene.h"
#include "recon/scene_document.h"
#include "solver/diagnose/candidates.h"
#include "solver/diagnose/diagnose_options.h"
#include "solver/diagnose/pixel_records.h"
#include "solver/diagnose/residual_fit.h"
#include "tools/common/geometry.h"
#include "tools/common/json.h"

namespace igi::diagnose {

// The pose correction of `camera`: the coarse-to-fine alignment when `context` has the photos
// and renders (scored as the change of the render it warps), otherwise one damped Gauss–Newton
// (Levenberg–Marquardt) step (six amplitudes: the damped direction, its length fitted); its
// params hold the step (rotation_vector, translation_m), which the effect's Write composes with
// the camera's qvec/tvec in the declared document.
CandidateResult FitPoseError(const CandidateContext& context, const ResidualFitter& fitter,
                             int camera);

// A gradient fit is a pose error when its rotation stays below kMaxPoseErrorDeg and its shift
// below kMaxPoseShiftOfDepth times the median depth of the camera's samples (scene units are
// arbitrary: metres in a room, sphere radii in DiLiGenT).
constexpr double kMaxPoseErrorDeg = 5;
constexpr double kMaxPoseShiftOfDepth = 0.1;

// Levenberg–Marquardt damping of a pose step's normal equations (relative to their diagonal,
// rotation in radians and shift in units of the median depth): motions the image tells apart
// less well than this are left out of the step (see FitPoseError).
constexpr double kPoseDamping = 0.01;

// A pose step that raises the fitted residual is retried at half its length this many times.
constexpr int kPoseHalvings = 2;

// RefinePose stops once a step cuts the fitted residual² by less than this share of it.
constexpr double kPoseMinStepGain = 0.002;

// Composes a small rotation ω (camera frame, radians) and shift δ (scene units) with the pose of
// camera entry `camera` in *doc: R ← exp(ω) R, t ← exp(ω) t + δ.
void ComposePoseStep(const std::string& camera, const Eigen::Vector3d& omega,
                     const Eigen::Vector3d& delta, recon::SceneDocument* doc);

// The median depth (camera z, scene units) of `camera`'s records; 0 when it has none.
double MedianDepth(const std::vector<PixelRecord>& records, const recon::Scene& model, int camera);

// Blocks whose model-image gradient energy reaches this many times the median block's are the
// edges where a pose error is scored.
constexpr double kEdgeFactor = 4;

struct PoseRefinement {
  int iterations = 0;        // Gauss–Newton steps made
  double rotation_deg = 0;   // the whole correction: rotation angle
  double translation_m = 0;  // and camera-centre shift
  double last_step_deg = 0, last_step_m = 0;
};

// Iterates the pose of `camera` in *doc from the model's pose: re-renders the camera's photos
// with the moved pose, rebuilds the records (the camera's outliers included: its sharpest edges
// are the signal) and applies the next step, until a step is below 0.005° and 3e-5 of the
// median depth (0.1 mm at 3 m), a step cuts the fitted residual² by less than kPoseMinStepGain
// of it, a step raises it even at a quarter of its length (taken back), or max_iterations
// (halvings included) were made.
PoseRefinement RefinePose(const recon::Scene& model, int camera, const PhotoSet& photos,
                          const std::vector<Image>& sims, const DiagnoseOptions& options,
                          bool materials_solved, double cell_m, int max_iterations,
                          recon::SceneDocument* doc);

}  // namespace igi::diagnose
