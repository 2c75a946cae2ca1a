#include "recon/registration_refinement.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>
#include <spdlog/spdlog.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <optional>
#include <set>

#include "recon/camera.h"
#include "recon/mesh_closest_point.h"
#include "tools/common/error.h"

namespace igi::recon {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;
using Pose = std::array<double, 6>;  // angle-axis rotation, translation (cam_from_world)

// Fixed intrinsics: PINHOLE or OPENCV in COLMAP's order, zero distortion for PINHOLE.
struct Intrinsics {
  std::array<double, 8> p = {0, 0, 0, 0, 0, 0, 0, 0};
  bool distorted = false;

  explicit Intrinsics(const Camera& camera) {
    std::copy(camera.params.begin(), camera.params.end(), p.begin());
    distorted = camera.model == CameraModel::kOpenCv;
  }

  // Camera-frame point -> pixel; false behind the camera. Same model as Camera::ImgFromCam.
  template <typename T>
  bool Project(const T* x_cam, T* pixel) const {
    if (!(x_cam[2] > T(1e-12))) return false;
    T u = x_cam[0] / x_cam[2];
    T v = x_cam[1] / x_cam[2];
    if (distorted) {
      const T uu = u * u, vv = v * v, uv = u * v, r2 = uu + vv;
      const T radial = p[4] * r2 + p[5] * r2 * r2;
      const T du = u * radial + 2.0 * p[6] * uv + p[7] * (r2 + 2.0 * uu);
      const T dv = v * radial + 2.0 * p[7] * uv + p[6] * (r2 + 2.0 * vv);
      u += du;
      v += dv;
    }
    pixel[0] = p[0] * u + p[2];
    pixel[1] = p[1] * v + p[3];
    return true;
  }
};

template <typename T>
void CamFromWorld(const T* pose, const T* x_world, T* x_cam) {
  ceres::AngleAxisRotatePoint(pose, x_world, x_cam);
  for (int k = 0; k < 3; ++k) x_cam[k] += pose[3 + k];
}

// A track observation: the pose and the 3D point are free.
struct TrackCost {
  Intrinsics intrinsics;
  Vector2d pixel;
  double sigma;
  template <typename T>
  bool operator()(const T* pose, const T* point, T* residual) const {
    T x_cam[3], px[2];
    CamFromWorld(pose, point, x_cam);
    if (!intrinsics.Project(x_cam, px)) return false;
    residual[0] = (px[0] - pixel.x()) / sigma;
    residual[1] = (px[1] - pixel.y()) / sigma;
    return true;
  }
};

// A marker observation: the scene point is known.
struct MarkerCost {
  Intrinsics intrinsics;
  Vector2d pixel;
  Vector3d point;
  double sigma;
  template <typename T>
  bool operator()(const T* pose, T* residual) const {
    const T x[3] = {T(point.x()), T(point.y()), T(point.z())};
    T x_cam[3], px[2];
    CamFromWorld(pose, x, x_cam);
    if (!intrinsics.Project(x_cam, px)) return false;
    residual[0] = (px[0] - pixel.x()) / sigma;
    residual[1] = (px[1] - pixel.y()) / sigma;
    return true;
  }
};

// Distance of a point to the mesh, the closest mesh point found again at every evaluation (so a
// point near an edge is not held to the wrong face's plane). Derivative: the unit direction from
// the closest point (the face normal when the point is on the surface).
class MeshDistanceCost : public ceres::SizedCostFunction<1, 3> {
 public:
  MeshDistanceCost(const MeshClosestPoint* closest, double sigma_m)
      : closest_(closest), sigma_m_(sigma_m) {}
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const Vector3d x(parameters[0][0], parameters[0][1], parameters[0][2]);
    const auto c = closest_->Query(x);
    if (!c) return false;
    const Vector3d d = x - c->point;
    const double distance = d.norm();
    residuals[0] = distance / sigma_m_;
    if (jacobians != nullptr && jacobians[0] != nullptr) {
      const Vector3d u = distance > 1e-12 ? Vector3d(d / distance) : c->normal;
      for (int k = 0; k < 3; ++k) jacobians[0][k] = u[k] / sigma_m_;
    }
    return true;
  }

