#include "recon/mesh_alignment.h"

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>
#include <random>

#include "recon/camera.h"
#include "recon/mesh_closest_point.h"
#include "tools/common/error.h"
#include "tools/common/parallel.h"

namespace igi::recon {
namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;

constexpr double kHuber = 1.345;   // Huber constant, in robust sigmas
constexpr double kMad = 1.4826;    // median absolute deviation -> sigma (Gaussian)
constexpr double kDamping = 1e-9;  // relative Levenberg damping of the ICP normal equations

struct Match {
  Vector3d q;       // moved point
  Vector3d target;  // closest mesh point
  Vector3d normal;
  double distance = 0;
};

double Median(std::vector<double> v) {
  if (v.empty()) return 0;
  const size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<long>(mid), v.end());
  return v[mid];
}

double Quantile(std::vector<double> v, double fraction) {
  if (v.empty()) return 0;
  const size_t k = std::min(v.size() - 1, static_cast<size_t>(fraction * (v.size() - 1) + 0.5));
  std::nth_element(v.begin(), v.begin() + static_cast<long>(k), v.end());
  return v[k];
}

std::vector<Match> MatchPoints(const std::vector<Vector3d>& points, const Similarity3d& sim,
                               const MeshClosestPoint& closest) {
  std::vector<Match> matches(points.size());
  ParallelFor(0, static_cast<int64_t>(points.size()), [&](int64_t i) {
    Match& m = matches[static_cast<size_t>(i)];
    m.q = sim * points[static_cast<size_t>(i)];
    const auto c = closest.Query(m.q);
    m.target = c->point;
    m.normal = c->normal;
    m.distance = c->distance_m;
  });
  return matches;
}

std::vector<double> Distances(const std::vector<Match>& matches) {
  std::vector<double> d;
  d.reserve(matches.size());
  for (const Match& m : matches) d.push_back(m.distance);
  return d;
}

Matrix3d Skew(const Vector3d& w) {
  Matrix3d s;
  s << 0, -w.z(), w.y(), w.z(), 0, -w.x(), -w.y(), w.x(), 0;
  return s;
}

Matrix3d ExpSo3(const Vector3d& w) {
  const double angle = w.norm();
  if (angle < 1e-15) return Matrix3d::Identity() + Skew(w);
  return Eigen::AngleAxisd(angle, w / angle).toRotationMatrix();
}

// One robust point-to-plane step; returns the size of the update.
double IcpStep(const std::vector<Match>& matches, double trim_fraction, double extent_m,
               Similarity3d* sim) {
  const double cut = Quantile(Distances(matches), trim_fraction);
  std::vector<double> abs_r;
  Vector3d centroid = Vector3d::Zero();
  int kept = 0;
  for (const Match& m : matches) {
    if (m.distance > cut) continue;
    abs_r.push_back(std::abs(m.normal.dot(m.q - m.target)));
    centroid += m.q;
    ++kept;
  }
  if (kept < 7) return 0;
  centroid /= kept;
  const double sigma = std::max(kMad * Median(abs_r), 1e-12 * extent_m);
  Eigen::Matrix<double, 7, 7> a = Eigen::Matrix<double, 7, 7>::Zero();
  Eigen::Matrix<double, 7, 1> b = Eigen::Matrix<double, 7, 1>::Zero();
  for (const Match& m : matches) {
    if (m.distance > cut) continue;
    const Vector3d d = m.q - centroid;
    const double r = m.normal.dot(m.q - m.target);
    const double w = std::abs(r) <= kHuber * sigma ? 1.0 : kHuber * sigma / std::abs(r);
    Eigen::Matrix<double, 7, 1> j;
    j << d.cross(m.normal), m.normal, m.normal.dot(d);
    a += w * j * j.transpose();
    b -= w * r * j;
  }
  a.diagonal() += kDamping * a.diagonal().cwiseMax(1e-30);
  const Eigen::Matrix<double, 7, 1> x = a.ldlt().solve(b);
  if (!x.allFinite()) return 0;
  const Matrix3d dr = ExpSo3(x.head<3>());
  const double ds = std::exp(x[6]);
  // q' = centroid + ds * dR (q - centroid) + dt, composed with the current similarity.
  sim->scale *= ds;
  sim->rotation = Eigen::Quaterniond(dr * sim->rotation.toRotationMatrix()).normalized();
  sim->translation = centroid + ds * (dr * (sim->translation - centroid)) + x.segment<3>(3);
  return std::max({x.head<3>().norm(), std::abs(x[6]), x.segment<3>(3).norm() / extent_m});
}

