#include "solver/diagnose/effects/pose_error.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <tuple>
#include <utility>
#include <vector>

#include "solver/diagnose/effects/effects.h"
#include "solver/render/render.h"
#include "solver/render/sampling.h"

namespace igi::diagnose {

using Vec6 = Eigen::Matrix<double, 6, 1>;

namespace {

// The held-out gain's significance where a pose error shows: on the model image's edges (flat
// blocks add only their noise). The held-out blocks of the camera whose gradient energy is at
// least kEdgeFactor times the median block's (the median block is flat: its gradient is noise);
// the gains of their records (without the albedo nuisance) as units — the photo's noise is
// independent from pixel to pixel, and a pose fitted to noise gains nothing on held-out pixels —
// in Wilcoxon's signed-rank z.
template <class Basis>
double EdgeBlockZ(const std::vector<PixelRecord>& records, int camera, const recon::Scene& model,
                  int block_px, const Basis& basis, const Eigen::VectorXd& coef) {
  std::map<std::tuple<int, int, int>, double> energy;
  std::vector<std::pair<std::tuple<int, int, int>, double>> gains;
  for (const PixelRecord& r : records) {
    // Outliers too: a pose error's strongest residuals, on the sharpest edges, are flagged so.
    if (!r.held_out || model.photos[r.photo].camera != camera) continue;
    const std::tuple<int, int, int> key{r.photo, r.x / block_px, r.y / block_px};
    energy[key] += double(r.sim_gradient.squaredNorm());
    double g = 0;
    for (int c = 0; c < 3; ++c) {
      double b[6] = {0, 0, 0, 0, 0, 0};
      basis(r, c, b);
      double pred = 0;
      for (int k = 0; k < int(coef.size()); ++k) pred += b[k] * coef[k];
      const double y = double(r.recorded[c]) - r.sim[c];
      g += y * y - (y - pred) * (y - pred);
    }
    gains.emplace_back(key, g);
  }
  std::vector<double> values;
  for (const auto& [k, e] : energy) values.push_back(e);
  if (values.size() < 4) return 0;
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  const double threshold = kEdgeFactor * values[values.size() / 2];
  std::vector<double> edge_gains;
  for (const auto& [k, g] : gains) {
    if (energy[k] >= threshold) edge_gains.push_back(g);
  }
  return SignedRankZ(edge_gains);
}

// The nuisance-projected normal equations of the six flows over the fitted, non-outlier records
// (as ResidualFitter: per cell and channel, every quantity v becomes v − sim·Σ v·sim / Σ sim²
// when the albedos are free), solved with Levenberg–Marquardt damping: (A + λ diag A) x = g.
template <class Flows>
Vec6 DampedPoseStep(const CandidateContext& cx, const ResidualFitter& f, const Flows& flows) {
  using Mat6 = Eigen::Matrix<double, 6, 6>;
  struct Acc {
    double ss = 0, sy = 0;
    Vec6 sb = Vec6::Zero(), by = Vec6::Zero();
    Mat6 bb = Mat6::Zero();
  };
  const std::vector<PixelRecord>& records = f.records();
  int num_cells = 0;
  const std::vector<int> cell = RecordCells(cx.model, records, cx.cell_m, &num_cells);
  std::vector<Acc> acc(size_t(num_cells) * 3);
  for (size_t i = 0; i < records.size(); ++i) {
    const PixelRecord& r = records[i];
    if (r.outlier || r.held_out) continue;
    for (int c = 0; c < 3; ++c) {
      Vec6 b = Vec6::Zero();
      flows(r, c, b.data());
      const double s = r.sim[c], y = double(r.recorded[c]) - s;
      Acc& a = acc[size_t(cell[i]) * 3 + c];
      a.ss += s * s, a.sy += s * y;
      a.sb += s * b, a.by += y * b;
      a.bb += b * b.transpose();
    }
  }
  Mat6 m = Mat6::Zero();
  Vec6 g = Vec6::Zero();
  for (const Acc& a : acc) {
    m += a.bb, g += a.by;
    if (f.nuisance() && a.ss > 0) {
      m -= a.sb * a.sb.transpose() / a.ss;
      g -= a.sb * (a.sy / a.ss);
    }
  }
  Mat6 damped = m;
  damped.diagonal() += kPoseDamping * m.diagonal();
  return damped.ldlt().solve(g);
}

}  // namespace

void ComposePoseStep(const std::string& camera, const Eigen::Vector3d& omega,
                     const Eigen::Vector3d& delta, recon::SceneDocument* doc) {
  const Rigid3d pose = doc->CameraPose(camera);
  const double a = omega.norm();
  const Eigen::Quaterniond dr(a > 0 ? Eigen::AngleAxisd(a, omega / a)
                                    : Eigen::AngleAxisd::Identity());
  doc->SetCameraPose(camera,
                     Rigid3d((dr * pose.rotation).normalized(), dr * pose.translation + delta));
}

double MedianDepth(const std::vector<PixelRecord>& records, const recon::Scene& model, int camera) {
  std::vector<float> z;
  for (const PixelRecord& r : records) {
    if (model.photos[r.photo].camera == camera && r.point_cam.z() > 0) z.push_back(r.point_cam.z());
  }
  if (z.empty()) return 0;
  std::nth_element(z.begin(), z.begin() + z.size() / 2, z.end());
  return z[z.size() / 2];
}

namespace {

// The image flow (pixels) of a point `p` (camera frame) under the six motions: rotation ω
// (radians) and translation δ / depth (radians at the median depth `depth`, so that a damping
// weighs both alike).
void PoseFlows(const Eigen::Vector3d& p, double fx, double fy, double depth, double du[6],
               double dv[6]) {
  for (int k = 0; k < 6; ++k) {
    const Eigen::Vector3d d = k < 3 ? Eigen::Vector3d::Unit(k).cross(p)
                                    : Eigen::Vector3d(depth * Eigen::Vector3d::Unit(k - 3));
    du[k] = fx * (d.x() / p.z() - p.x() * d.z() / (p.z() * p.z()));
    dv[k] = fy * (d.y() / p.z() - p.y() * d.z() / (p.z() * p.z()));
  }
}

// The flows of record `r`'s point (PoseFlows) and its image shift under the motion x, (Σ du·x,
// Σ dv·x); false when the point is not in front of the camera.
bool RecordFlows(const PixelRecord& r, double fx, double fy, double depth, const Vec6& x,
                 double du[6], double dv[6], double* shift_u, double* shift_v) {
  const Eigen::Vector3d p = r.point_cam.cast<double>();
  if (!(p.z() > 1e-6)) return false;
  PoseFlows(p, fx, fy, depth, du, dv);
  *shift_u = *shift_v = 0;
  for (int k = 0; k < 6; ++k) *shift_u += du[k] * x[k], *shift_v += dv[k] * x[k];
  return true;
}

// A photo or render, non-finite values set to 0 and values clamped to `limit` (a lamp's own
// pixels, hundreds of times the scene's, would spread over their neighbours), blurred by a
// Gaussian of `sigma` pixels (OpenCV).
cv::Mat Blurred(const Image& im, float limit, double sigma) {
  cv::Mat m(im.height, im.width, CV_32FC3);
  for (int y = 0; y < im.height; ++y) {
    for (int x = 0; x < im.width; ++x) {
      for (int c = 0; c < 3; ++c) {
        const float v = im.at(x, y, std::min(c, im.channels - 1));
        m.at<cv::Vec3f>(y, x)[c] = std::isfinite(v) ? std::clamp(v, 0.0f, limit) : 0.0f;
      }
    }
  }
  cv::Mat out;
  cv::GaussianBlur(m, out, cv::Size(0, 0), sigma, sigma, cv::BORDER_REPLICATE);
  return out;
}

// Channel c of `m` at the image point (u, v) (pixel (x, y)'s centre is (x + 0.5, y + 0.5)),
// bilinear, with its gradient; false outside the image.
bool SampleAt(const cv::Mat& m, double u, double v, int c, double* value, double* gx, double* gy) {
  const double fx = u - 0.5, fy = v - 0.5;
  const int x0 = int(std::floor(fx)), y0 = int(std::floor(fy));
  if (x0 < 0 || y0 < 0 || x0 + 1 >= m.cols || y0 + 1 >= m.rows) return false;
  const double ax = fx - x0, ay = fy - y0;
  auto px = [&](int x, int y) { return double(m.at<cv::Vec3f>(y, x)[c]); };
  const double p00 = px(x0, y0), p10 = px(x0 + 1, y0), p01 = px(x0, y0 + 1),
               p11 = px(x0 + 1, y0 + 1);
  *value = (1 - ay) * ((1 - ax) * p00 + ax * p10) + ay * ((1 - ax) * p01 + ax * p11);
  *gx = (1 - ay) * (p10 - p00) + ay * (p11 - p01);
  *gy = (1 - ax) * (p01 - p00) + ax * (p11 - p10);
  return true;
}

// The Gaussian widths (pixels) of the coarse-to-fine alignment's levels, and its Gauss–Newton
// iterations per level.
constexpr double kAlignSigmas[] = {4.0, 2.0, 1.0};
constexpr int kAlignIterations = 5;

// The camera's photos aligned with their renders, coarse to fine: at each level both are blurred
// by a Gaussian (a shift of a few pixels is then within the linearisation's reach), and the
// motion x (six amplitudes, PoseFlows) minimises Σ (photo(q) − sim(q − J(q)·x))² over the
// camera's fitted records q by damped Gauss–Newton, the render warped by each iterate (a
// Lucas–Kanade alignment whose flow is the camera's motion over the records' known depths). The
// finest level's blurred renders are returned in `fine` (by photo; empty for other cameras).
std::optional<Vec6> AlignCoarseToFine(const CandidateContext& cx,
                                      const std::vector<PixelRecord>& records, int camera,
                                      double depth, std::vector<cv::Mat>* fine) {
  const recon::Camera& cam = cx.model.cameras[camera];
  const double fx = cam.focal_x_px(), fy = cam.focal_y_px();
  const std::vector<Image>& photos = cx.photos->recorded;
  const std::vector<Image>& sims = *cx.sims;
  // Per photo of the camera: the clamp above its records' brightest value.
  std::vector<float> limit(photos.size(), 0.0f);
  for (const PixelRecord& r : records) {
    if (cx.model.photos[r.photo].camera != camera) continue;
    limit[r.photo] =
        std::max({limit[r.photo], 1.5f * r.recorded.maxCoeff(), 1.5f * r.sim.maxCoeff()});
  }
  Vec6 x = Vec6::Zero();
  std::vector<cv::Mat> photo_at(photos.size()), sim_at(photos.size());
  for (const double sigma : kAlignSigmas) {
    for (size_t i = 0; i < photos.size(); ++i) {
      if (!(limit[i] > 0) || i >= sims.size() || sims[i].empty()) continue;
      photo_at[i] = Blurred(photos[i], limit[i], sigma);
      sim_at[i] = Blurred(sims[i], limit[i], sigma);
    }
    for (int it = 0; it < kAlignIterations; ++it) {
      Eigen::Matrix<double, 6, 6> a = Eigen::Matrix<double, 6, 6>::Zero();
      Vec6 g = Vec6::Zero();
      for (const PixelRecord& r : records) {
        if (r.held_out || cx.model.photos[r.photo].camera != camera) continue;
        if (sim_at[r.photo].empty()) continue;
        double du[6], dv[6], shift_u, shift_v;
        if (!RecordFlows(r, fx, fy, depth, x, du, dv, &shift_u, &shift_v)) continue;
        const double u = r.x + 0.5, v = r.y + 0.5;
        for (int c = 0; c < 3; ++c) {
          double s, gx, gy, ph, unused_x, unused_y;
          if (!SampleAt(sim_at[r.photo], u - shift_u, v - shift_v, c, &s, &gx, &gy) ||
              !SampleAt(photo_at[r.photo], u, v, c, &ph, &unused_x, &unused_y)) {
            continue;
          }
          Vec6 row;
          for (int k = 0; k < 6; ++k) row[k] = -(gx * du[k] + gy * dv[k]);
          a += row * row.transpose();
          g += row * (ph - s);
        }
      }
      Eigen::Matrix<double, 6, 6> damped = a;
      damped.diagonal() += kPoseDamping * a.diagonal();
      const Vec6 step = damped.ldlt().solve(g);
      if (!step.allFinite()) return std::nullopt;
      x += step;
      if (x.head<3>().norm() * 180 / render::kPi > kMaxPoseErrorDeg) return std::nullopt;
      if (step.norm() < 1e-6) break;
    }
  }
  *fine = std::move(sim_at);
  return x;
}

}  // namespace

// pose_error of one camera: the photo is the model seen from a slightly moved camera, so the
// residual follows the model image's gradient along the flow of a small rotation ω (camera frame)
// and translation δ: photo − sim ≈ −∇sim · J(ω, δ). Six amplitudes per camera.
CandidateResult FitPoseError(const CandidateContext& cx, const ResidualFitter& f, int camera) {
  CandidateResult out;
  out.effect = "pose_error";
  const recon::Camera& cam = cx.model.cameras[camera];
  if (!cx.declared.contains("cameras") || cx.declared["cameras"].contains("colmap")) return out;
  const double fx = cam.focal_x_px(), fy = cam.focal_y_px();
  const double depth = MedianDepth(f.records(), cx.model, camera);
  if (!(depth > 0)) return out;
  auto flows = [&](const PixelRecord& r, int c, double* b) {
    if (cx.model.photos[r.photo].camera != camera) return;
    const Eigen::Vector3d p = r.point_cam.cast<double>();
    if (!(p.z() > 1e-6)) return;
    const double gx = r.sim_gradient(c, 0), gy = r.sim_gradient(c, 1);
    double du[6], dv[6];
    PoseFlows(p, fx, fy, depth, du, dv);
    for (int k = 0; k < 6; ++k) b[k] = -(gx * du[k] + gy * dv[k]);
  };
  Vec6 x;
  ResidualFit fit;
  std::function<void(const PixelRecord&, int, double*)> basis;
  std::vector<cv::Mat> fine;
  std::optional<Vec6> aligned;
  if (cx.photos && cx.sims) aligned = AlignCoarseToFine(cx, f.records(), camera, depth, &fine);
  if (aligned) {
    // With the images: the motion the coarse-to-fine alignment found, scored as the change it
    // makes, the finest level's render warped by it less the render (one amplitude, about 1).
    x = *aligned;
    basis = [&](const PixelRecord& r, int c, double* b) {
      if (cx.model.photos[r.photo].camera != camera || fine[r.photo].empty()) return;
      double du[6], dv[6], shift_u, shift_v;
      if (!RecordFlows(r, fx, fy, depth, x, du, dv, &shift_u, &shift_v)) return;
      double moved, here, gx, gy;
      if (SampleAt(fine[r.photo], r.x + 0.5 - shift_u, r.y + 0.5 - shift_v, c, &moved, &gx, &gy) &&
          SampleAt(fine[r.photo], r.x + 0.5, r.y + 0.5, c, &here, &gx, &gy)) {
        b[0] = moved - here;
      }
    };
    fit = f.Fit(1, basis);
    if (fit.coef.size() == 0) return out;
  } else {
    // From the records alone, one linearised step. Its direction: Levenberg–Marquardt damped
    // normal equations. A rotation and a sideways shift move a distant scene's image alike (they
    // differ only by the parallax of its depth range), so the undamped system is near-singular
    // along that valley and its solution wanders along it (DiLiGenT's ball: 0.55° cancelled by a
    // shift of 0.6 radii at 50 radii). The damping leaves the motions the image does tell apart;
    // the amplitude along the direction is then fitted (and scored) as one parameter.
    const Vec6 direction = DampedPoseStep(cx, f, flows);
    if (!direction.allFinite() || !(direction.norm() > 0)) return out;
    basis = [&](const PixelRecord& r, int c, double* b) {
      double six[6] = {0, 0, 0, 0, 0, 0};
      flows(r, c, six);
      b[0] = Eigen::Map<const Vec6>(six).dot(direction);
    };
    fit = f.Fit(1, basis);
    if (fit.coef.size() == 0) return out;
    x = fit.coef[0] * direction;
  }
  const Eigen::Vector3d omega = x.head<3>(), delta = depth * x.tail<3>();
  const double angle_deg = omega.norm() * 180 / render::kPi;
  // "Small" in the scene's own units: a shift below a tenth of the distance to what the camera
  // sees (a room seen from 3 m: 0.3 m; DiLiGenT's radius-1 ball seen from 50 units: 5 units).
  if (!(angle_deg < kMaxPoseErrorDeg) || !(delta.norm() < kMaxPoseShiftOfDepth * depth)) {
    out.note = fmt::format(
        "camera {}: the gradient fit ({:.2f} deg, {:.3g} scene units at a median depth of "
        "{:.3g}) is not a small pose error",
        cam.name, angle_deg, delta.norm(), depth);
    return out;
  }
  FillScores(fit, &out);
  // The candidate's z decides only whether the pose is iterated on re-renders (the trial's
  // edge-pixel test then judges it): the larger of the edge pixels' signed-rank z and the fit's
  // block z. A step that is not yet the pose (one linearised step; an alignment of blurred
  // images) can gain on the sharp edges and lose a little on most faint ones, and the block z
  // counts the gain where it is.
  out.z = std::max(out.z, EdgeBlockZ(f.records(), camera, cx.model, cx.block_px, basis, fit.coef));
  out.params = {{"camera", cam.name},
                {"rotation_deg", angle_deg},
                {"rotation_vector", {omega.x(), omega.y(), omega.z()}},
                {"translation_m", {delta.x(), delta.y(), delta.z()}}};
  Json photos = Json::array();
  for (const recon::Photo& p : cx.model.photos) {
    if (p.camera == camera) photos.push_back(p.file.filename().string());
  }
  out.where = {{"photos", photos}, {"frame", "image position (edges)"}};
  out.num_params = 6;
  out.evidence = fmt::format(
      "camera {}: the residual follows the model image's edges, as a shift of the view by "
      "{:.2f} deg and {:.1f} mm: its declared pose is off",
      cam.name, angle_deg, 1000 * delta.norm());
  out.valid = true;
  return out;
}

PoseRefinement RefinePose(const recon::Scene& model, int camera, const PhotoSet& photos,
                          const std::vector<Image>& sims, const DiagnoseOptions& o,
                          bool materials_solved, double cell_m, int max_iterations,
                          recon::SceneDocument* doc) {
  PoseRefinement out;
  recon::Scene m = model;
  const std::string name = m.cameras[camera].name;
  const Rigid3d start = model.cameras[camera].cam_from_world;
  std::vector<Image> current = sims;
  std::vector<std::unique_ptr<render::Renderer>> renderers(m.lightings.size());
  double last_train = std::numeric_limits<double>::infinity();
  recon::SceneDocument last_doc = *doc;
  Eigen::Vector3d last_omega = Eigen::Vector3d::Zero(), last_delta = Eigen::Vector3d::Zero();
  int halvings = 0;
  for (int it = 0; it < max_iterations; ++it) {
    m.cameras[camera].cam_from_world = doc->CameraPose(name);
    for (size_t i = 0; i < m.photos.size(); ++i) {
      const recon::Photo& p = m.photos[i];
      if (p.camera != camera) continue;
      if (!renderers[p.lighting])
        renderers[p.lighting] = std::make_unique<render::Renderer>(m, p.lighting);
      render::RenderOptions ro;  // as SimulatePhotos
      ro.spp = o.spp;
      ro.seed = o.seed + 7919 * i;
      ro.num_threads = o.num_threads;
      ro.show_progress = false;
      current[i] = renderers[p.lighting]->Render(m.cameras[camera], ro);
      solver::ApplyExposureAndResponse(p, &current[i]);
    }
    std::vector<PixelRecord> records = BuildRecords(m, photos, current, o);
    // The camera's residual tail is the pose error's own signal on sharp edges (the outlier flag
    // is meant for fireflies and unmodelled objects): its records take part.
    for (PixelRecord& r : records) {
      if (m.photos[r.photo].camera == camera) r.outlier = false;
    }
    int num_cells = 0;
    std::vector<int> cells = RecordCells(m, records, cell_m, &num_cells);
    const ResidualFitter f(records, std::move(cells), num_cells, materials_solved,
                           o.holdout_block_px);
    CandidateContext cx{m, doc->json(), materials_solved, cell_m, o.holdout_block_px};
    cx.photos = &photos;
    cx.sims = &current;
    const CandidateResult step = FitPoseError(cx, f, camera);
    // Gauss–Newton guarded: a step that made the fitted residual worse than the pose before it is
    // taken back and tried at half its length (twice at most; then the iteration ends).
    if (step.valid && step.train_before > last_train) {
      *doc = last_doc;
      if (++halvings > kPoseHalvings) {
        spdlog::info("igi-diagnose: pose of {}: the last step raised the residual; taken back",
                     name);
        break;
      }
      last_omega *= 0.5, last_delta *= 0.5;
      ComposePoseStep(name, last_omega, last_delta, doc);
      out.last_step_deg = last_omega.norm() * 180 / render::kPi;
      out.last_step_m = last_delta.norm();
      spdlog::info("igi-diagnose: pose of {}: the last step raised the residual; halved", name);
      continue;
    }
    if (!step.valid) break;
    // Converged to the noise: the last step cut the fitted residual² by less than
    // kPoseMinStepGain of it (on a render's and a photo's noise the steps wander by a tenth of a
    // degree without end).
    if (std::isfinite(last_train) &&
        last_train - step.train_before < kPoseMinStepGain * last_train) {
      spdlog::info("igi-diagnose: pose of {}: the last step gained {:.2f}% of the residual²; done",
                   name, 100 * (last_train - step.train_before) / last_train);
      break;
    }
    halvings = 0;
    last_train = step.train_before;
    last_doc = *doc;
    const std::vector<double> w = step.params["rotation_vector"].get<std::vector<double>>();
    const std::vector<double> d = step.params["translation_m"].get<std::vector<double>>();
    last_omega = Eigen::Vector3d(w[0], w[1], w[2]);
    last_delta = Eigen::Vector3d(d[0], d[1], d[2]);
    ComposePoseStep(name, last_omega, last_delta, doc);
    ++out.iterations;
    out.last_step_deg = step.params["rotation_deg"].get<double>();
    out.last_step_m = last_delta.norm();
    spdlog::info("igi-diagnose: pose of {}: step {} of {:.3f} deg, {:.2f} mm", name, it + 1,
                 out.last_step_deg, 1000 * out.last_step_m);
    // Converged: below 0.005° and 3e-5 of the depth (0.1 mm at 3 m).
    const double depth = MedianDepth(records, m, camera);
    if (out.last_step_deg < 0.005 && out.last_step_m < 3e-5 * depth) break;
  }
  const Rigid3d end = doc->CameraPose(name);
  out.rotation_deg =
      Eigen::AngleAxisd(end.rotation * start.rotation.inverse()).angle() * 180 / render::kPi;
  const Eigen::Vector3d c0 = -(start.rotation.inverse() * start.translation);
  const Eigen::Vector3d c1 = -(end.rotation.inverse() * end.translation);
  out.translation_m = (c1 - c0).norm();
  return out;
}

namespace {

// The held-out blocks of `camera`'s photos whose model image's gradient energy is at least
// kEdgeFactor times the median block's: where a pose error shows (its gain sits on edges; flat
// blocks only add their noise).
BlockFilter EdgeBlocks(const recon::Scene& model, int camera, const std::vector<Image>& sims,
                       const solver::PixelHoldout& h) {
  auto energies = std::make_shared<std::map<std::tuple<size_t, int, int>, double>>();
  for (size_t i = 0; i < sims.size(); ++i) {
    if (model.photos[i].camera != camera) continue;
    const Image& s = sims[i];
    for (int y = 1; y + 1 < s.height; ++y) {
      for (int x = 1; x + 1 < s.width; ++x) {
        if (!h.HeldOut(int(i), x, y)) continue;
        double e = 0;
        for (int c = 0; c < 3; ++c) {
          const double gx = s.at(x + 1, y, c) - s.at(x - 1, y, c);
          const double gy = s.at(x, y + 1, c) - s.at(x, y - 1, c);
          if (std::isfinite(gx) && std::isfinite(gy)) e += gx * gx + gy * gy;
        }
        (*energies)[{i, x / h.block_px, y / h.block_px}] += e;
      }
    }
  }
  std::vector<double> values;
  for (const auto& [k, e] : *energies) values.push_back(e);
  double median = 0;
  if (!values.empty()) {
    std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
    median = values[values.size() / 2];
  }
  return [energies, median](size_t photo, int bx, int by) {
    const auto it = energies->find({photo, bx, by});
    return it != energies->end() && it->second >= kEdgeFactor * median;
  };
}

// The index of the candidate's camera (params "camera") in `model`, or -1.
int CameraOf(const CandidateResult& c, const recon::Scene& model) {
  const std::string name = c.params.value("camera", "");
  for (int k = 0; k < int(model.cameras.size()); ++k) {
    if (model.cameras[k].name == name) return k;
  }
  return -1;
}

class PoseErrorEffect final : public Effect {
 public:
  std::string Name() const override { return "pose_error"; }
  // One fit per camera, on a copy of the records whose outlier flags are cleared in that
  // camera's photos: a pose error's strongest residuals lie on the sharpest edges, where the
  // flag (meant for fireflies and unmodelled objects) would leave out its own signal (a camera
  // of RADIANCE's room turned by 1°, 4.8 px: fitted without them, a step of 0.03°).
  void AddFits(const CandidateContext& cx, const RecordFits& in, const KeyFilter& allowed,
               std::vector<CandidateTask>* tasks) const override {
    for (int c = 0; c < int(cx.model.cameras.size()); ++c) {
      if (!allowed(Name() + ":" + cx.model.cameras[c].name)) continue;
      tasks->push_back({[&cx, &f = in.fitter, c] {
        std::vector<PixelRecord> own = f.records();
        for (PixelRecord& r : own) {
          if (cx.model.photos[r.photo].camera == c) r.outlier = false;
        }
        const RecordSubset edges(cx.model, std::move(own), cx.cell_m, f.nuisance(), cx.block_px);
        return FitPoseError(cx, edges.fitter(), c);
      }});
    }
  }

