#pragma once
// igi-register's job (docs/file-formats.md: report.json, markers): photos -> camera poses with
// COLMAP 3.8 (or an existing COLMAP model), optionally brought into a scene's frame.
//
// When COLMAP self-calibrated the camera, its principal point (held at the image centre) and
// aspect ratio are refined where the photos determine them (recon/intrinsics_refinement.h)
// before anything else; report.json's "intrinsics_refinement" says what was tried and kept.
//
// In a scene's frame the model is placed by the markers' control points when given, then by
// fitting the sparse points to the scene mesh (robust point-to-plane ICP with scale; without
// markers from a principal-axes start), then each pose is refined against the mesh; photos whose
// COLMAP pose misses their markers by > 10 px RMS, and photos COLMAP did not register, are posed
// from their markers when they see 4+ (PnP); last, every pose and sparse point is refined jointly
// (recon/registration_refinement.h). report.json's "alignment" says what was done and how well,
// and "registered" gives every photo's final reprojection RMS (tracks and markers).
//
// Bad input is found by ValidateRegisterInputs before anything is written (igi::InputError, exit
// 2); COLMAP missing, of another version than 3.8, or reconstructing nothing is igi::Error (exit
// 1). Photos that did not register are not an error here: Register lists them in its summary and
// in report.json.

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "recon/colmap_runner.h"
#include "recon/intrinsics_refinement.h"
#include "recon/registration.h"
#include "recon/scene.h"
#include "tools/common/json.h"

namespace igi::recon {

struct RegisterOptions {
  std::string images;   // folder of photos (JPEG, PNG, TIFF, BMP)
  std::string out;      // output folder: sparse/, report.json, scene.json (with `scene`), colmap/
  std::string scene;    // scene.json whose frame the poses are brought into; empty = COLMAP's frame
  std::string markers;  // control points (igi-markers JSON) in `scene`'s frame; empty = none
  // COLMAP's run. Its `intrinsics` are the known intrinsics (camera.json's, held fixed; absent:
  // COLMAP self-calibrates `camera_model`), and its `threads` also count the joint refinement's.
  ColmapRunOptions colmap;
  // The file `colmap.intrinsics` were read from, named in the photo size check's message.
  std::string camera_file;
  // After COLMAP self-calibrates (no `colmap.intrinsics`, no `colmap_model`): refine the principal
  // point and the aspect ratio, keeping each only where the photos determine it (kAuto), always
  // (kOn) or never (kOff) (recon/intrinsics_refinement.h).
  PrincipalPointRefinement refine_principal_point = PrincipalPointRefinement::kAuto;
  bool no_mesh_fit = false;          // with `scene`: align by `markers` only, no mesh fit
  bool no_pose_refinement = false;   // with `scene`: no per-photo refinement against the mesh
  bool no_joint_refinement = false;  // with `scene`: no final joint refinement of poses, points
  double marker_sigma_px = 1.0;      // accuracy of the markers' pixels
  double mesh_sigma_m = 0;           // accuracy of the mesh; 0 = from the mesh fit's residuals
  std::string colmap_model;          // an existing COLMAP model instead of running COLMAP
};

// The inputs of a registration, read and checked by ValidateRegisterInputs.
struct RegisterInputs {
  std::vector<std::string> images;    // the photos in RegisterOptions::images (file names)
  std::optional<Json> scene;          // scene.json as read (rewritten into the output)
  std::optional<Scene> loaded_scene;  // the same scene, validated, with its mesh
  std::optional<Markers> markers;
};

struct RegisterSummary {
  size_t registered = 0;                  // photos in the final model
  size_t images = 0;                      // photos given
  size_t points = 0;                      // sparse 3D points in the final model
  std::vector<std::string> unregistered;  // photos left out (file names), as in report.json
};

// Reads and checks every input of `options` before anything is written: the photo folder (2 or
// more photos), `colmap_model` a folder, every photo of the size of `colmap.intrinsics` when
// given, the scene (valid, with geometry, and with `markers` when the mesh is not fitted), and
// the markers (with a scene; their photos in `images`; their points inside the scene's bounding
// box grown by 10 % of its diagonal). Throws igi::InputError listing the problems (exit 2).
RegisterInputs ValidateRegisterInputs(const RegisterOptions& options);

// Runs COLMAP into `out`/colmap (or loads `colmap_model`), brings the model into the scene's
// frame when a scene is given, and writes `out`/sparse/ (COLMAP TXT model), `out`/report.json
// and, with a scene, `out`/scene.json (the input scene with one camera per registered photo, in
// the scene's frame, and its photos; relative paths rewritten to hold from `out`). `inputs` come
// from ValidateRegisterInputs(options).
RegisterSummary Register(const RegisterOptions& options, const RegisterInputs& inputs);

}  // namespace igi::recon
