#include "recon/register_job.h"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "recon/camera.h"
#include "recon/colmap_model.h"
#include "recon/mesh.h"
#include "recon/mesh_alignment.h"
#include "recon/registration_refinement.h"
#include "recon/scene_document.h"
#include "tools/common/error.h"
#include "tools/common/image.h"
#include "tools/common/strings.h"

namespace igi::recon {

namespace fs = std::filesystem;

namespace {

// A marker point outside the scene's bounding box grown by 10 % of its diagonal is not a point
// of the scene (wrong units or a typo): exit 2.
void CheckMarkersInScene(const Markers& markers, const TriangleMesh& mesh,
                         const std::string& file) {
  Eigen::AlignedBox3d box;
  for (const auto& p : mesh.positions) box.extend(p.cast<double>());
  const double margin = 0.1 * box.diagonal().norm();
  box.extend(box.min() - Eigen::Vector3d::Constant(margin));
  box.extend(box.max() + Eigen::Vector3d::Constant(margin));
  ProblemList problems;
  for (const auto& [name, p] : markers.points) {
    if (!box.contains(p)) {
      problems.Add(file, "points." + name, fmt::format("[{}, {}, {}]", p.x(), p.y(), p.z()),
                   "is not in the scene (outside its geometry's bounding box)");
    }
  }
  problems.ThrowIfAny();
}

std::string Relative(const fs::path& target, const fs::path& base) {
  return fs::relative(fs::absolute(target), fs::absolute(base)).generic_string();
}

// The input scene with a camera per registered photo and its photos (lighting taken from the
// input scene's photo of the same file name, else its only lighting).
Json SceneWithCameras(const RegisterOptions& options, Json scene, const ColmapModel& model,
                      Json* report) {
  // Every relative path of the input scene (read from `from`) made to hold in the output folder.
  const fs::path from = fs::path(options.scene).parent_path();
  SceneDocument doc(std::move(scene));
  doc.RebasePaths(from.empty() ? fs::path(".") : from, options.out);
  std::map<std::string, Json> old_photos;
  if (doc.json().contains("photos")) {
    for (const auto& p : doc.json()["photos"]) {
      old_photos[fs::path(p["file"].get<std::string>()).filename().string()] = p;
    }
  }
  std::optional<std::string> only_lighting;
  if (doc.json().contains("lightings") && doc.json()["lightings"].size() == 1) {
    only_lighting = doc.json()["lightings"].begin().key();
  }
  doc.SetCameras(Json::object());
  std::vector<ScenePhotoEntry> photos;
  Json no_lighting = Json::array();
  for (const auto& [id, image] : model.images) {
    const std::string key = fs::path(image.name).stem().string();
    doc.SetCamera(key, CameraOfImage(model, image));
    ScenePhotoEntry photo{Relative(fs::path(options.images) / image.name, options.out), key, "",
                          std::nullopt};
    const auto old = old_photos.find(image.name);
    if (old != old_photos.end() && old->second.contains("lighting")) {
      photo.lighting = old->second["lighting"].get<std::string>();
      if (old->second.contains("mask") && old->second["mask"].is_string()) {
        photo.mask = old->second["mask"].get<std::string>();
      }
    } else if (only_lighting) {
      photo.lighting = *only_lighting;
    } else {
      no_lighting.push_back(image.name);
      continue;
    }
    photos.push_back(std::move(photo));
  }
  doc.SetPhotos(photos);
  (*report)["photos_without_lighting"] = no_lighting;
  return std::move(doc).json();
}

Json IntrinsicsRefinementJson(const IntrinsicsRefinementSummary& r) {
  Json adjustments = Json::array();
  for (const IntrinsicsAdjustment& a : r.adjustments) {
    Json cameras = Json::array();
    for (const CameraIntrinsicsFit& c : a.cameras) {
      cameras.push_back({{"camera_id", c.camera_id},
                         {"images", c.images},
                         {"model_before", c.model_before},
                         {"tested", c.tested},
                         {"focal_before_px", c.focal_before_px},
                         {"focal_px", c.focal_px},
                         {"focal_sigma_px", c.focal_sigma_px},
                         {"aspect", c.aspect},
                         {"aspect_sigma", c.aspect_sigma},
                         {"aspect_significance", c.aspect_significance},
                         {"principal_point_px", c.principal_point_px},
                         {"principal_point_sigma_px", c.principal_point_sigma_px},
                         {"principal_point_offset_px", c.offset_px},
                         {"principal_point_significance", c.principal_point_significance},
                         {"verdict", c.verdict}});
    }
    adjustments.push_back({{"iterations", a.iterations},
                           {"termination", a.termination},
                           {"rms_before_px", a.rms_before_px},
                           {"rms_after_px", a.rms_after_px},
                           {"covariance", a.covariance},
                           {"cameras", cameras}});
  }
  Json kept = Json::object();
  for (const auto& [id, terms] : r.kept) kept[std::to_string(id)] = terms;
  Json j = {{"mode", std::string(PrincipalPointRefinementName(r.mode))},
            {"kept", kept},
            {"images", r.images},
            {"points", r.points},
            {"observations", r.observations},
            {"adjustments", adjustments}};
  if (!r.skipped.empty()) j["skipped"] = r.skipped;
  return j;
}

// Refines the principal point and aspect ratio of the cameras COLMAP self-calibrated in this run;
// returns report.json's "intrinsics_refinement" (null when the intrinsics were known or given).
Json RefineIntrinsics(const RegisterOptions& options, ColmapRunSummary* run) {
  if (options.colmap.intrinsics || !options.colmap_model.empty()) return nullptr;
  IntrinsicsRefinementOptions refinement;
  refinement.mode = options.refine_principal_point;
  refinement.threads = options.colmap.threads;
  return IntrinsicsRefinementJson(RefineSelfCalibratedIntrinsics(&run->model, refinement));
}

Json BaseReport(const ColmapRunSummary& run, const RegisterOptions& options) {
  Json report;
  report["format"] = "igi-register-report";
  report["version"] = 1;
  report["colmap_version"] = run.version;
  report["images"] = run.images;
  report["unregistered"] = run.unregistered;
  report["models_reconstructed"] = run.num_models;
  report["known_intrinsics"] = options.colmap.intrinsics.has_value();
  if (options.colmap_model.empty()) {
    report["colmap_guided_matching"] = options.colmap.guided_matching;
    if (!options.colmap.intrinsics) {
      report["self_calibrated_model"] =
          std::string(calib::ColmapCameraModelName(options.colmap.camera_model));
    }
  }
  Json cameras = Json::array();
  for (const auto& [id, cam] : run.model.cameras) {
    cameras.push_back({{"camera_id", id}, {"model", cam.model}, {"params", cam.params}});
  }
  report["cameras"] = cameras;
  return report;
}

// report.json's "registered" (the final poses' reprojection errors; with the joint refinement
// also the markers') and "points3d".
void AddRegistered(const ColmapModel& model, const Json& alignment, Json* report) {
  std::map<std::string, Json> refined;
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
  Json registered = Json::array();
  for (const ImageReprojection& r : ReprojectionErrors(model)) {
    Json entry = {{"file", r.name},
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

Json MarkersJson(const MarkerAlignment& alignment) {
  Json a;
  a["markers_used"] = alignment.used;
  a["scale"] = alignment.scene_from_model.scale;
  a["rms_residual_m"] = alignment.rms_residual_m;
  a["rms_reprojection_px"] = alignment.rms_reprojection_px;
  Json residuals = Json::object();
  for (const auto& [name, r] : alignment.residual_m) residuals[name] = r;
  a["residual_m"] = residuals;
  return a;
}

Json MeshJson(const MeshAlignmentSummary& m) {
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

Json JointRefinementJson(const BundleRefinementSummary& b) {
  Json per_image = Json::array();
  for (const ImageRefinement& r : b.per_image) {
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
Json PoseFromMarkers(const Markers& markers, ColmapRunSummary* run) {
  Json posed = Json::array();
  for (const MarkerPose& p : PoseImagesFromMarkers(markers, run->unregistered, &run->model)) {
    posed.push_back({{"file", p.name}, {"markers", p.markers}, {"rms_px", p.rms_px}});
    std::erase(run->unregistered, p.name);
  }
  return posed;
}

// Brings the model into the scene's frame: markers (when given) for a start, then the sparse
// points fitted to the mesh (from the markers' similarity, else from principal axes), then each
// pose refined against the mesh, photos left out by COLMAP posed from markers, and last every
// pose and point refined jointly (tracks, markers, mesh). Returns report.json's "alignment".
Json AlignToScene(const RegisterOptions& options, const RegisterInputs& in, ColmapRunSummary* run) {
  ColmapModel* model = &run->model;
  Json a;
  Similarity3d sim;
  std::vector<std::string> steps;
  if (in.markers) {
    const MarkerAlignment alignment = AlignByMarkers(*model, *in.markers);
    sim = alignment.scene_from_model;
    a["markers"] = MarkersJson(alignment);
    steps.push_back("markers");
  }
  const TriangleMesh& mesh = in.loaded_scene->mesh;
  std::optional<MeshAlignmentSummary> fit;
  if (!options.no_mesh_fit) {
    const std::vector<Eigen::Vector3d> points = ModelPoints(*model);
    fit = in.markers ? AlignPointsToMesh(points, mesh, sim) : AlignPointsToMeshCoarse(points, mesh);
    sim = fit->scene_from_model;
    a["mesh"] = MeshJson(*fit);
    steps.push_back("mesh");
  }
  TransformModel(sim, model);
  a["scale"] = sim.scale;
  if (fit && !options.no_pose_refinement) {
    const PoseRefinementSummary p = RefinePosesAgainstMesh(mesh, fit->inlier_threshold_m, model);
    a["pose_refinement"] = {{"images", p.images},
                            {"points", p.points},
                            {"rounds", p.rounds},
                            {"rms_before_px", p.rms_before_px},
                            {"rms_after_px", p.rms_after_px}};
    steps.push_back("pose_refinement");
  }
  if (in.markers) {
    Json reposed = Json::array();
    for (const MarkerPose& p : RePoseImagesFromMarkers(*in.markers, model)) {
      reposed.push_back({{"file", p.name},
                         {"markers", p.markers},
                         {"rms_before_px", p.rms_before_px},
                         {"rms_px", p.rms_px}});
    }
    a["reposed_from_markers"] = reposed;
    a["posed_from_markers"] = PoseFromMarkers(*in.markers, run);
  }
  if (!options.no_joint_refinement) {
    BundleRefinementOptions refinement;
    refinement.threads = options.colmap.threads;
    refinement.use_mesh = fit.has_value();
    refinement.marker_sigma_px = options.marker_sigma_px;
    // The points' spread about the mesh after the fit (before the pose refinement snapped them).
    refinement.mesh_sigma_m =
        options.mesh_sigma_m > 0
            ? options.mesh_sigma_m
            : (fit ? fit->inlier_threshold_m / MeshAlignmentOptions{}.inlier_sigmas : 0);
    const BundleRefinementSummary b =
        RefineBundle(in.markers ? &*in.markers : nullptr, refinement.use_mesh ? &mesh : nullptr,
                     model, refinement);
    a["joint_refinement"] = JointRefinementJson(b);
    steps.push_back("joint_refinement");
  }
  a["method"] = Join(steps, "+");
  return a;
}

}  // namespace

RegisterInputs ValidateRegisterInputs(const RegisterOptions& options) {
  RegisterInputs in;
  if (!fs::is_directory(options.images)) {
    throw InputError(DescribeProblem(options.images, "--images", "", "is not a folder"));
  }
  in.images = ListColmapImages(options.images);
  if (in.images.size() < 2) {
    throw InputError(DescribeProblem(options.images, "--images",
                                     std::to_string(in.images.size()) + " photos",
                                     "registration needs at least 2 (JPEG/PNG/TIFF)"));
  }
  if (!options.colmap_model.empty() && !fs::is_directory(options.colmap_model)) {
    throw InputError(
        DescribeProblem(options.colmap_model, "--colmap-model", "", "is not a folder"));
  }
  if (options.colmap.intrinsics) {
    const KnownIntrinsics& camera = *options.colmap.intrinsics;
    ProblemList problems;
    for (const std::string& name : in.images) {
      const ImageInfo info = ReadImageInfo(fs::path(options.images) / name);
      if (info.width != camera.width || info.height != camera.height) {
        problems.Add(name, "", std::to_string(info.width) + "x" + std::to_string(info.height),
                     "differs from " + options.camera_file + "'s " + std::to_string(camera.width) +
                         "x" + std::to_string(camera.height));
      }
    }
    problems.ThrowIfAny();
  }
  if (!options.scene.empty()) {
    SceneLoadOptions load_options;
    load_options.check_images = false;
    in.loaded_scene = LoadScene(options.scene, load_options);  // validates the scene
    in.scene = ReadJsonFile(options.scene);
    if (in.loaded_scene->mesh.num_triangles() == 0 ||
        (options.markers.empty() && options.no_mesh_fit)) {
      throw InputError(DescribeProblem(
          "", "--scene", options.scene,
          "needs geometry, and --markers when the mesh is not fitted (--no-mesh-fit)"));
    }
  }
  if (!options.markers.empty()) {
    if (options.scene.empty()) {
      throw InputError(
          DescribeProblem("", "--markers", options.markers, "needs --scene (the markers' frame)"));
    }
    in.markers = ReadMarkers(options.markers);
    ProblemList problems;
    for (const auto& [photo, seen] : in.markers->pixels) {
      if (std::find(in.images.begin(), in.images.end(), photo) == in.images.end()) {
        problems.Add(options.markers, "pixels." + photo, "", "is not a photo in " + options.images);
      }
    }
    problems.ThrowIfAny();
    CheckMarkersInScene(*in.markers, in.loaded_scene->mesh, options.markers);
  }
  return in;
}

RegisterSummary Register(const RegisterOptions& options, const RegisterInputs& inputs) {
  const fs::path out(options.out);
  ColmapRunSummary run = options.colmap_model.empty()
                             ? RunColmap(options.images, out / "colmap", options.colmap)
                             : LoadColmapRun(options.images, options.colmap_model);
  const Json intrinsics = RefineIntrinsics(options, &run);
  Json alignment;
  if (inputs.scene) alignment = AlignToScene(options, inputs, &run);
  Json report = BaseReport(run, options);
  if (!intrinsics.is_null()) report["intrinsics_refinement"] = intrinsics;
  AddRegistered(run.model, alignment, &report);
  if (inputs.scene) report["alignment"] = alignment;
  WriteColmapModelText(run.model, out / "sparse");
  if (inputs.scene) {
    WriteJsonFile(out / "scene.json", SceneWithCameras(options, *inputs.scene, run.model, &report));
  }
  WriteJsonFile(out / "report.json", report);
  RegisterSummary summary;
  summary.registered = run.model.images.size();
  summary.images = run.images.size();
  summary.points = run.model.points3d.size();
  summary.unregistered = run.unregistered;
  return summary;
}

}  // namespace igi::recon