 private:
  const MeshClosestPoint* closest_;
  double sigma_m_;
};

Pose PoseOfImage(const ColmapImage& image) {
  Pose pose;
  const Eigen::Vector4d q = image.qvec.normalized();  // w, x, y, z as Ceres
  ceres::QuaternionToAngleAxis(q.data(), pose.data());
  for (int k = 0; k < 3; ++k) pose[3 + k] = image.tvec[k];
  return pose;
}

void SetImagePose(const Pose& pose, ColmapImage* image) {
  Eigen::Vector4d q;
  ceres::AngleAxisToQuaternion(pose.data(), q.data());
  image->qvec = q.normalized();
  image->tvec = Vector3d(pose[3], pose[4], pose[5]);
}

struct Sums {
  double sq = 0;
  int count = 0;
  void Add(double e2) { sq += e2, ++count; }
  double Rms() const { return count > 0 ? std::sqrt(sq / count) : 0; }
};

// Reprojection statistics of the current model (tracks of 2+ observations, markers).
struct Stats {
  std::map<uint32_t, Sums> tracks, markers;
  Sums all_tracks, all_markers;
};

Stats ComputeStats(const ColmapModel& model, const Markers* markers,
                   const std::set<std::pair<uint32_t, uint32_t>>& dropped) {
  Stats s;
  for (const auto& [id, image] : model.images) {
    const Camera camera = CameraOfImage(model, image);
    for (size_t i = 0; i < image.points2d.size(); ++i) {
      const ColmapPoint2D& p = image.points2d[i];
      if (p.point3d_id < 0 || dropped.count({id, static_cast<uint32_t>(i)}) > 0) continue;
      const auto it = model.points3d.find(static_cast<uint64_t>(p.point3d_id));
      if (it == model.points3d.end() || it->second.track.size() < 2) continue;
      const auto px = camera.ImgFromWorld(it->second.xyz);
      if (!px) continue;
      const double e2 = (*px - p.xy).squaredNorm();
      s.tracks[id].Add(e2);
      s.all_tracks.Add(e2);
    }
    if (markers == nullptr) continue;
    const auto seen = markers->pixels.find(image.name);
    if (seen == markers->pixels.end()) continue;
    for (const auto& [name, pixel] : seen->second) {
      const auto px = camera.ImgFromWorld(markers->points.at(name));
      if (!px) continue;
      const double e2 = (*px - pixel).squaredNorm();
      s.markers[id].Add(e2);
      s.all_markers.Add(e2);
    }
  }
  return s;
}

// The parameter blocks of one solve.
struct Blocks {
  std::map<uint32_t, Pose> poses;
  std::map<uint64_t, Vector3d> points;
};

// A track observation: image id, index of its 2D point.
using Observation = std::pair<uint32_t, uint32_t>;

int AddTrackTerms(const ColmapModel& model, const BundleRefinementOptions& options,
                  const std::map<uint32_t, Intrinsics>& intrinsics,
                  const std::set<Observation>& dropped, Blocks* blocks, ceres::Problem* problem) {
  int observations = 0;
  for (const auto& [point_id, point] : model.points3d) {
    // The observations with the point in front of the camera; a point needs two.
    std::vector<std::pair<uint32_t, TrackCost>> costs;
    for (const ColmapTrackElement& t : point.track) {
      if (dropped.count({t.image_id, t.point2d_idx}) > 0) continue;
      const ColmapImage& image = model.images.at(t.image_id);
      TrackCost cost{intrinsics.at(image.camera_id), image.points2d[t.point2d_idx].xy,
                     options.track_sigma_px};
      const Pose pose = PoseOfImage(image);
      double residual[2];
      if (cost(pose.data(), point.xyz.data(), residual)) costs.emplace_back(t.image_id, cost);
    }
    if (costs.size() < 2) continue;
    Vector3d& x = blocks->points.emplace(point_id, point.xyz).first->second;
    for (const auto& [image_id, cost] : costs) {
      Pose& pose =
          blocks->poses.emplace(image_id, PoseOfImage(model.images.at(image_id))).first->second;
      problem->AddResidualBlock(
          new ceres::AutoDiffCostFunction<TrackCost, 2, 6, 3>(new TrackCost(cost)),
          new ceres::HuberLoss(options.huber_sigmas), pose.data(), x.data());
      ++observations;
    }
  }
  return observations;
}

