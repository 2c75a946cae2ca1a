#pragma once
// The last step of igi-register in a scene's frame: a joint refinement (bundle adjustment, Ceres)
// of every registered camera pose and every triangulated sparse point, minimising
//   - the reprojection error of COLMAP's tracks (each 3D point's observations, in pixels),
//   - the reprojection error of the control points (markers: 3D positions known in the scene
//     frame, held fixed, and their pixels in some photos), and optionally
//   - the distance of the sparse points to the scene mesh (the closest mesh point found again at
//     every evaluation, so points near edges are not held to a wrong face's plane),
// each under a robust (Huber) loss; observations still beyond max_error_px after a solve are
// dropped and the problem solved again. The observations dropped (also those still beyond
// max_error_px at the end) leave the model, and points left with fewer than 2 observations go.
// Intrinsics stay fixed (known, or COLMAP's). The markers and the mesh fix the frame and scale, so
// the result does not inherit the error of a similarity fit: every photo with markers is pinned by
// them directly.
//
// Photos that COLMAP did not register can be posed from the markers alone
// (PoseImagesFromMarkers: PnP with the model's intrinsics when enough markers are seen) before
// the refinement.

#include <map>
#include <string>
#include <vector>

#include "recon/colmap_model.h"
#include "recon/mesh.h"
#include "recon/registration.h"

namespace igi::recon {

struct BundleRefinementOptions {
  double track_sigma_px = 1.0;     // accuracy of a feature position: residuals / this
  double marker_sigma_px = 1.0;    // accuracy of a marker pixel: residuals / this
  double huber_sigmas = 2.0;       // Huber threshold of every term, in its sigmas
  bool use_mesh = true;            // point-to-plane term (when a mesh is given)
  double mesh_sigma_m = 0;         // its sigma; 0 = 1.4826 x the points' median distance
  double mesh_max_distance_m = 0;  // points farther from the mesh get no term; 0 = 3 sigma
  int rounds = 2;                  // solves; before each but the first, track observations
                                   // reprojecting beyond max_error_px are dropped and the
                                   // points given a mesh term chosen again
  double max_error_px = 4.0;       // COLMAP's own filter (--Mapper.filter_max_reproj_error)
  int max_iterations = 200;        // per solve
  // Ceres threads (values below 1 count as 1).
  int threads = 1;
  void Validate() const;  // throws igi::Error (a programming error)
};

struct ImageRefinement {
  std::string name;
  int observations = 0;                                      // track observations used
  int markers = 0;                                           // marker observations used
  double rms_before_px = 0, rms_after_px = 0;                // tracks
  double marker_rms_before_px = 0, marker_rms_after_px = 0;  // markers (0 without)
};

struct BundleRefinementSummary {
  int images = 0;               // poses refined
  int points = 0;               // 3D points refined (tracks of 2+ observations)
  int observations = 0;         // track observations
  int marker_observations = 0;  // marker pixels in registered photos
  int mesh_points = 0;          // points with a mesh-distance term (last round)
  int outliers = 0;             // track observations removed (beyond max_error_px)
  double mesh_sigma_m = 0;
  int iterations = 0;  // over every round
  double initial_cost = 0, final_cost = 0;
  std::string termination;                     // Ceres's last termination type
  double rms_before_px = 0, rms_after_px = 0;  // track observations (after: those kept)
  double marker_rms_before_px = 0, marker_rms_after_px = 0;  // every marker observation
  double mesh_rms_before_m = 0, mesh_rms_after_m = 0;        // points with a mesh term
  std::vector<ImageRefinement> per_image;                    // in image-name order
};

// Refines `model` (already in the scene frame: markers' and mesh's) in place. `markers` and
// `mesh` may be null; with neither the frame is not fixed and igi::Error is thrown. Markers
// naming photos not in the model are ignored.
BundleRefinementSummary RefineBundle(const Markers* markers, const TriangleMesh* mesh,
                                     ColmapModel* model, const BundleRefinementOptions& options);

struct MarkerPose {
  std::string name;
  int markers = 0;
  double rms_px = 0;         // of the markers after PnP
  double rms_before_px = 0;  // of the markers under the pose replaced (re-posing)
};

// Poses each photo of `photos` that is not in `model` but sees at least `min_markers` markers
// (PnP with the intrinsics of the model's first camera, then Levenberg-Marquardt), and adds it
// to the model as an image without 2D points when the markers' reprojection RMS is below
// `max_rms_px` (with known intrinsics 4 points in general position fix a pose and leave 2
// residuals to check it). Returns the photos added.
std::vector<MarkerPose> PoseImagesFromMarkers(const Markers& markers,
                                              const std::vector<std::string>& photos,
                                              ColmapModel* model, int min_markers = 4,
                                              double max_rms_px = 2.0);

// Photos of the model that see at least `min_markers` markers reprojecting farther than
// `disagree_px` RMS under the current pose (already in the scene frame) are posed from the
// markers instead (as above) when that fits them within `max_rms_px`; their track observations
// leave the model (they were consistent with the wrong pose), so the markers alone hold them.
// COLMAP can register a close-up wrongly from few matches on repeated texture (measured on the
// synthetic room: 17-23 degrees off). Returns the photos re-posed.
std::vector<MarkerPose> RePoseImagesFromMarkers(const Markers& markers, ColmapModel* model,
                                                double disagree_px = 10, int min_markers = 4,
                                                double max_rms_px = 2.0);

}  // namespace igi::recon
