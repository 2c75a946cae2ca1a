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
// instead). Without --camera COLMAP self-calibrates --camera-model (default SIMPLE_RADIAL);
// --guided-matching turns on COLMAP's guided matching (recon/colmap_runner.h: what it does). Exit 3
// when some photos did not register (listed in report.json); exit 1 when COLMAP is missing, of
// another version than 3.8, or reconstructs nothing; exit 2 for bad input (nothing written).
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <Eigen/Geometry>
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "calib/camera_file.h"
#include "recon/colmap_runner.h"
#include "recon/mesh_alignment.h"
#include "recon/registration.h"
#include "recon/registration_refinement.h"
#include "recon/scene.h"
#include "tools/common/cli.h"
#include "tools/common/error.h"
#include "tools/common/image.h"
#include "tools/common/json.h"
#include "tools/common/strings.h"

namespace fs = std::filesystem;

namespace {

struct Args {
  std::string images;
  std::string out;
  std::string scene;
  std::string camera;
  std::string markers;
  igi::ColmapRunOptions colmap;
  bool multi_camera = false;
  bool no_mesh_fit = false;
  bool no_pose_refinement = false;
  bool no_joint_refinement = false;
  double marker_sigma_px = 1.0;  // accuracy of the markers' pixels
  double mesh_sigma_m = 0;       // accuracy of the mesh; 0 = from the mesh fit's residuals
  std::string colmap_model;      // an existing COLMAP model instead of running COLMAP
};

struct Inputs {
  std::vector<std::string> images;
  std::optional<igi::calib::CameraFile> camera;
  std::optional<igi::Json> scene;
  std::optional<igi::Scene> loaded_scene;  // with its mesh
  std::optional<igi::Markers> markers;
};

// A marker point outside the scene's bounding box grown by 10 % of its diagonal is not a point
// of the scene (wrong units or a typo): exit 2.
void CheckMarkersInScene(const igi::Markers& markers, const igi::TriangleMesh& mesh,
                         const std::string& file) {
  Eigen::AlignedBox3d box;
  for (const auto& p : mesh.positions) box.extend(p.cast<double>());
  const double margin = 0.1 * box.diagonal().norm();
  box.extend(box.min() - Eigen::Vector3d::Constant(margin));
  box.extend(box.max() + Eigen::Vector3d::Constant(margin));
  igi::ProblemList problems;
  for (const auto& [name, p] : markers.points) {
    if (!box.contains(p)) {
      problems.Add(file, "points." + name, fmt::format("[{}, {}, {}]", p.x(), p.y(), p.z()),
                   "is not in the scene (outside its geometry's bounding box)");
    }
  }
  problems.ThrowIfAny();
}

// Checks every input before anything is written (exit 2 on a problem).
Inputs ValidateInputs(const Args& args) {
  Inputs in;
  if (!fs::is_directory(args.images)) {
    throw igi::InputError(igi::DescribeProblem(args.images, "--images", "", "is not a folder"));
  }
  in.images = igi::ListColmapImages(args.images);
  if (in.images.size() < 2) {
    throw igi::InputError(igi::DescribeProblem(args.images, "--images",
                                               std::to_string(in.images.size()) + " photos",
                                               "registration needs at least 2 (JPEG/PNG/TIFF)"));
  }
  if (!args.colmap_model.empty() && !fs::is_directory(args.colmap_model)) {
    throw igi::InputError(
        igi::DescribeProblem(args.colmap_model, "--colmap-model", "", "is not a folder"));
  }
  if (!args.camera.empty()) {
    in.camera = igi::calib::ReadCameraFile(args.camera);
    igi::ProblemList problems;
    for (const std::string& name : in.images) {
      const igi::ImageInfo info = igi::ReadImageInfo(fs::path(args.images) / name);
      if (info.width != in.camera->width || info.height != in.camera->height) {
        problems.Add(name, "", std::to_string(info.width) + "x" + std::to_string(info.height),
                     "differs from " + args.camera + "'s " + std::to_string(in.camera->width) +
                         "x" + std::to_string(in.camera->height));
      }
    }
    problems.ThrowIfAny();
  }
  if (!args.scene.empty()) {
    igi::SceneLoadOptions options;
    options.check_images = false;
    in.loaded_scene = igi::LoadScene(args.scene, options);  // validates the scene
    in.scene = igi::ReadJsonFile(args.scene);
    if (in.loaded_scene->mesh.num_triangles() == 0 || (args.markers.empty() && args.no_mesh_fit)) {
      throw igi::InputError(igi::DescribeProblem(
          "", "--scene", args.scene,
          "needs geometry, and --markers when the mesh is not fitted (--no-mesh-fit)"));
    }
  }
  if (!args.markers.empty()) {
    if (args.scene.empty()) {
      throw igi::InputError(igi::DescribeProblem("", "--markers", args.markers,
                                                 "needs --scene (the markers' frame)"));
    }
    in.markers = igi::ReadMarkers(args.markers);
    igi::ProblemList problems;
    for (const auto& [photo, seen] : in.markers->pixels) {
      if (std::find(in.images.begin(), in.images.end(), photo) == in.images.end()) {
        problems.Add(args.markers, "pixels." + photo, "", "is not a photo in " + args.images);
      }
    }
    problems.ThrowIfAny();
    CheckMarkersInScene(*in.markers, in.loaded_scene->mesh, args.markers);
  }
  return in;
}

std::string Relative(const fs::path& target, const fs::path& base) {
  return fs::relative(fs::absolute(target), fs::absolute(base)).generic_string();
}

// Rewrites the relative file paths of a scene read from `from` so they hold in `to`.
void RebasePaths(igi::Json* scene, const fs::path& from, const fs::path& to) {
  auto rebase = [&](igi::Json& value) {
    if (value.is_string() && fs::path(value.get<std::string>()).is_relative()) {
      value = Relative(from / value.get<std::string>(), to);
    }
  };
  if (scene->contains("geometry")) {
    for (auto& g : (*scene)["geometry"]) rebase(g["file"]);
  }
  if (scene->contains("materials")) {
    for (auto& [name, m] : (*scene)["materials"].items()) {
      if (m.contains("rho_d_map")) rebase(m["rho_d_map"]);
    }
  }
  if (scene->contains("lights")) {
    for (auto& [name, l] : (*scene)["lights"].items()) {
      if (l.contains("file")) rebase(l["file"]);
      if (l.contains("profile") && l["profile"].contains("ies")) rebase(l["profile"]["ies"]);
    }
  }
}

// The input scene with a camera per registered photo and its photos (lighting taken from the
// input scene's photo of the same file name, else its only lighting).
igi::Json SceneWithCameras(const Args& args, igi::Json scene, const igi::ColmapModel& model,
                           igi::Json* report) {
  const fs::path from = fs::path(args.scene).parent_path();
  RebasePaths(&scene, from.empty() ? fs::path(".") : from, args.out);
  std::map<std::string, igi::Json> old_photos;
  if (scene.contains("photos")) {
    for (const auto& p : scene["photos"]) {
      old_photos[fs::path(p["file"].get<std::string>()).filename().string()] = p;
    }
  }
  std::optional<std::string> only_lighting;
  if (scene.contains("lightings") && scene["lightings"].size() == 1) {
    only_lighting = scene["lightings"].begin().key();
  }
  igi::Json cameras = igi::Json::object();
  igi::Json photos = igi::Json::array();
  igi::Json no_lighting = igi::Json::array();
  for (const auto& [id, image] : model.images) {
    const igi::ColmapCamera& cam = model.cameras.at(image.camera_id);
    const igi::Camera camera = igi::CameraOfImage(model, image);
    const std::string key = fs::path(image.name).stem().string();
    cameras[key] = {{"model", std::string(igi::CameraModelName(camera.model))},
                    {"width", cam.width},
                    {"height", cam.height},
                    {"params", camera.params},
                    {"qvec", {image.qvec[0], image.qvec[1], image.qvec[2], image.qvec[3]}},
                    {"tvec", {image.tvec[0], image.tvec[1], image.tvec[2]}}};
    igi::Json photo = {{"file", Relative(fs::path(args.images) / image.name, args.out)},
                       {"camera", key}};
    const auto old = old_photos.find(image.name);
    if (old != old_photos.end() && old->second.contains("lighting")) {
      photo["lighting"] = old->second["lighting"];
      if (old->second.contains("mask")) photo["mask"] = old->second["mask"];
    } else if (only_lighting) {
      photo["lighting"] = *only_lighting;
    } else {
      no_lighting.push_back(image.name);
      continue;
    }
    photos.push_back(photo);
  }
  scene["cameras"] = cameras;
  scene["photos"] = photos;
  (*report)["photos_without_lighting"] = no_lighting;
  return scene;
}

igi::Json BaseReport(const igi::ColmapRunSummary& run, const Args& args) {
  igi::Json report;
  report["format"] = "igi-register-report";
  report["version"] = 1;
  report["colmap_version"] = run.version;
  report["images"] = run.images;
  report["unregistered"] = run.unregistered;
  report["models_reconstructed"] = run.num_models;
  report["known_intrinsics"] = !args.camera.empty();
  if (args.colmap_model.empty()) {
    report["colmap_guided_matching"] = args.colmap.guided_matching;
    if (args.camera.empty()) report["self_calibrated_model"] = args.colmap.camera_model;
  }
  igi::Json cameras = igi::Json::array();
  for (const auto& [id, cam] : run.model.cameras) {
    cameras.push_back({{"camera_id", id}, {"model", cam.model}, {"params", cam.params}});
  }
  report["cameras"] = cameras;
  return report;
}

// report.json's "registered" (the final poses' reprojection errors; with the joint refinement
// also the markers') and "points3d".
void AddRegistered(const igi::ColmapModel& model, const igi::Json& alignment, igi::Json* report) {
  std::map<std::string, igi::Json> refined;
  if (alignment.contains("joint_refinement")) {
    for (const auto& r : alignment["joint_refinement"]["per_image"]) {
      refined[r["file"].get<std::string>()] = r;
    }
  }
  std::map<std::string, std::string> posed_by;
  if (alignment.contains("posed_from_markers")) {
    for (const auto& p : alignment["posed_from_markers"]) posed_by[p["file"]] = "markers";
    for (const auto& p : alignment["reposed_from_markers"]) posed_by[p["file"]] = "markers";
  }
  igi::Json registered = igi::Json::array();
  for (const igi::ImageReprojection& r : igi::ReprojectionErrors(model)) {
    igi::Json entry = {{"file", r.name},
                       {"posed_by", posed_by.count(r.name) > 0 ? "markers" : "colmap"},
                       {"observations", r.observations},
                       {"reprojection_rms_px", r.rms_px}};
    const auto it = refined.find(r.name);
    if (it != refined.end()) {
      entry["markers"] = it->second["markers"];
      entry["marker_rms_px"] = it->second["marker_rms_after_px"];
    }
    registered.push_back(entry);
  }
  (*report)["registered"] = registered;
  (*report)["points3d"] = model.points3d.size();
}

igi::Json MarkersJson(const igi::MarkerAlignment& alignment) {
  igi::Json a;
  a["markers_used"] = alignment.used;
  a["scale"] = alignment.scene_from_model.scale;
  a["rms_residual_m"] = alignment.rms_residual_m;
  a["rms_reprojection_px"] = alignment.rms_reprojection_px;
  igi::Json residuals = igi::Json::object();
  for (const auto& [name, r] : alignment.residual_m) residuals[name] = r;
  a["residual_m"] = residuals;
  return a;
}

igi::Json MeshJson(const igi::MeshAlignmentSummary& m) {
  return {{"start", m.start},
          {"hypotheses", m.hypotheses},
          {"iterations", m.iterations},
          {"points", m.points},
          {"scale", m.scene_from_model.scale},
          {"inlier_threshold_m", m.inlier_threshold_m},
          {"inlier_fraction", m.inlier_fraction},
          {"rms_m", m.rms_m},
          {"median_m", m.median_m}};
}

igi::Json JointRefinementJson(const igi::BundleRefinementSummary& b) {
  igi::Json per_image = igi::Json::array();
  for (const igi::ImageRefinement& r : b.per_image) {
    per_image.push_back({{"file", r.name},
                         {"observations", r.observations},
                         {"markers", r.markers},
                         {"rms_before_px", r.rms_before_px},
                         {"rms_after_px", r.rms_after_px},
                         {"marker_rms_before_px", r.marker_rms_before_px},
                         {"marker_rms_after_px", r.marker_rms_after_px}});
  }
  return {{"images", b.images},
          {"points", b.points},
          {"observations", b.observations},
          {"marker_observations", b.marker_observations},
          {"mesh_points", b.mesh_points},
          {"outliers_dropped", b.outliers},
          {"mesh_sigma_m", b.mesh_sigma_m},
          {"iterations", b.iterations},
          {"initial_cost", b.initial_cost},
          {"final_cost", b.final_cost},
          {"termination", b.termination},
          {"rms_before_px", b.rms_before_px},
          {"rms_after_px", b.rms_after_px},
          {"marker_rms_before_px", b.marker_rms_before_px},
          {"marker_rms_after_px", b.marker_rms_after_px},
          {"mesh_rms_before_m", b.mesh_rms_before_m},
          {"mesh_rms_after_m", b.mesh_rms_after_m},
          {"per_image", per_image}};
}

// Photos COLMAP left out that see enough markers are posed from them (PnP) and join the model.
igi::Json PoseFromMarkers(const igi::Markers& markers, igi::ColmapRunSummary* run) {
  igi::Json posed = igi::Json::array();
  for (const igi::MarkerPose& p :
       igi::PoseImagesFromMarkers(markers, run->unregistered, &run->model)) {
    posed.push_back({{"file", p.name}, {"markers", p.markers}, {"rms_px", p.rms_px}});
    std::erase(run->unregistered, p.name);
  }
  return posed;
}

// Brings the model into the scene's frame: markers (when given) for a start, then the sparse
// points fitted to the mesh (from the markers' similarity, else from principal axes), then each
// pose refined against the mesh, photos left out by COLMAP posed from markers, and last every
// pose and point refined jointly (tracks, markers, mesh). Returns report.json's "alignment".
igi::Json AlignToScene(const Args& args, const Inputs& in, igi::ColmapRunSummary* run) {
  igi::ColmapModel* model = &run->model;
  igi::Json a;
  igi::Similarity3d sim;
  std::vector<std::string> steps;
  if (in.markers) {
    const igi::MarkerAlignment alignment = igi::AlignByMarkers(*model, *in.markers);
    sim = alignment.scene_from_model;
    a["markers"] = MarkersJson(alignment);
    steps.push_back("markers");
  }
  const igi::TriangleMesh& mesh = in.loaded_scene->mesh;
  std::optional<igi::MeshAlignmentSummary> fit;
  if (!args.no_mesh_fit) {
    const std::vector<Eigen::Vector3d> points = igi::ModelPoints(*model);
    fit = in.markers ? igi::AlignPointsToMesh(points, mesh, sim)
                     : igi::AlignPointsToMeshCoarse(points, mesh);
    sim = fit->scene_from_model;
    a["mesh"] = MeshJson(*fit);
    steps.push_back("mesh");
  }
  igi::TransformModel(sim, model);
  a["scale"] = sim.scale;
  if (fit && !args.no_pose_refinement) {
    const igi::PoseRefinementSummary p =
        igi::RefinePosesAgainstMesh(mesh, fit->inlier_threshold_m, model);
    a["pose_refinement"] = {{"images", p.images},
                            {"points", p.points},
                            {"rounds", p.rounds},
                            {"rms_before_px", p.rms_before_px},
                            {"rms_after_px", p.rms_after_px}};
    steps.push_back("pose_refinement");
  }
  if (in.markers) {
    igi::Json reposed = igi::Json::array();
    for (const igi::MarkerPose& p : igi::RePoseImagesFromMarkers(*in.markers, model)) {
      reposed.push_back({{"file", p.name},
                         {"markers", p.markers},
                         {"rms_before_px", p.rms_before_px},
                         {"rms_px", p.rms_px}});
    }
    a["reposed_from_markers"] = reposed;
    a["posed_from_markers"] = PoseFromMarkers(*in.markers, run);
  }
  if (!args.no_joint_refinement) {
    igi::BundleRefinementOptions options;
    options.threads = args.colmap.threads;
    options.use_mesh = fit.has_value();
    options.marker_sigma_px = args.marker_sigma_px;
    // The points' spread about the mesh after the fit (before the pose refinement snapped them).
    options.mesh_sigma_m =
        args.mesh_sigma_m > 0
            ? args.mesh_sigma_m
            : (fit ? fit->inlier_threshold_m / igi::MeshAlignmentOptions{}.inlier_sigmas : 0);
    const igi::BundleRefinementSummary b = igi::RefineBundle(
        in.markers ? &*in.markers : nullptr, options.use_mesh ? &mesh : nullptr, model, options);
    a["joint_refinement"] = JointRefinementJson(b);
    steps.push_back("joint_refinement");
  }
  a["method"] = igi::Join(steps, "+");
  return a;
}

int Run(Args& args, const igi::CommonFlags& flags) {
  const Inputs in = ValidateInputs(args);
  args.colmap.threads = flags.threads;
  args.colmap.single_camera = !args.multi_camera;
  if (in.camera) {
    args.colmap.intrinsics = igi::KnownIntrinsics{in.camera->model, in.camera->width,
                                                  in.camera->height, in.camera->params};
  }
  const fs::path out(args.out);
  igi::ColmapRunSummary run = args.colmap_model.empty()
                                  ? igi::RunColmap(args.images, out / "colmap", args.colmap)
                                  : igi::LoadColmapRun(args.images, args.colmap_model);
  igi::Json alignment;
  if (in.scene) alignment = AlignToScene(args, in, &run);
  igi::Json report = BaseReport(run, args);
  AddRegistered(run.model, alignment, &report);
  if (in.scene) report["alignment"] = alignment;
  igi::WriteColmapModelText(run.model, out / "sparse");
  if (in.scene) {
    igi::WriteJsonFile(out / "scene.json", SceneWithCameras(args, *in.scene, run.model, &report));
  }
  igi::WriteJsonFile(out / "report.json", report);
  std::printf("%s: %zu of %zu photos registered, %zu points\n", args.out.c_str(),
              run.model.images.size(), run.images.size(), run.model.points3d.size());
  if (run.unregistered.empty()) return 0;
  std::vector<std::string> problems;
  for (const std::string& name : run.unregistered) {
    problems.push_back(igi::DescribeProblem((fs::path(args.images) / name).string(), "", "",
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
  Args args;
  app.add_option("--images", args.images, "Folder of photos")->required();
  app.add_option("--out", args.out, "Output folder")->required();
  app.add_option("--scene", args.scene, "scene.json whose frame the poses are brought into");
  app.add_option("--markers", args.markers, "Control points (igi-markers JSON) for --scene");
  app.add_option("--camera", args.camera, "camera.json: known intrinsics, held fixed");
  app.add_option("--colmap", args.colmap.executable, "COLMAP executable");
  app.add_option("--min-pose-inliers", args.colmap.min_pose_inliers,
                 "COLMAP's mapper registers a photo with this many 2D-3D inliers (>= 6)")
      ->check(CLI::Range(6, 1000000));
  app.add_option("--max-image-size", args.colmap.max_image_size,
                 "SIFT extraction downscales larger photos to this size");
  app.add_option("--max-features", args.colmap.max_features,
                 "At most this many SIFT keypoints per photo (COLMAP's default 8192; CPU "
                 "matching time grows with it)");
  app.add_option("--camera-model", args.colmap.camera_model,
                 "COLMAP camera model self-calibrated without --camera: SIMPLE_RADIAL "
                 "(default), RADIAL, OPENCV, PINHOLE or SIMPLE_PINHOLE")
      ->check(CLI::IsMember(igi::kSelfCalibratedModels));
  app.add_flag("--guided-matching", args.colmap.guided_matching,
               "COLMAP matches each photo pair again along its epipolar geometry (more correct "
               "matches, 2-2.4x the matching time)");
  app.add_flag(
      "--no-mesh-fit", args.no_mesh_fit,
      "With --scene: align by --markers only, without fitting the sparse points to the mesh");
  app.add_flag("--no-pose-refinement", args.no_pose_refinement,
               "With --scene: keep the aligned poses (no per-photo refinement against the mesh)");
  app.add_flag("--no-joint-refinement", args.no_joint_refinement,
               "With --scene: skip the final joint refinement of poses and points (tracks, "
               "markers, mesh)");
  app.add_option("--marker-sigma", args.marker_sigma_px,
                 "Accuracy of the markers' pixel positions (px), their weight in the joint "
                 "refinement")
      ->check(CLI::PositiveNumber);
  app.add_option("--mesh-sigma", args.mesh_sigma_m,
                 "Accuracy of the scene mesh (m), its weight in the joint refinement (default: "
                 "the sparse points' spread about it after the mesh fit)")
      ->check(CLI::PositiveNumber);
  app.add_option("--colmap-model", args.colmap_model,
                 "Use this COLMAP model (TXT or BIN folder) of the --images photos instead of "
                 "running COLMAP");
  app.add_flag("--multi-camera", args.multi_camera, "One camera per photo (default: one shared)");
  app.add_flag("--allow-other-colmap", args.colmap.allow_other_version,
               "Accept a COLMAP other than 3.8");
  return igi::RunMain(app, flags, argc, argv, [&]() -> int { return Run(args, flags); });
}