  // The candidate is one linearised step: the pose is iterated from the declared one by
  // Gauss–Newton on re-renders of the camera (RefinePose), and the candidate becomes the pose
  // found.
  TrialPlan PlanTrial(CandidateResult* c, const DiagnosisModel& m) override {
    const int camera = CameraOf(*c, m.model);
    if (camera < 0) return {m.declared, m.maps, std::nullopt};
    recon::SceneDocument doc(m.declared);
    const PoseRefinement pr = RefinePose(m.model, camera, m.photos, m.sims, m.options,
                                         m.materials_solved, m.cell_m, 8, &doc);
    Json& p = c->params;
    p["iterations"] = pr.iterations;
    p["rotation_deg"] = pr.rotation_deg;
    p["center_shift_m"] = pr.translation_m;
    p.erase("rotation_vector");
    p.erase("translation_m");
    const Json& cam = doc.json().at("cameras").at(p["camera"].get<std::string>());
    p["qvec"] = cam.at("qvec");
    p["tvec"] = cam.at("tvec");
    c->evidence = fmt::format(
        "camera {}: the residual follows the model image's edges, as a shift of the view: {} "
        "Gauss-Newton steps on re-renders move its pose by {:.3f} deg and its centre by {:.1f} "
        "mm (last step {:.4f} deg, {:.2f} mm)",
        p["camera"].get<std::string>(), pr.iterations, pr.rotation_deg, 1000 * pr.translation_m,
        pr.last_step_deg, 1000 * pr.last_step_m);
    return {std::move(doc).json(), m.maps, std::nullopt};
  }