double MeshExtent(const TriangleMesh& mesh) {
  Eigen::AlignedBox3d box;
  for (const auto& p : mesh.positions) box.extend(p.cast<double>());
  return std::max(box.diagonal().norm(), 1e-9);
}

struct IcpResult {
  Similarity3d sim;
  int iterations = 0;
};

IcpResult RunIcp(const std::vector<Vector3d>& points, const MeshClosestPoint& closest,
                 const Similarity3d& start, int iterations, double extent_m,
                 const MeshAlignmentOptions& options) {
  IcpResult result{start, 0};
  for (int it = 0; it < iterations; ++it) {
    const std::vector<Match> matches = MatchPoints(points, result.sim, closest);
    const double step = IcpStep(matches, options.trim_fraction, extent_m, &result.sim);
    result.iterations = it + 1;
    if (step < options.tolerance) break;
  }
  return result;
}

void Summarise(const std::vector<Vector3d>& points, const MeshClosestPoint& closest,
               const MeshAlignmentOptions& options, MeshAlignmentSummary* s) {
  const std::vector<double> d = Distances(MatchPoints(points, s->scene_from_model, closest));
  s->points = points.size();
  s->median_m = Median(d);
  s->inlier_threshold_m = options.inlier_sigmas * kMad * s->median_m;
  double sum_sq = 0;
  size_t inliers = 0;
  for (double x : d) {
    if (x > s->inlier_threshold_m) continue;
    sum_sq += x * x;
    ++inliers;
  }
  s->inlier_fraction = points.empty() ? 0 : static_cast<double>(inliers) / points.size();
  s->rms_m = inliers > 0 ? std::sqrt(sum_sq / static_cast<double>(inliers)) : 0;
}

// Area-uniform samples of the mesh surface.
std::vector<Vector3d> SampleMesh(const TriangleMesh& mesh, size_t count) {
  std::vector<double> cdf;
  double total = 0;
  for (size_t t = 0; t < mesh.num_triangles(); ++t) cdf.push_back(total += mesh.TriangleArea(t));
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<Vector3d> samples;
  for (size_t i = 0; i < count; ++i) {
    const size_t t =
        static_cast<size_t>(std::lower_bound(cdf.begin(), cdf.end(), u(rng) * total) - cdf.begin());
    const Eigen::Vector3i& tri = mesh.triangles[std::min(t, mesh.num_triangles() - 1)];
    double a = u(rng), b = u(rng);
    if (a + b > 1) a = 1 - a, b = 1 - b;
    const Vector3d p0 = mesh.positions[tri[0]].cast<double>();
    samples.push_back(p0 + a * (mesh.positions[tri[1]].cast<double>() - p0) +
                      b * (mesh.positions[tri[2]].cast<double>() - p0));
  }
  return samples;
}

struct Frame {
  Vector3d centroid;
  Matrix3d axes;  // columns: principal axes, largest variance first, right-handed
  double spread;  // sqrt of the total variance
};

Frame PrincipalFrame(const std::vector<Vector3d>& points) {
  Frame f;
  f.centroid = Vector3d::Zero();
  for (const Vector3d& p : points) f.centroid += p;
  f.centroid /= static_cast<double>(points.size());
  Matrix3d cov = Matrix3d::Zero();
  for (const Vector3d& p : points) cov += (p - f.centroid) * (p - f.centroid).transpose();
  cov /= static_cast<double>(points.size());
  Eigen::SelfAdjointEigenSolver<Matrix3d> eig(cov);
  f.axes = eig.eigenvectors().rowwise().reverse();
  if (f.axes.determinant() < 0) f.axes.col(2) *= -1;
  f.spread = std::sqrt(std::max(cov.trace(), 1e-30));
  return f;
}

// The 24 rotations that map coordinate axes to coordinate axes.
std::vector<Matrix3d> AxisRotations() {
  std::vector<Matrix3d> out;
  const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (const auto& p : perms) {
    for (int signs = 0; signs < 8; ++signs) {
      Matrix3d m = Matrix3d::Zero();
      for (int r = 0; r < 3; ++r) m(r, p[r]) = (signs >> r) & 1 ? -1 : 1;
      if (m.determinant() > 0) out.push_back(m);
    }
  }
  return out;
}

