#pragma once
// Cameras of a scene (docs/scene-format.md): COLMAP's models and parameter order, COLMAP's frames
// (x right, y down, z forward; pose `cam_from_world`), and continuous pixel coordinates whose
// top-left pixel centre is (0.5, 0.5).
//
// Internally every camera is PINHOLE [fx, fy, cx, cy] or OPENCV [fx, fy, cx, cy, k1, k2, p1, p2];
// COLMAP's SIMPLE_PINHOLE, SIMPLE_RADIAL and RADIAL convert to those exactly.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "tools/common/geometry.h"

namespace igi::recon {

enum class CameraModel { kPinhole, kOpenCv };

std::string_view CameraModelName(CameraModel model);

struct Camera {
  std::string name;
  CameraModel model = CameraModel::kPinhole;
  int width = 0;
  int height = 0;
  // PINHOLE: fx, fy, cx, cy. OPENCV: fx, fy, cx, cy, k1, k2, p1, p2 (pixels, COLMAP order).
  std::vector<double> params;
  Rigid3d cam_from_world;
  // Vignetting (igi extension of scene.json, "vignetting": {"k1", "k2"}): the photo records
  // radiance × (1 + k1 r² + k2 r⁴), r = distance to the principal point over half the image
  // diagonal. Zero = none.
  double vignetting_k1 = 0, vignetting_k2 = 0;
  bool HasVignetting() const { return vignetting_k1 != 0 || vignetting_k2 != 0; }
  // The vignetting factor at continuous pixel coordinates (1 without vignetting).
  double VignettingFactor(const Eigen::Vector2d& pixel) const;

  double focal_x_px() const { return params[0]; }
  double focal_y_px() const { return params[1]; }
  double principal_x_px() const { return params[2]; }
  double principal_y_px() const { return params[3]; }
  // The camera centre in world coordinates.
  Eigen::Vector3d CenterInWorld() const;

  // Camera-frame point -> continuous pixel coordinates. nullopt behind the camera (z <= 0).
  std::optional<Eigen::Vector2d> ImgFromCam(const Eigen::Vector3d& point_cam) const;
  // Continuous pixel coordinates -> unit ray direction in the camera frame (undistorted).
  Eigen::Vector3d CamRayFromImg(const Eigen::Vector2d& pixel) const;
  // World point -> pixel; nullopt when behind the camera.
  std::optional<Eigen::Vector2d> ImgFromWorld(const Eigen::Vector3d& point_world) const;
  // Pixel -> unit ray direction in the world frame (origin: CenterInWorld()).
  Eigen::Vector3d WorldRayFromImg(const Eigen::Vector2d& pixel) const;
};

// Number of parameters of an internal model (4 or 8).
size_t CameraModelNumParams(CameraModel model);

// Converts a COLMAP camera model and its parameters to an internal one. Returns nullopt for a
// model that has no exact PINHOLE/OPENCV equivalent (e.g. fisheye models), or a wrong count.
std::optional<std::pair<CameraModel, std::vector<double>>> ConvertColmapCameraModel(
    std::string_view colmap_model, const std::vector<double>& params);

}  // namespace igi::recon
