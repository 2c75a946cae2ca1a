// igi-register: photos -> camera poses with COLMAP 3.8 (report.json, markers:
// docs/file-formats.md).
//   igi-register --images DIR [--camera camera.json] [--scene scene.json [--markers markers.json]]
//                --out DIR
// With --scene the model is brought into the scene's frame: by the markers' control points when
// given, then by fitting the sparse points to the scene mesh (robust point-to-plane ICP with
// scale; without markers from a principal-axes start), then each pose is refined against the
// mesh; photos whose COLMAP pose misses their markers by > 10 px RMS, and photos COLMAP did not
// register, are posed from their markers when they see 4+ (PnP); last,
// every pose and sparse point is refined jointly (Ceres: COLMAP's tracks, the markers'
// reprojection and the points' distance to the mesh, robust losses; recon/
// registration_refinement.h). report.json "alignment" says what was done and how well, and
// "registered" gives every photo's final reprojection RMS (tracks and markers).
// Writes DIR/sparse/ (COLMAP TXT model), DIR/report.json and, with --scene, DIR/scene.json (the
// input scene with one camera per registered photo, in the scene's frame, and its photos).
// COLMAP's own database, models and log go to DIR/colmap/ (--colmap-model: an existing model
// instead). Without --camera COLMAP self-calibrates --camera-model (default SIMPLE_RADIAL) with the
// principal point at the image centre; --refine-principal-point (auto by default) then refines
// the principal point and the aspect ratio where the photos determine them
// (recon/intrinsics_refinement.h; docs/registration.md); --guided-matching turns on COLMAP's guided
// matching (recon/colmap_runner.h: what it does). Exit 3 when some photos did not register (listed
// in report.json); exit 1 when COLMAP is missing, of another version than 3.8, or reconstructs
// nothing; exit 2 for bad input (nothing written).
#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "calib/camera_file.h"
#include "recon/colmap_runner.h"
#include "recon/register_job.h"
#include "tools/common/cli.h"
#include "tools/common/error.h"

namespace {

namespace fs = std::filesystem;

// Completes `options` from the flags that are not its fields (the camera file read into known
// intrinsics), registers, prints one line and throws PartialError (exit 3) listing the photos
// that did not register.
int Run(const std::string& camera, bool multi_camera, const igi::CommonFlags& flags,
        igi::recon::RegisterOptions* options) {
  if (!camera.empty()) {
    const igi::calib::CameraFile file = igi::calib::ReadCameraFile(camera);
    options->colmap.intrinsics =
        igi::recon::KnownIntrinsics{file.model, file.width, file.height, file.params};
    options->camera_file = camera;
  }
  options->colmap.threads = flags.threads;
  options->colmap.single_camera = !multi_camera;
  const igi::recon::RegisterInputs inputs = igi::recon::ValidateRegisterInputs(*options);
  const igi::recon::RegisterSummary run = igi::recon::Register(*options, inputs);
  std::printf("%s: %zu of %zu photos registered, %zu points\n", options->out.c_str(),
              run.registered, run.images, run.points);
  if (run.unregistered.empty()) return 0;
  std::vector<std::string> problems;
  for (const std::string& name : run.unregistered) {
    problems.push_back(igi::DescribeProblem((fs::path(options->images) / name).string(), "", "",
                                            "did not register (listed in report.json)"));
  }
  throw igi::PartialError(problems);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app("igi-register: photos -> camera poses (COLMAP 3.8), optionally in a scene's frame",
               "igi-register");
  igi::CommonFlags flags;
  igi::AddCommonFlags(app, &flags);
  igi::recon::RegisterOptions options;
  std::string camera;
  std::string camera_model = "SIMPLE_RADIAL";  // checked against kSelfCalibratedModels when parsed
  std::string refine_principal_point = "auto";
  bool multi_camera = false;
  app.add_option("--images", options.images, "Folder of photos")->required();
  app.add_option("--out", options.out, "Output folder")->required();
  app.add_option("--scene", options.scene, "scene.json whose frame the poses are brought into");
  app.add_option("--markers", options.markers, "Control points (igi-markers JSON) for --scene");
  app.add_option("--camera", camera, "camera.json: known intrinsics, held fixed");
  app.add_option("--colmap", options.colmap.executable, "COLMAP executable");
  app.add_option("--min-pose-inliers", options.colmap.min_pose_inliers,
                 "COLMAP's mapper registers a photo with this many 2D-3D inliers (>= 6)")
      ->check(CLI::Range(6, 1000000));
  app.add_option("--max-image-size", options.colmap.max_image_size,
                 "SIFT extraction downscales larger photos to this size");
  app.add_option("--max-features", options.colmap.max_features,
                 "At most this many SIFT keypoints per photo (COLMAP's default 8192; CPU "
                 "matching time grows with it)");
  app.add_option("--camera-model", camera_model,
                 "COLMAP camera model self-calibrated without --camera: SIMPLE_RADIAL "
                 "(default), RADIAL, OPENCV, PINHOLE or SIMPLE_PINHOLE")
      ->check(CLI::IsMember(igi::recon::kSelfCalibratedModels));
  app.add_option("--refine-principal-point", refine_principal_point,
                 "Without --camera, after COLMAP's mapping: refine the principal point and the "
                 "aspect ratio fy/fx, keeping each where the photos determine it (auto, default), "
                 "always (on) or never (off: COLMAP's, the principal point at the image centre)")
      ->check(CLI::IsMember({"auto", "on", "off"}));
  app.add_flag("--guided-matching", options.colmap.guided_matching,
               "COLMAP matches each photo pair again along its epipolar geometry (more correct "
               "matches, 2-2.4x the matching time)");
  app.add_flag(
      "--no-mesh-fit", options.no_mesh_fit,
      "With --scene: align by --markers only, without fitting the sparse points to the mesh");
  app.add_flag("--no-pose-refinement", options.no_pose_refinement,
               "With --scene: keep the aligned poses (no per-photo refinement against the mesh)");
  app.add_flag("--no-joint-refinement", options.no_joint_refinement,
               "With --scene: skip the final joint refinement of poses and points (tracks, "
               "markers, mesh)");
  app.add_option("--marker-sigma", options.marker_sigma_px,
                 "Accuracy of the markers' pixel positions (px), their weight in the joint "
                 "refinement")
      ->check(CLI::PositiveNumber);
  app.add_option("--mesh-sigma", options.mesh_sigma_m,
                 "Accuracy of the scene mesh (m), its weight in the joint refinement (default: "
                 "the sparse points' spread about it after the mesh fit)")
      ->check(CLI::PositiveNumber);
  app.add_option("--colmap-model", options.colmap_model,
                 "Use this COLMAP model (TXT or BIN folder) of the --images photos instead of "
                 "running COLMAP");
  app.add_flag("--multi-camera", multi_camera, "One camera per photo (default: one shared)");
  app.add_flag("--allow-other-colmap", options.colmap.allow_other_version,
               "Accept a COLMAP other than 3.8");
  return igi::RunMain(app, flags, argc, argv, [&]() -> int {
    options.colmap.camera_model = igi::calib::ColmapCameraModelFromName(camera_model).value();
    options.refine_principal_point =
        igi::recon::PrincipalPointRefinementFromName(refine_principal_point).value();
    return Run(camera, multi_camera, flags, &options);
  });
}