// The points without gross outliers (beyond 3x the median distance from the median).
std::vector<Vector3d> WithoutOutliers(const std::vector<Vector3d>& points) {
  Vector3d median;
  for (int k = 0; k < 3; ++k) {
    std::vector<double> c;
    for (const Vector3d& p : points) c.push_back(p[k]);
    median[k] = Median(c);
  }
  std::vector<double> d;
  for (const Vector3d& p : points) d.push_back((p - median).norm());
  const double cut = 3 * Median(d);
  std::vector<Vector3d> kept;
  for (const Vector3d& p : points) {
    if ((p - median).norm() <= cut) kept.push_back(p);
  }
  return kept;
}

std::vector<Vector3d> Subsample(const std::vector<Vector3d>& points, int count) {
  if (static_cast<int>(points.size()) <= count) return points;
  std::vector<Vector3d> out;
  const double step = static_cast<double>(points.size()) / count;
  for (int i = 0; i < count; ++i) out.push_back(points[static_cast<size_t>(i * step)]);
  return out;
}

double ReprojectionSumSq(const Camera& camera, const std::vector<Eigen::Vector2d>& pixels,
                         const std::vector<Vector3d>& world) {
  double sum = 0;
  for (size_t i = 0; i < pixels.size(); ++i) {
    const auto p = camera.ImgFromWorld(world[i]);
    sum += p ? (*p - pixels[i]).squaredNorm() : 0;
  }
  return sum;
}

// Residuals (2 per point; 0 behind the camera) of a pose perturbed by (rotation w, translation).
Eigen::VectorXd PoseResiduals(const Camera& camera, const Eigen::Matrix<double, 6, 1>& delta,
                              const std::vector<Eigen::Vector2d>& pixels,
                              const std::vector<Vector3d>& world) {
  const Matrix3d r = ExpSo3(delta.head<3>()) * camera.cam_from_world.rotation.toRotationMatrix();
  const Vector3d t = camera.cam_from_world.translation + delta.tail<3>();
  Eigen::VectorXd res = Eigen::VectorXd::Zero(2 * static_cast<Eigen::Index>(pixels.size()));
  for (size_t i = 0; i < pixels.size(); ++i) {
    const auto p = camera.ImgFromCam(r * world[i] + t);
    if (p) res.segment<2>(2 * static_cast<Eigen::Index>(i)) = *p - pixels[i];
  }
  return res;
}

// Gauss-Newton with Huber weights (2 px) and a numeric Jacobian on the 6 pose parameters.
void RefinePose(const std::vector<Eigen::Vector2d>& pixels, const std::vector<Vector3d>& world,
                Camera* camera) {
  constexpr double kHuberPx = 2.0;
  constexpr double kStep = 1e-7;
  for (int it = 0; it < 10; ++it) {
    const Eigen::Matrix<double, 6, 1> zero = Eigen::Matrix<double, 6, 1>::Zero();
    const Eigen::VectorXd r0 = PoseResiduals(*camera, zero, pixels, world);
    Eigen::MatrixXd j(r0.size(), 6);
    for (int k = 0; k < 6; ++k) {
      Eigen::Matrix<double, 6, 1> d = zero;
      d[k] = kStep;
      j.col(k) =
          (PoseResiduals(*camera, d, pixels, world) - PoseResiduals(*camera, -d, pixels, world)) /
          (2 * kStep);
    }
    Eigen::VectorXd w(r0.size());
    for (Eigen::Index i = 0; i < r0.size(); i += 2) {
      const double e = r0.segment<2>(i).norm();
      w.segment<2>(i).setConstant(e <= kHuberPx ? 1.0 : kHuberPx / e);
    }
    const Eigen::Matrix<double, 6, 6> a = j.transpose() * w.asDiagonal() * j;
    const Eigen::Matrix<double, 6, 1> x = a.ldlt().solve(-(j.transpose() * w.asDiagonal() * r0));
    if (!x.allFinite()) return;
    const Matrix3d r = ExpSo3(x.head<3>()) * camera->cam_from_world.rotation.toRotationMatrix();
    camera->cam_from_world = Rigid3d(Eigen::Quaterniond(r).normalized(),
                                     camera->cam_from_world.translation + x.tail<3>());
    if (x.norm() < 1e-12) break;
  }
}

