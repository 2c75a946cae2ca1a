#include "recon/camera.h"

#include <cmath>

#include "calib/vignetting.h"

namespace igi::recon {

std::string_view CameraModelName(CameraModel model) {
  return model == CameraModel::kPinhole ? "PINHOLE" : "OPENCV";
}

size_t CameraModelNumParams(CameraModel model) { return model == CameraModel::kPinhole ? 4 : 8; }

Eigen::Vector3d Camera::CenterInWorld() const { return cam_from_world.Inverse().translation; }

double Camera::VignettingFactor(const Eigen::Vector2d& pixel) const {
  if (!HasVignetting()) return 1.0;
  return calib::Vignetting{vignetting_k1, vignetting_k2}.Factor(calib::VignettingRadius2(
      pixel.x(), pixel.y(), principal_x_px(), principal_y_px(), width, height));
}

namespace {

// OpenCV's radial-tangential distortion of normalised coordinates (COLMAP's OPENCV model).
Eigen::Vector2d Distort(const std::vector<double>& p, const Eigen::Vector2d& u) {
  const double k1 = p[4], k2 = p[5], p1 = p[6], p2 = p[7];
  const double x = u.x(), y = u.y();
  const double r2 = x * x + y * y;
  const double radial = 1.0 + k1 * r2 + k2 * r2 * r2;
  return {x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x),
          y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y};
}

// Inverts Distort by Newton's method with a numeric Jacobian (as COLMAP does).
Eigen::Vector2d Undistort(const std::vector<double>& p, const Eigen::Vector2d& distorted) {
  Eigen::Vector2d u = distorted;
  for (int iter = 0; iter < 100; ++iter) {
    const Eigen::Vector2d f = Distort(p, u) - distorted;
    if (f.squaredNorm() < 1e-24) break;
    constexpr double kStep = 1e-7;
    Eigen::Matrix2d jac;
    jac.col(0) = (Distort(p, u + Eigen::Vector2d(kStep, 0)) - Distort(p, u)) / kStep;
    jac.col(1) = (Distort(p, u + Eigen::Vector2d(0, kStep)) - Distort(p, u)) / kStep;
    u -= jac.inverse() * f;
  }
  return u;
}

}  // namespace

std::optional<Eigen::Vector2d> Camera::ImgFromCam(const Eigen::Vector3d& point_cam) const {
  if (!(point_cam.z() > 0)) return std::nullopt;
  Eigen::Vector2d u(point_cam.x() / point_cam.z(), point_cam.y() / point_cam.z());
  if (model == CameraModel::kOpenCv) u = Distort(params, u);
  // COLMAP's principal point is in the same continuous coordinates (pixel centre at 0.5).
  return Eigen::Vector2d(params[0] * u.x() + params[2], params[1] * u.y() + params[3]);
}

Eigen::Vector3d Camera::CamRayFromImg(const Eigen::Vector2d& pixel) const {
  Eigen::Vector2d u((pixel.x() - params[2]) / params[0], (pixel.y() - params[3]) / params[1]);
  if (model == CameraModel::kOpenCv) u = Undistort(params, u);
  return Eigen::Vector3d(u.x(), u.y(), 1.0).normalized();
}

std::optional<Eigen::Vector2d> Camera::ImgFromWorld(const Eigen::Vector3d& point_world) const {
  return ImgFromCam(cam_from_world * point_world);
}

Eigen::Vector3d Camera::WorldRayFromImg(const Eigen::Vector2d& pixel) const {
  return cam_from_world.rotation.conjugate() * CamRayFromImg(pixel);
}

std::optional<std::pair<CameraModel, std::vector<double>>> ConvertColmapCameraModel(
    std::string_view m, const std::vector<double>& p) {
  using Result = std::pair<CameraModel, std::vector<double>>;
  if (m == "SIMPLE_PINHOLE" && p.size() == 3) {
    return Result{CameraModel::kPinhole, {p[0], p[0], p[1], p[2]}};
  }
  if (m == "PINHOLE" && p.size() == 4) return Result{CameraModel::kPinhole, p};
  if (m == "SIMPLE_RADIAL" && p.size() == 4) {
    return Result{CameraModel::kOpenCv, {p[0], p[0], p[1], p[2], p[3], 0, 0, 0}};
  }
  if (m == "RADIAL" && p.size() == 5) {
    return Result{CameraModel::kOpenCv, {p[0], p[0], p[1], p[2], p[3], p[4], 0, 0}};
  }
  if (m == "OPENCV" && p.size() == 8) return Result{CameraModel::kOpenCv, p};
  return std::nullopt;
}

}  // namespace igi::recon