int AddMarkerTerms(const ColmapModel& model, const Markers& markers,
                   const BundleRefinementOptions& options,
                   const std::map<uint32_t, Intrinsics>& intrinsics, Blocks* blocks,
                   ceres::Problem* problem) {
  int count = 0;
  for (const auto& [id, image] : model.images) {
    const auto seen = markers.pixels.find(image.name);
    if (seen == markers.pixels.end()) continue;
    Pose& pose = blocks->poses.emplace(id, PoseOfImage(image)).first->second;
    for (const auto& [name, pixel] : seen->second) {
      MarkerCost cost{intrinsics.at(image.camera_id), pixel, markers.points.at(name),
                      options.marker_sigma_px};
      double residual[2];
      if (!cost(pose.data(), residual)) continue;
      problem->AddResidualBlock(
          new ceres::AutoDiffCostFunction<MarkerCost, 2, 6>(new MarkerCost(cost)),
          new ceres::HuberLoss(options.huber_sigmas), pose.data());
      ++count;
    }
  }
  return count;
}

// Mesh-distance terms for the points within `max_distance_m` of the mesh; returns how many and
// their RMS distance.
std::pair<int, double> AddMeshTerms(const MeshClosestPoint& closest, double sigma_m,
                                    double max_distance_m, double huber_sigmas, Blocks* blocks,
                                    ceres::Problem* problem) {
  Sums sums;
  for (auto& [id, x] : blocks->points) {
    const auto c = closest.Query(x, max_distance_m);
    if (!c) continue;
    sums.Add(c->distance_m * c->distance_m);
    problem->AddResidualBlock(new MeshDistanceCost(&closest, sigma_m),
                              new ceres::HuberLoss(huber_sigmas), x.data());
  }
  return {sums.count, sums.Rms()};
}

// Adds to `dropped` the track observations (of points with 2+ observations) that reproject
// farther than `max_error_px`; returns how many were added.
int DropOutliers(const ColmapModel& model, double max_error_px, std::set<Observation>* dropped) {
  std::map<uint32_t, Camera> cameras;
  for (const auto& [id, image] : model.images) cameras.emplace(id, CameraOfImage(model, image));
  int count = 0;
  for (const auto& [point_id, point] : model.points3d) {
    if (point.track.size() < 2) continue;
    for (const ColmapTrackElement& t : point.track) {
      const auto px = cameras.at(t.image_id).ImgFromWorld(point.xyz);
      const Vector2d& seen = model.images.at(t.image_id).points2d[t.point2d_idx].xy;
      if (px && (*px - seen).norm() <= max_error_px) continue;
      count += dropped->insert({t.image_id, t.point2d_idx}).second ? 1 : 0;
    }
  }
  return count;
}

// Removes the dropped observations from the model (as COLMAP's own filter does): their 2D
// points lose their 3D point, which leaves the track; a point left with fewer than 2
// observations is removed.
void RemoveObservations(const std::set<Observation>& dropped, ColmapModel* model) {
  for (const auto& [image_id, index] : dropped) {
    ColmapPoint2D& p = model->images.at(image_id).points2d[index];
    if (p.point3d_id < 0) continue;
    auto& track = model->points3d.at(static_cast<uint64_t>(p.point3d_id)).track;
    std::erase_if(track, [&, image_id = image_id, index = index](const ColmapTrackElement& t) {
      return t.image_id == image_id && t.point2d_idx == index;
    });
    p.point3d_id = -1;
  }
  for (auto it = model->points3d.begin(); it != model->points3d.end();) {
    if (it->second.track.size() >= 2) {
      ++it;
      continue;
    }
    for (const ColmapTrackElement& t : it->second.track) {
      model->images.at(t.image_id).points2d[t.point2d_idx].point3d_id = -1;
    }
    it = model->points3d.erase(it);
  }
}