// The image's observations of snapped points: pixels and world points.
void SnappedObservations(const ColmapImage& image, const std::map<uint64_t, Vector3d>& snapped,
                         std::vector<Eigen::Vector2d>* pixels, std::vector<Vector3d>* world) {
  for (const ColmapPoint2D& p : image.points2d) {
    if (p.point3d_id < 0) continue;
    const auto it = snapped.find(static_cast<uint64_t>(p.point3d_id));
    if (it == snapped.end()) continue;
    pixels->push_back(p.xy);
    world->push_back(it->second);
  }
}

double SnappedReprojectionRms(const ColmapModel& model,
                              const std::map<uint64_t, Vector3d>& snapped) {
  double sum_sq = 0;
  size_t count = 0;
  for (const auto& [id, image] : model.images) {
    std::vector<Eigen::Vector2d> pixels;
    std::vector<Vector3d> world;
    SnappedObservations(image, snapped, &pixels, &world);
    sum_sq += ReprojectionSumSq(CameraOfImage(model, image), pixels, world);
    count += pixels.size();
  }
  return count > 0 ? std::sqrt(sum_sq / static_cast<double>(count)) : 0;
}

// Each pose alone against the snapped points; returns how many were refined.
int RefineEveryPose(const std::map<uint64_t, Vector3d>& snapped, ColmapModel* model) {
  int refined = 0;
  for (auto& [id, image] : model->images) {
    std::vector<Eigen::Vector2d> pixels;
    std::vector<Vector3d> world;
    SnappedObservations(image, snapped, &pixels, &world);
    if (pixels.size() < 6) continue;
    Camera camera = CameraOfImage(*model, image);
    const double before = ReprojectionSumSq(camera, pixels, world);
    RefinePose(pixels, world, &camera);
    ++refined;
    if (!(ReprojectionSumSq(camera, pixels, world) <= before)) continue;  // keep the better pose
    image.qvec = QvecFromQuaternion(camera.cam_from_world.rotation.normalized());
    image.tvec = camera.cam_from_world.translation;
  }
  return refined;
}

// Every snapped point triangulated again from the current poses (least squares over its rays)
// and snapped to the mesh; points that leave the mesh's neighbourhood are dropped.
void Resnap(const ColmapModel& model, const MeshClosestPoint& closest, double threshold_m,
            std::map<uint64_t, Vector3d>* snapped) {
  std::map<uint32_t, Camera> cameras;
  for (const auto& [id, image] : model.images) cameras.emplace(id, CameraOfImage(model, image));
  for (auto it = snapped->begin(); it != snapped->end();) {
    if (model.points3d.at(it->first).track.size() < 2) {  // nothing to triangulate from
      ++it;
      continue;
    }
    Matrix3d a = Matrix3d::Zero();
    Vector3d b = Vector3d::Zero();
    for (const ColmapTrackElement& t : model.points3d.at(it->first).track) {
      const Camera& camera = cameras.at(t.image_id);
      const Vector3d d =
          camera.WorldRayFromImg(model.images.at(t.image_id).points2d[t.point2d_idx].xy);
      const Matrix3d p = Matrix3d::Identity() - d * d.transpose();
      a += p;
      b += p * camera.CenterInWorld();
    }
    const Vector3d x = a.ldlt().solve(b);
    const auto c = x.allFinite() ? closest.Query(x, threshold_m) : std::nullopt;
    if (c) {
      it->second = c->point;
      ++it;
    } else {
      it = snapped->erase(it);
    }
  }
}

}  // namespace

void MeshAlignmentOptions::Validate() const {
  if (max_iterations < 1 || coarse_iterations < 1 || coarse_sample < 10 || random_hypotheses < 0 ||
      !(trim_fraction > 0) || trim_fraction > 1 || !(tolerance > 0) || !(inlier_sigmas > 0)) {
    throw Error("MeshAlignmentOptions: invalid values");
  }
}

