#pragma once
// What igi-register does with a COLMAP model: per-photo reprojection errors, and bringing the
// model into the scene's frame from control points (markers).
//
// Markers file ("format": "igi-markers", "version": 1): named 3D points in the scene frame
// (metres) and their pixel positions (COLMAP convention, top-left pixel centre (0.5, 0.5)) in
// some photos:
//   {"format": "igi-markers", "version": 1,
//    "points": {"door_corner": [0, 0, 2.1], …},
//    "pixels": {"IMG_0001.jpg": {"door_corner": [812.5, 301.0], …}, …}}
// A pixel entry naming a point that "points" lacks is an InputError (exit 2), as is any other
// rule broken.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "recon/camera.h"
#include "recon/colmap_model.h"

namespace igi::recon {

struct ImageReprojection {
  std::string name;
  int observations = 0;  // triangulated 2D points
  double rms_px = 0;     // RMS reprojection error over them
};

// The igi camera of a registered COLMAP image (model converted to PINHOLE/OPENCV); throws
// igi::Error for a camera model without an exact equivalent.
Camera CameraOfImage(const ColmapModel& model, const ColmapImage& image);
// Reprojection error of every registered image, in image-name order.
std::vector<ImageReprojection> ReprojectionErrors(const ColmapModel& model);

struct Markers {
  std::map<std::string, Eigen::Vector3d> points;  // scene frame, metres
  // photo file name -> marker name -> pixel
  std::map<std::string, std::map<std::string, Eigen::Vector2d>> pixels;
};
Markers ReadMarkers(const std::filesystem::path& path);

// x_scene = scale * rotation * x_colmap + translation.
struct Similarity3d {
  double scale = 1;
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  Eigen::Vector3d operator*(const Eigen::Vector3d& x) const {
    return scale * (rotation * x) + translation;
  }
};

// Applies scene_from_model to every pose and 3D point of `model` (poses keep unit scale:
// camera-frame distances are multiplied by the scale).
void TransformModel(const Similarity3d& scene_from_model, ColmapModel* model);

struct MarkerAlignment {
  Similarity3d scene_from_model;
  std::vector<std::string> used;             // markers seen in >= 2 registered photos
  std::map<std::string, double> residual_m;  // |aligned triangulation - scene point|
  double rms_residual_m = 0;
  double rms_reprojection_px = 0;  // scene points projected into the photos
};

// Triangulates each marker seen in two or more registered photos and fits the similarity
// (Umeyama) that takes them onto the scene points. Throws igi::Error when fewer than three
// markers can be triangulated.
MarkerAlignment AlignByMarkers(const ColmapModel& model, const Markers& markers);

}  // namespace igi::recon