double MeshSigma(const MeshClosestPoint& closest, const ColmapModel& model) {
  std::vector<double> d;
  for (const auto& [id, p] : model.points3d) {
    if (p.track.size() >= 2) d.push_back(closest.Query(p.xyz)->distance_m);
  }
  if (d.empty()) return 0;
  std::nth_element(d.begin(), d.begin() + static_cast<long>(d.size() / 2), d.end());
  return 1.4826 * d[d.size() / 2];
}

double MeshRms(const MeshClosestPoint& closest, const Blocks& blocks, double max_distance_m) {
  Sums sums;
  for (const auto& [id, x] : blocks.points) {
    if (const auto c = closest.Query(x, max_distance_m)) sums.Add(c->distance_m * c->distance_m);
  }
  return sums.Rms();
}

ceres::Solver::Options SolverOptions(const BundleRefinementOptions& options, size_t images) {
  ceres::Solver::Options o;
  o.linear_solver_type = images <= 500 ? ceres::DENSE_SCHUR : ceres::SPARSE_SCHUR;
  o.max_num_iterations = options.max_iterations;
  o.num_threads = std::max(1, options.threads);
  o.function_tolerance = 1e-12;
  o.gradient_tolerance = 1e-14;
  o.parameter_tolerance = 1e-12;
  o.logging_type = ceres::SILENT;
  return o;
}

void FillPerImage(const ColmapModel& model, const Stats& before, const Stats& after,
                  BundleRefinementSummary* s) {
  for (const auto& [id, image] : model.images) {
    ImageRefinement r;
    r.name = image.name;
    auto get = [id = id](const std::map<uint32_t, Sums>& m) {
      const auto it = m.find(id);
      return it == m.end() ? Sums{} : it->second;
    };
    r.observations = get(after.tracks).count;
    r.markers = get(after.markers).count;
    r.rms_before_px = get(before.tracks).Rms();
    r.rms_after_px = get(after.tracks).Rms();
    r.marker_rms_before_px = get(before.markers).Rms();
    r.marker_rms_after_px = get(after.markers).Rms();
    s->per_image.push_back(r);
  }
  std::sort(s->per_image.begin(), s->per_image.end(),
            [](const auto& a, const auto& b) { return a.name < b.name; });
}

// RMS reprojection of the markers `seen` in a photo (infinite when one is behind the camera).
double MarkerRms(const Camera& camera, const Markers& markers,
                 const std::map<std::string, Vector2d>& seen) {
  Sums sums;
  for (const auto& [name, pixel] : seen) {
    const auto px = camera.ImgFromWorld(markers.points.at(name));
    if (!px) return std::numeric_limits<double>::infinity();
    sums.Add((*px - pixel).squaredNorm());
  }
  return sums.Rms();
}

// Poses `image` (its camera from the model) from the markers it sees: PnP (SQPnP) and
// Levenberg-Marquardt with the fixed intrinsics. Returns the markers' RMS, or nullopt (image
// unchanged) when PnP fails, a marker ends behind the camera or the RMS exceeds max_rms_px.
std::optional<double> PoseFromMarkers(const ColmapModel& model, const Markers& markers,
                                      const std::map<std::string, Vector2d>& seen,
                                      double max_rms_px, ColmapImage* image) {
  const ColmapCamera& colmap_camera = model.cameras.at(image->camera_id);
  const auto converted = ConvertColmapCameraModel(colmap_camera.model, colmap_camera.params);
  if (!converted) return std::nullopt;
  const std::vector<double>& p = converted->second;
  const cv::Matx33d k(p[0], 0, p[2], 0, p[1], p[3], 0, 0, 1);
  cv::Mat dist = cv::Mat::zeros(4, 1, CV_64F);
  if (converted->first == CameraModel::kOpenCv) {
    for (int i = 0; i < 4; ++i) dist.at<double>(i) = p[4 + i];
  }
  std::vector<cv::Point3d> object;
  std::vector<cv::Point2d> pixels;
  for (const auto& [name, px] : seen) {
    const Vector3d& x = markers.points.at(name);
    object.emplace_back(x.x(), x.y(), x.z());
    pixels.emplace_back(px.x(), px.y());
  }
  cv::Mat rvec, tvec;
  if (!cv::solvePnP(object, pixels, k, dist, rvec, tvec, false, cv::SOLVEPNP_SQPNP)) {
    return std::nullopt;
  }
  cv::solvePnPRefineLM(object, pixels, k, dist, rvec, tvec);
  ColmapImage posed = *image;
  SetImagePose({rvec.at<double>(0), rvec.at<double>(1), rvec.at<double>(2), tvec.at<double>(0),
                tvec.at<double>(1), tvec.at<double>(2)},
               &posed);
  const double rms = MarkerRms(CameraOfImage(model, posed), markers, seen);
  if (!(rms <= max_rms_px)) {
    spdlog::warn("{}: pose from {} markers rejected (RMS {:.2f} px)", image->name, seen.size(),
                 rms);
    return std::nullopt;
  }
  *image = posed;
  return rms;
}

