#pragma once
// Fitting reconstructed points (COLMAP's sparse model, arbitrary frame and scale) to the scene
// mesh: a similarity (scale, rotation, translation) found by robust point-to-plane ICP against
// the mesh triangles, from a coarse start given by the caller (e.g. control points) or from the
// principal axes of both point sets with the 24 axis-aligned rotation hypotheses.
//
// ICP iteration: every point is moved by the current similarity, its closest mesh point and
// that triangle's normal are found; the farthest (1 - trim_fraction) of the points are dropped
// (trimmed ICP) and the rest weighted by Huber's function of the point-to-plane residual (scale:
// 1.4826 x median |residual|, Huber constant 1.345); the linearised 7-parameter update (rotation,
// translation, log scale about the points' centroid) is solved by damped least squares.
//
// Then the poses can be refined against the mesh: each photo's pose alone is moved to minimise
// the reprojection error of its observed sparse points snapped to the mesh (closest point).

#include <Eigen/Core>
#include <string>
#include <vector>

#include "recon/colmap_model.h"
#include "recon/mesh.h"
#include "recon/registration.h"

namespace igi::recon {

struct MeshAlignmentOptions {
  int max_iterations = 60;      // of the final ICP
  double trim_fraction = 0.8;   // share of the points kept in each iteration, (0, 1]
  double tolerance = 1e-8;      // stop when the update (rotation rad, relative scale, and
                                // translation / mesh size) is below this
  int coarse_iterations = 15;   // ICP iterations per rotation hypothesis (PCA start)
  int coarse_sample = 500;      // points used per hypothesis (PCA start)
  int random_hypotheses = 200;  // random rotations tried after the 24 principal-axes ones
  double inlier_sigmas = 3;     // final inliers: distance <= this x robust sigma
  void Validate() const;        // throws igi::Error (a programming error, not user input)
};

struct MeshAlignmentSummary {
  Similarity3d scene_from_model;
  std::string start;              // "given" or "pca"
  int hypotheses = 0;             // rotation hypotheses tried (pca)
  int iterations = 0;             // of the final ICP
  size_t points = 0;              // points fitted
  double inlier_threshold_m = 0;  // distance to the mesh below which a point is an inlier
  double inlier_fraction = 0;
  double rms_m = 0;     // RMS distance of the inliers to the mesh, metres
  double median_m = 0;  // median distance of all points to the mesh
};

// Fits `points_model` to `mesh` starting from `start` (scene_from_model).
MeshAlignmentSummary AlignPointsToMesh(const std::vector<Eigen::Vector3d>& points_model,
                                       const TriangleMesh& mesh, const Similarity3d& start,
                                       const MeshAlignmentOptions& options = {});

// As above from a coarse start of its own: the points' and the mesh's (area-sampled) centroids,
// scale from their spreads, and each of the 24 rotations that map the points' principal axes to
// the mesh's up to order and sign plus `random_hypotheses` random rotations; the hypothesis with
// the most points within 1 % of the mesh size after a short ICP wins. A mesh with symmetries
// (an empty box room) can still be fitted upside down: prefer control points for the start.
// Throws igi::Error with fewer than 10 points.
MeshAlignmentSummary AlignPointsToMeshCoarse(const std::vector<Eigen::Vector3d>& points_model,
                                             const TriangleMesh& mesh,
                                             const MeshAlignmentOptions& options = {});

struct PoseRefinementSummary {
  int images = 0;            // poses refined
  int points = 0;            // sparse points snapped to the mesh (inliers) at the end
  int rounds = 0;            // pose / point alternations
  double rms_before_px = 0;  // reprojection of the snapped points, before
  double rms_after_px = 0;   // and after
};

// Refines every image pose of `model` (already in the scene frame) against the mesh: the
// model's 3D points within `inlier_threshold_m` of the mesh are replaced by their closest mesh
// points, then `rounds` times: each pose is moved alone (Gauss-Newton, Huber on 2 px) to
// minimise their reprojection, and each point is triangulated again from the new poses and
// snapped to the mesh (so the structure cannot bend away from the mesh). Images with fewer than
// 6 such points keep their pose. The snapped points replace the model's.
PoseRefinementSummary RefinePosesAgainstMesh(const TriangleMesh& mesh, double inlier_threshold_m,
                                             ColmapModel* model, int rounds = 5);

// The model's 3D points (any order).
std::vector<Eigen::Vector3d> ModelPoints(const ColmapModel& model);

}  // namespace igi::recon
