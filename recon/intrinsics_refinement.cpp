#include "recon/intrinsics_refinement.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

#include "recon/camera.h"
#include "recon/registration.h"
#include "tools/common/enum_names.h"
#include "tools/common/error.h"
#include "tools/common/strings.h"

namespace igi::recon {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;
using Pose = std::array<double, 6>;  // angle-axis rotation, translation (cam_from_world)
// f, a = fy / fx, cx, cy, k1, k2, p1, p2 (OPENCV's distortion; unused terms held at zero).
using IntrinsicsBlock = std::array<double, 8>;

constexpr EnumNames<PrincipalPointRefinement, 3> kModeNames{
    {{PrincipalPointRefinement::kOff, "off"},
     {PrincipalPointRefinement::kAuto, "auto"},
     {PrincipalPointRefinement::kOn, "on"}}};

// A track observation under free intrinsics, pose and point; the projection is Camera's
// (recon/camera.h): OPENCV's distortion of the normalised coordinates, then fx = f, fy = a f.
struct TrackCost {
  Vector2d pixel;
  double sigma;
  template <typename T>
  bool operator()(const T* k, const T* pose, const T* point, T* residual) const {
    T x[3];
    ceres::AngleAxisRotatePoint(pose, point, x);
    for (int i = 0; i < 3; ++i) x[i] += pose[3 + i];
    if (!(x[2] > T(1e-12))) return false;
    const T u = x[0] / x[2], v = x[1] / x[2];
    const T uu = u * u, vv = v * v, uv = u * v, r2 = uu + vv;
    const T radial = k[4] * r2 + k[5] * r2 * r2;
    const T ud = u + u * radial + 2.0 * k[6] * uv + k[7] * (r2 + 2.0 * uu);
    const T vd = v + v * radial + 2.0 * k[7] * uv + k[6] * (r2 + 2.0 * vv);
    residual[0] = (k[0] * ud + k[2] - pixel.x()) / sigma;
    residual[1] = (k[0] * k[1] * vd + k[3] - pixel.y()) / sigma;
    return true;
  }
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

// A camera's block as COLMAP left it, and what its model has.
struct CameraStart {
  IntrinsicsBlock block{};
  std::vector<int> held_distortion;  // of 4..7: the terms the COLMAP model lacks
  bool distorted = false;            // the model has distortion terms
  bool two_focals = false;           // the model has fx and fy (a is free, not tested)
};

std::optional<CameraStart> StartOf(const ColmapCamera& camera) {
  const auto converted = ConvertColmapCameraModel(camera.model, camera.params);
  if (!converted) return std::nullopt;
  const std::vector<double>& p = converted->second;
  CameraStart s;
  s.block = {p[0], p[1] / p[0], p[2], p[3], 0, 0, 0, 0};
  for (size_t i = 4; i < p.size(); ++i) s.block[i] = p[i];
  int free_terms = 0;  // distortion terms the COLMAP model has
  if (camera.model == "SIMPLE_RADIAL") free_terms = 1;
  if (camera.model == "RADIAL") free_terms = 2;
  if (camera.model == "OPENCV") free_terms = 4;
  s.distorted = free_terms > 0;
  s.two_focals = camera.model == "PINHOLE" || camera.model == "OPENCV";
  for (int i = 4 + free_terms; i < 8; ++i) s.held_distortion.push_back(i);
  return s;
}

// The terms under test that are free for one camera.
struct Tested {
  bool principal_point = false;
  bool aspect = false;
  bool Any() const { return principal_point || aspect; }
  bool operator==(const Tested&) const = default;
};

std::string TestedName(const Tested& t) {
  if (t.principal_point && t.aspect) return "principal_point+aspect";
  if (t.principal_point) return "principal_point";
  return t.aspect ? "aspect" : "";
}

// The problem's blocks; poses and points in maps so that their addresses stay put.
struct Blocks {
  std::map<uint32_t, IntrinsicsBlock> cameras;
  std::map<uint32_t, Pose> poses;
  std::map<uint64_t, Vector3d> points;
};

struct Built {
  int observations = 0;
  double sum_sq_px = 0;  // squared reprojection errors at the start
};

Built AddTracks(const ColmapModel& model, const IntrinsicsRefinementOptions& o, Blocks* b,
                ceres::Problem* problem) {
  Built built;
  for (const auto& [point_id, point] : model.points3d) {
    if (point.track.size() < 2) continue;
    Vector3d& x = b->points.emplace(point_id, point.xyz).first->second;
    for (const ColmapTrackElement& t : point.track) {
      const ColmapImage& image = model.images.at(t.image_id);
      IntrinsicsBlock& k = b->cameras.at(image.camera_id);
      Pose& pose = b->poses.emplace(t.image_id, PoseOfImage(image)).first->second;
      const TrackCost cost{image.points2d[t.point2d_idx].xy, o.track_sigma_px};
      double r[2];
      if (!cost(k.data(), pose.data(), x.data(), r)) continue;
      built.sum_sq_px += (r[0] * r[0] + r[1] * r[1]) * o.track_sigma_px * o.track_sigma_px;
      problem->AddResidualBlock(
          new ceres::AutoDiffCostFunction<TrackCost, 2, 8, 6, 3>(new TrackCost(cost)),
          new ceres::HuberLoss(o.huber_sigmas), k.data(), pose.data(), x.data());
      ++built.observations;
    }
  }
  return built;
}

Vector3d CentreOf(const ColmapImage& image) {
  const Eigen::Quaterniond q(image.qvec[0], image.qvec[1], image.qvec[2], image.qvec[3]);
  return -(q.normalized().conjugate() * image.tvec);
}

// Holds the gauge: the pose of the photo with the most observations, and of the photo farthest
// from it the translation coordinate that moves most with the model's scale.
void HoldGauge(const ColmapModel& model, Blocks* b, ceres::Problem* problem) {
  uint32_t first = 0;
  size_t most = 0;
  for (const auto& [id, pose] : b->poses) {
    size_t seen = 0;
    for (const ColmapPoint2D& p : model.images.at(id).points2d) seen += p.point3d_id >= 0;
    if (seen >= most) most = seen, first = id;
  }
  if (b->poses.empty()) return;
  problem->SetParameterBlockConstant(b->poses.at(first).data());
  const Vector3d origin = CentreOf(model.images.at(first));
  uint32_t second = first;
  double farthest = -1;
  for (const auto& [id, pose] : b->poses) {
    const double d = (CentreOf(model.images.at(id)) - origin).norm();
    if (id != first && d > farthest) farthest = d, second = id;
  }
  if (second == first) return;
  // Scaling the model about the first photo's centre moves the second's translation along
  // R (c - origin).
  const ColmapImage& image = model.images.at(second);
  const Eigen::Quaterniond q(image.qvec[0], image.qvec[1], image.qvec[2], image.qvec[3]);
  const Vector3d moved = q.normalized() * (CentreOf(image) - origin);
  int axis = 0;
  moved.cwiseAbs().maxCoeff(&axis);
  problem->SetManifold(b->poses.at(second).data(), new ceres::SubsetManifold(6, {3 + axis}));
}

// Holds what is not free: a camera without a tested term entirely (COLMAP's intrinsics), else
// the distortion terms its model lacks and the untested terms.
void HoldIntrinsics(const std::map<uint32_t, CameraStart>& starts,
                    const std::map<uint32_t, Tested>& tested, Blocks* b, ceres::Problem* problem) {
  for (auto& [id, block] : b->cameras) {
    if (!problem->HasParameterBlock(block.data())) continue;
    const Tested& t = tested.at(id);
    if (!t.Any()) {
      problem->SetParameterBlockConstant(block.data());
      continue;
    }
    std::vector<int> held = starts.at(id).held_distortion;
    if (!t.aspect && !starts.at(id).two_focals) held.push_back(1);
    if (!t.principal_point) held.insert(held.end(), {2, 3});
    if (!held.empty()) problem->SetManifold(block.data(), new ceres::SubsetManifold(8, held));
  }
}

// Fills each tested camera's standard deviations and significances from the intrinsics'
// covariance (scaled by `variance`); false when it cannot be computed (a rank-deficient
// Jacobian: the photos do not fix every free term).
bool AddCovariance(const IntrinsicsRefinementOptions& o, double variance, Blocks* b,
                   ceres::Problem* problem, const std::map<uint32_t, CameraStart>& starts,
                   IntrinsicsAdjustment* a) {
  ceres::Covariance::Options co;
  co.algorithm_type = ceres::SPARSE_QR;
  co.num_threads = std::max(1, o.threads);
  ceres::Covariance covariance(co);
  std::vector<std::pair<const double*, const double*>> pairs;
  for (const CameraIntrinsicsFit& fit : a->cameras) {
    const double* block = b->cameras.at(fit.camera_id).data();
    if (!fit.tested.empty() && problem->HasParameterBlock(block)) pairs.emplace_back(block, block);
  }
  if (pairs.empty()) return true;
  if (!covariance.Compute(pairs, problem)) return false;
  for (CameraIntrinsicsFit& fit : a->cameras) {
    const double* block = b->cameras.at(fit.camera_id).data();
    if (fit.tested.empty() || !problem->HasParameterBlock(block)) continue;
    Eigen::Matrix<double, 8, 8, Eigen::RowMajor> c;
    if (!covariance.GetCovarianceBlock(block, block, c.data())) return false;
    c *= variance;
    fit.focal_sigma_px = std::sqrt(std::max(0.0, c(0, 0)));
    const Eigen::Vector2d offset(fit.offset_px[0], fit.offset_px[1]);
    const Eigen::Matrix2d pp = c.block<2, 2>(2, 2);
    fit.principal_point_sigma_px = {std::sqrt(std::max(0.0, pp(0, 0))),
                                    std::sqrt(std::max(0.0, pp(1, 1)))};
    if (pp.determinant() > 0) {
      fit.principal_point_significance = std::sqrt(offset.dot(pp.inverse() * offset));
    }
    if (c(1, 1) > 0 && !starts.at(fit.camera_id).two_focals) {
      fit.aspect_sigma = std::sqrt(c(1, 1));
      fit.aspect_significance =
          std::abs(fit.aspect - starts.at(fit.camera_id).block[1]) / fit.aspect_sigma;
    }
  }
  return true;
}

// The terms of `fit`'s camera that pass kAuto's tests (a subset of `tested`); sets the verdict.
Tested Passing(const IntrinsicsRefinementOptions& o, const ColmapCamera& camera, bool covariance,
               const Tested& tested, CameraIntrinsicsFit* fit) {
  Tested pass = tested;
  std::vector<std::string> why;
  if (tested.principal_point) {
    if (!covariance) {
      why.push_back("principal point not determined (rank-deficient)");
    } else if (fit->principal_point_significance < o.min_significance) {
      why.push_back(
          fmt::format("principal point {:.1f}, {:.1f} px from the centre is {:.1f} "
                      "standard deviations (< {:g})",
                      fit->offset_px[0], fit->offset_px[1], fit->principal_point_significance,
                      o.min_significance));
    } else if (std::abs(fit->offset_px[0]) > o.max_principal_point_offset * camera.width ||
               std::abs(fit->offset_px[1]) > o.max_principal_point_offset * camera.height) {
      why.push_back(
          fmt::format("principal point {:.1f}, {:.1f} px from the centre (more than "
                      "{:g} of the image size)",
                      fit->offset_px[0], fit->offset_px[1], o.max_principal_point_offset));
    }
    pass.principal_point = why.empty();
  }
  if (tested.aspect) {
    const size_t before = why.size();
    if (!covariance) {
      why.push_back("aspect ratio not determined (rank-deficient)");
    } else if (fit->aspect_significance < o.min_significance) {
      why.push_back(fmt::format("aspect ratio {:.5f} is {:.1f} standard deviations from 1 (< {:g})",
                                fit->aspect, fit->aspect_significance, o.min_significance));
    } else if (std::abs(fit->aspect - 1) > o.max_aspect_offset) {
      why.push_back(
          fmt::format("aspect ratio {:.4f} beyond 1 ± {:g}", fit->aspect, o.max_aspect_offset));
    }
    pass.aspect = why.size() == before;
  }
  fit->verdict = why.empty() ? "kept" : Join(why, "; ");
  return pass;
}

// Writes an adjustment's blocks into `model`: the poses, the points and the intrinsics of the
// cameras with a tested term.
void WriteBack(const Blocks& b, const std::map<uint32_t, CameraStart>& starts,
               const std::map<uint32_t, Tested>& tested, ColmapModel* model) {
  for (const auto& [id, k] : b.cameras) {
    if (!tested.at(id).Any()) continue;
    ColmapCamera& camera = model->cameras.at(id);
    camera.model = starts.at(id).distorted ? "OPENCV" : "PINHOLE";
    camera.params = {k[0], k[0] * k[1], k[2], k[3]};
    if (starts.at(id).distorted) camera.params.insert(camera.params.end(), k.begin() + 4, k.end());
  }
  for (const auto& [id, pose] : b.poses) SetImagePose(pose, &model->images.at(id));
  for (const auto& [id, x] : b.points) model->points3d.at(id).xyz = x;
}

double RmsReprojection(const ColmapModel& model) {
  double sq = 0;
  int n = 0;
  for (const ImageReprojection& e : ReprojectionErrors(model)) {
    sq += e.rms_px * e.rms_px * e.observations;
    n += e.observations;
  }
  return std::sqrt(sq / std::max(1, n));
}

// Each camera's intrinsics after an adjustment (before their covariance).
std::vector<CameraIntrinsicsFit> FitsOf(const ColmapModel& model,
                                        const std::map<uint32_t, CameraStart>& starts,
                                        const std::map<uint32_t, Tested>& tested, const Blocks& b) {
  std::vector<CameraIntrinsicsFit> fits;
  for (const auto& [id, k] : b.cameras) {
    const ColmapCamera& camera = model.cameras.at(id);
    CameraIntrinsicsFit fit;
    fit.camera_id = id;
    for (const auto& [image_id, pose] : b.poses) {
      fit.images += model.images.at(image_id).camera_id == id ? 1 : 0;
    }
    fit.model_before = camera.model;
    fit.tested = TestedName(tested.at(id));
    fit.focal_before_px = starts.at(id).block[0];
    fit.focal_px = k[0];
    fit.aspect = k[1];
    fit.principal_point_px = {k[2], k[3]};
    fit.offset_px = {k[2] - 0.5 * camera.width, k[3] - 0.5 * camera.height};
    fits.push_back(fit);
  }
  return fits;
}

// One adjustment of `model` with the `tested` terms free; `adjusted` gets the result (unset when
// Ceres gives no usable solution).
IntrinsicsAdjustment Adjust(const ColmapModel& model, const std::map<uint32_t, CameraStart>& starts,
                            const std::map<uint32_t, Tested>& tested,
                            const IntrinsicsRefinementOptions& o,
                            IntrinsicsRefinementSummary* summary,
                            std::optional<ColmapModel>* adjusted) {
  IntrinsicsAdjustment a;
  Blocks b;
  for (const auto& [id, start] : starts) b.cameras.emplace(id, start.block);
  ceres::Problem problem;
  const Built built = AddTracks(model, o, &b, &problem);
  HoldGauge(model, &b, &problem);
  HoldIntrinsics(starts, tested, &b, &problem);
  summary->images = static_cast<int>(b.poses.size());
  summary->points = static_cast<int>(b.points.size());
  summary->observations = built.observations;
  ceres::Solver::Options so;
  so.linear_solver_type = b.poses.size() <= 500 ? ceres::DENSE_SCHUR : ceres::SPARSE_SCHUR;
  so.max_num_iterations = o.max_iterations;
  so.num_threads = std::max(1, o.threads);
  so.function_tolerance = 1e-10;
  so.logging_type = ceres::SILENT;
  ceres::Solver::Summary s;
  ceres::Solve(so, &problem, &s);
  a.iterations = static_cast<int>(s.iterations.size());
  a.termination = ceres::TerminationTypeToString(s.termination_type);
  a.rms_before_px = std::sqrt(built.sum_sq_px / std::max(1, built.observations));
  if (!s.IsSolutionUsable()) {
    a.termination += ": " + s.message;
    return a;
  }
  adjusted->emplace(model);
  WriteBack(b, starts, tested, &**adjusted);
  a.rms_after_px = RmsReprojection(**adjusted);
  a.cameras = FitsOf(model, starts, tested, b);
  // The residuals' variance per unit weight (Huber-weighted, as the Jacobian is).
  const int dof = s.num_residuals_reduced - s.num_effective_parameters_reduced;
  const double variance = dof > 0 ? 2 * s.final_cost / dof : 1.0;
  a.covariance = AddCovariance(o, variance, &b, &problem, starts, &a);
  return a;
}

}  // namespace

std::string_view PrincipalPointRefinementName(PrincipalPointRefinement mode) {
  return kModeNames.Name(mode);
}

std::optional<PrincipalPointRefinement> PrincipalPointRefinementFromName(std::string_view name) {
  return kModeNames.FromName(name);
}

void IntrinsicsRefinementOptions::Validate() const {
  ProblemList problems;
  auto positive = [&](double v, const char* name) {
    if (!(v > 0)) problems.Add("", name, fmt::format("{}", v), "must be > 0");
  };
  positive(min_significance, "min_significance");
  positive(track_sigma_px, "track_sigma_px");
  positive(huber_sigmas, "huber_sigmas");
  if (!(max_principal_point_offset > 0 && max_principal_point_offset <= 0.5)) {
    problems.Add("", "max_principal_point_offset", fmt::format("{}", max_principal_point_offset),
                 "must be in (0, 0.5]");
  }
  if (!(max_aspect_offset > 0 && max_aspect_offset < 1)) {
    problems.Add("", "max_aspect_offset", fmt::format("{}", max_aspect_offset),
                 "must be in (0, 1)");
  }
  if (max_iterations < 1) {
    problems.Add("", "max_iterations", std::to_string(max_iterations), "must be >= 1");
  }
  problems.ThrowIfAny();
}

std::string IntrinsicsRefinementSummary::KeptFor(uint32_t camera_id) const {
  for (const auto& [id, terms] : kept) {
    if (id == camera_id) return terms;
  }
  return "none";
}

IntrinsicsRefinementSummary RefineSelfCalibratedIntrinsics(
    ColmapModel* model, const IntrinsicsRefinementOptions& options) {
  options.Validate();
  IntrinsicsRefinementSummary summary;
  summary.mode = options.mode;
  if (options.mode == PrincipalPointRefinement::kOff) return summary;
  std::map<uint32_t, CameraStart> starts;
  std::map<uint32_t, Tested> tested;
  for (const auto& [id, image] : model->images) {
    const ColmapCamera& camera = model->cameras.at(image.camera_id);
    const std::optional<CameraStart> start = StartOf(camera);
    if (!start) {
      summary.skipped = "camera model " + camera.model + " is not refined";
      return summary;
    }
    starts.emplace(image.camera_id, *start);
    tested[image.camera_id] = {true, !start->two_focals};
  }
  if (model->images.size() < 2) {
    summary.skipped = "fewer than 2 registered photos";
    return summary;
  }
  // Each round holds the terms the last one could not keep; a camera loses a term per round, so
  // this ends after at most 2 rounds per camera and one more.
  while (std::any_of(tested.begin(), tested.end(), [](const auto& t) { return t.second.Any(); })) {
    std::optional<ColmapModel> adjusted;
    IntrinsicsAdjustment a = Adjust(*model, starts, tested, options, &summary, &adjusted);
    if (!adjusted) {
      spdlog::warn("intrinsics refinement: {}; COLMAP's intrinsics kept", a.termination);
      summary.adjustments.push_back(std::move(a));
      break;
    }
    std::map<uint32_t, Tested> passing;
    for (CameraIntrinsicsFit& fit : a.cameras) {
      const Tested& t = tested.at(fit.camera_id);
      passing[fit.camera_id] =
          options.mode == PrincipalPointRefinement::kOn
              ? t
              : Passing(options, model->cameras.at(fit.camera_id), a.covariance, t, &fit);
      if (options.mode == PrincipalPointRefinement::kOn && t.Any()) fit.verdict = "kept";
      spdlog::info("intrinsics refinement, camera {} ({}): {}", fit.camera_id, fit.tested,
                   fit.verdict);
    }
    summary.adjustments.push_back(std::move(a));
    if (passing == tested) {
      *model = std::move(*adjusted);
      for (const auto& [id, t] : tested) {
        summary.kept.emplace_back(id, t.Any() ? TestedName(t) : "none");
      }
      break;
    }
    tested = std::move(passing);
  }
  return summary;
}

}  // namespace igi::recon