  // A pose error shows on edges: the significance counts the pixels of the camera's held-out
  // blocks with edges (EdgeBlocks), as signed-rank units.
  HeldOutScope Scope(const CandidateResult& c, const DiagnosisModel& m) const override {
    HeldOutScope scope;
    const int camera = CameraOf(c, m.model);
    if (camera < 0) return scope;
    scope.blocks = EdgeBlocks(m.model, camera, m.sims, m.holdout);
    scope.pixel_units = true;
    return scope;
  }

  // The camera's pose: the one found (qvec, tvec), or the fitted step composed with the pose.
  void Write(const CandidateResult& c, recon::SceneDocument* doc) const override {
    const std::string camera = c.params.at("camera").get<std::string>();
    if (c.params.contains("qvec") && c.params.contains("tvec")) {
      const std::vector<double> q = c.params["qvec"].get<std::vector<double>>();
      const std::vector<double> t = c.params["tvec"].get<std::vector<double>>();
      doc->SetCameraPose(camera, Rigid3d(Eigen::Quaterniond(q.at(0), q.at(1), q.at(2), q.at(3)),
                                         Eigen::Vector3d(t.at(0), t.at(1), t.at(2))));
      return;
    }
    const std::vector<double> w = c.params.at("rotation_vector").get<std::vector<double>>();
    const std::vector<double> d = c.params.at("translation_m").get<std::vector<double>>();
    ComposePoseStep(camera, Eigen::Vector3d(w[0], w[1], w[2]), Eigen::Vector3d(d[0], d[1], d[2]),
                    doc);
  }
};

}  // namespace

std::unique_ptr<Effect> MakePoseError() { return std::make_unique<PoseErrorEffect>(); }

}  // namespace igi::diagnose