// What every solve shares.
struct Problem {
  const Markers* markers = nullptr;
  std::map<uint32_t, Intrinsics> intrinsics;
  std::optional<MeshClosestPoint> closest;  // with the mesh term
  double max_distance_m = 0;                // points farther from the mesh get no term
};

// One solve over the current model; writes the refined poses and points back. Returns false
// (model unchanged) when Ceres gives no usable solution.
bool SolveOnce(const Problem& p, const BundleRefinementOptions& options,
               const std::set<Observation>& dropped, int round, ColmapModel* model,
               BundleRefinementSummary* s) {
  Blocks blocks;
  ceres::Problem problem;
  s->observations = AddTrackTerms(*model, options, p.intrinsics, dropped, &blocks, &problem);
  if (p.markers != nullptr) {
    s->marker_observations =
        AddMarkerTerms(*model, *p.markers, options, p.intrinsics, &blocks, &problem);
  }
  if (p.closest) {
    const auto [count, rms] = AddMeshTerms(*p.closest, s->mesh_sigma_m, p.max_distance_m,
                                           options.huber_sigmas, &blocks, &problem);
    s->mesh_points = count;
    if (round == 0) s->mesh_rms_before_m = rms;
  }
  ceres::Solver::Summary summary;
  ceres::Solve(SolverOptions(options, blocks.poses.size()), &problem, &summary);
  if (round == 0) s->initial_cost = summary.initial_cost;
  s->final_cost = summary.final_cost;
  s->iterations += static_cast<int>(summary.iterations.size());
  s->termination = ceres::TerminationTypeToString(summary.termination_type);
  s->images = static_cast<int>(blocks.poses.size());
  s->points = static_cast<int>(blocks.points.size());
  if (!summary.IsSolutionUsable()) {
    spdlog::warn("joint refinement: {}; poses kept", summary.message);
    return false;
  }
  for (const auto& [id, pose] : blocks.poses) SetImagePose(pose, &model->images.at(id));
  for (const auto& [id, x] : blocks.points) model->points3d.at(id).xyz = x;
  if (p.closest) s->mesh_rms_after_m = MeshRms(*p.closest, blocks, p.max_distance_m);
  spdlog::info("joint refinement round {}: cost {:.6g} -> {:.6g} in {} iterations ({})", round + 1,
               summary.initial_cost, summary.final_cost, summary.iterations.size(), s->termination);
  return true;
}

}  // namespace

void BundleRefinementOptions::Validate() const {
  if (!(track_sigma_px > 0) || !(marker_sigma_px > 0) || !(huber_sigmas > 0) || mesh_sigma_m < 0 ||
      mesh_max_distance_m < 0 || rounds < 1 || max_iterations < 1 || threads < 0) {
    throw Error("BundleRefinementOptions: invalid values");
  }
}