MeshAlignmentSummary AlignPointsToMesh(const std::vector<Vector3d>& points_model,
                                       const TriangleMesh& mesh, const Similarity3d& start,
                                       const MeshAlignmentOptions& options) {
  options.Validate();
  if (points_model.size() < 10 || mesh.num_triangles() == 0) {
    throw Error("fitting to the mesh needs at least 10 points and a mesh (" +
                std::to_string(points_model.size()) + " points)");
  }
  const MeshClosestPoint closest(mesh);
  const IcpResult icp =
      RunIcp(points_model, closest, start, options.max_iterations, MeshExtent(mesh), options);
  MeshAlignmentSummary s;
  s.scene_from_model = icp.sim;
  s.start = "given";
  s.iterations = icp.iterations;
  Summarise(points_model, closest, options, &s);
  return s;
}

MeshAlignmentSummary AlignPointsToMeshCoarse(const std::vector<Vector3d>& points_model,
                                             const TriangleMesh& mesh,
                                             const MeshAlignmentOptions& options) {
  options.Validate();
  const std::vector<Vector3d> kept = WithoutOutliers(points_model);
  if (kept.size() < 10 || mesh.num_triangles() == 0) {
    throw Error("fitting to the mesh needs at least 10 points and a mesh (" +
                std::to_string(kept.size()) + " points)");
  }
  const MeshClosestPoint closest(mesh);
  const double extent = MeshExtent(mesh);
  const Frame from = PrincipalFrame(kept);
  const Frame to = PrincipalFrame(SampleMesh(mesh, 20000));
  const std::vector<Vector3d> sample = Subsample(kept, options.coarse_sample);
  // Rotation hypotheses: the 24 that map principal axes onto principal axes, then random ones
  // (the principal axes of a partial reconstruction can be far from the mesh's).
  std::vector<Matrix3d> rotations;
  for (const Matrix3d& flip : AxisRotations()) {
    rotations.push_back(to.axes * flip * from.axes.transpose());
  }
  std::mt19937_64 rng(11);
  std::normal_distribution<double> n(0, 1);
  for (int i = 0; i < options.random_hypotheses; ++i) {
    rotations.push_back(Eigen::Quaterniond(n(rng), n(rng), n(rng), n(rng)).normalized().matrix());
  }
  double best_score = -1;
  Similarity3d best;
  for (const Matrix3d& r : rotations) {
    Similarity3d sim;
    sim.scale = to.spread / from.spread;
    sim.rotation = Eigen::Quaterniond(r);
    sim.translation = to.centroid - sim.scale * (r * from.centroid);
    const double start_scale = sim.scale;
    sim = RunIcp(sample, closest, sim, options.coarse_iterations, extent, options).sim;
    // A hypothesis whose scale ran away collapsed onto a few surfaces: not a fit.
    if (sim.scale < 0.25 * start_scale || sim.scale > 4 * start_scale) continue;
    // Score: number of points within 1 % of the mesh's size.
    int near = 0;
    for (const Match& m : MatchPoints(sample, sim, closest)) near += m.distance < 0.01 * extent;
    if (near > best_score) best_score = near, best = sim;
  }
  MeshAlignmentSummary s = AlignPointsToMesh(points_model, mesh, best, options);
  s.start = "pca";
  s.hypotheses = static_cast<int>(rotations.size());
  return s;
}

PoseRefinementSummary RefinePosesAgainstMesh(const TriangleMesh& mesh, double inlier_threshold_m,
                                             ColmapModel* model, int rounds) {
  const MeshClosestPoint closest(mesh);
  std::map<uint64_t, Vector3d> snapped;
  for (const auto& [id, p] : model->points3d) {
    if (const auto c = closest.Query(p.xyz, inlier_threshold_m)) snapped[id] = c->point;
  }
  PoseRefinementSummary summary;
  summary.rms_before_px = SnappedReprojectionRms(*model, snapped);
  for (int round = 0; round < rounds; ++round) {
    summary.images = RefineEveryPose(snapped, model);
    if (round + 1 < rounds) Resnap(*model, closest, inlier_threshold_m, &snapped);
  }
  summary.points = static_cast<int>(snapped.size());
  summary.rounds = rounds;
  summary.rms_after_px = SnappedReprojectionRms(*model, snapped);
  for (const auto& [id, x] : snapped) model->points3d.at(id).xyz = x;
  return summary;
}

std::vector<Vector3d> ModelPoints(const ColmapModel& model) {
  std::vector<Vector3d> points;
  points.reserve(model.points3d.size());
  for (const auto& [id, p] : model.points3d) points.push_back(p.xyz);
  return points;
}

}  // namespace igi::recon