BundleRefinementSummary RefineBundle(const Markers* markers, const TriangleMesh* mesh,
                                     ColmapModel* model, const BundleRefinementOptions& options) {
  options.Validate();
  const bool with_mesh = mesh != nullptr && options.use_mesh && mesh->num_triangles() > 0;
  if (markers == nullptr && !with_mesh) {
    throw Error("the joint refinement needs markers or a mesh to fix the scene's frame");
  }
  Problem p{markers, {}, std::nullopt, 0};
  for (const auto& [id, image] : model->images) {
    p.intrinsics.emplace(image.camera_id, Intrinsics(CameraOfImage(*model, image)));
  }
  BundleRefinementSummary s;
  if (with_mesh) {
    p.closest.emplace(*mesh);
    s.mesh_sigma_m =
        options.mesh_sigma_m > 0 ? options.mesh_sigma_m : MeshSigma(*p.closest, *model);
    s.mesh_sigma_m = std::max(s.mesh_sigma_m, 1e-6);
    p.max_distance_m =
        options.mesh_max_distance_m > 0 ? options.mesh_max_distance_m : 3 * s.mesh_sigma_m;
  }
  const Stats before = ComputeStats(*model, markers, {});
  std::set<Observation> dropped;
  for (int round = 0; round < options.rounds; ++round) {
    if (round > 0) {
      const int outliers = DropOutliers(*model, options.max_error_px, &dropped);
      s.outliers += outliers;
      if (outliers == 0 && !with_mesh) break;
    }
    if (!SolveOnce(p, options, dropped, round, model, &s)) break;
  }
  s.outliers += DropOutliers(*model, options.max_error_px, &dropped);
  RemoveObservations(dropped, model);
  const Stats after = ComputeStats(*model, markers, {});
  s.rms_before_px = before.all_tracks.Rms();
  s.rms_after_px = after.all_tracks.Rms();
  s.marker_rms_before_px = before.all_markers.Rms();
  s.marker_rms_after_px = after.all_markers.Rms();
  FillPerImage(*model, before, after, &s);
  return s;
}

std::vector<MarkerPose> PoseImagesFromMarkers(const Markers& markers,
                                              const std::vector<std::string>& photos,
                                              ColmapModel* model, int min_markers,
                                              double max_rms_px) {
  std::vector<MarkerPose> added;
  if (model->cameras.empty()) return added;
  const uint32_t camera_id = model->cameras.begin()->first;
  uint32_t next_id = model->images.empty() ? 1 : model->images.rbegin()->first + 1;
  for (const std::string& photo : photos) {
    const auto seen = markers.pixels.find(photo);
    if (model->FindImageByName(photo) != nullptr || seen == markers.pixels.end() ||
        static_cast<int>(seen->second.size()) < min_markers) {
      continue;
    }
    ColmapImage image;
    image.image_id = next_id;
    image.camera_id = camera_id;
    image.name = photo;
    const auto rms = PoseFromMarkers(*model, markers, seen->second, max_rms_px, &image);
    if (!rms) continue;
    model->images.emplace(next_id++, image);
    added.push_back({photo, static_cast<int>(seen->second.size()), *rms, 0});
  }
  return added;
}

std::vector<MarkerPose> RePoseImagesFromMarkers(const Markers& markers, ColmapModel* model,
                                                double disagree_px, int min_markers,
                                                double max_rms_px) {
  std::vector<MarkerPose> reposed;
  std::set<Observation> dropped;
  for (auto& [id, image] : model->images) {
    const auto seen = markers.pixels.find(image.name);
    if (seen == markers.pixels.end() || static_cast<int>(seen->second.size()) < min_markers) {
      continue;
    }
    const double before = MarkerRms(CameraOfImage(*model, image), markers, seen->second);
    if (before <= disagree_px) continue;
    ColmapImage moved = image;
    const auto rms = PoseFromMarkers(*model, markers, seen->second, max_rms_px, &moved);
    if (!rms) continue;
    spdlog::warn("{}: COLMAP's pose misses its markers by {:.1f} px RMS; posed from them",
                 image.name, before);
    image.qvec = moved.qvec;
    image.tvec = moved.tvec;
    for (size_t i = 0; i < image.points2d.size(); ++i) {
      if (image.points2d[i].point3d_id >= 0) dropped.insert({id, static_cast<uint32_t>(i)});
    }
    reposed.push_back({image.name, static_cast<int>(seen->second.size()), *rms, before});
  }
  RemoveObservations(dropped, model);
  return reposed;
}

}  // namespace igi::recon
