#include "recon/registration.h"

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <cmath>

#include "tools/common/error.h"
#include "tools/common/json.h"

namespace igi::recon {
namespace {

// Least-squares point nearest to rays (origin, unit direction).
Eigen::Vector3d NearestToRays(
    const std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>>& rays) {
  Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (const auto& [origin, direction] : rays) {
    const Eigen::Matrix3d p = Eigen::Matrix3d::Identity() - direction * direction.transpose();
    a += p;
    b += p * origin;
  }
  return a.ldlt().solve(b);
}

void ReadMarkerPixels(const JsonCursor& root, Markers* markers) {
  const JsonCursor pixels = root["pixels"];
  for (const std::string& photo : pixels.ObjectKeys()) {
    const JsonCursor in_photo = pixels[photo];
    for (const std::string& name : in_photo.ObjectKeys()) {
      const JsonCursor pixel = in_photo[name];
      if (markers->points.count(name) == 0) {
        pixel.Problem("names a marker point that \"points\" lacks");
        continue;
      }
      if (auto xy = pixel.Numbers(2)) markers->pixels[photo][name] = {(*xy)[0], (*xy)[1]};
    }
  }
}

}  // namespace

Camera CameraOfImage(const ColmapModel& model, const ColmapImage& image) {
  const ColmapCamera& colmap = model.cameras.at(image.camera_id);
  const auto converted = ConvertColmapCameraModel(colmap.model, colmap.params);
  if (!converted) {
    throw Error("camera " + std::to_string(colmap.camera_id) + ": COLMAP model " + colmap.model +
                " has no PINHOLE/OPENCV equivalent");
  }
  Camera camera;
  camera.name = image.name;
  camera.model = converted->first;
  camera.params = converted->second;
  camera.width = colmap.width;
  camera.height = colmap.height;
  camera.cam_from_world = Rigid3d(QuaternionFromQvec(image.qvec).normalized(), image.tvec);
  return camera;
}

std::vector<ImageReprojection> ReprojectionErrors(const ColmapModel& model) {
  std::vector<ImageReprojection> result;
  for (const auto& [id, image] : model.images) {
    const Camera camera = CameraOfImage(model, image);
    ImageReprojection r{image.name, 0, 0};
    double sum_sq = 0;
    for (const ColmapPoint2D& p : image.points2d) {
      if (p.point3d_id < 0) continue;
      const auto it = model.points3d.find(static_cast<uint64_t>(p.point3d_id));
      if (it == model.points3d.end()) continue;
      const auto projected = camera.ImgFromWorld(it->second.xyz);
      if (!projected) continue;
      sum_sq += (*projected - p.xy).squaredNorm();
      ++r.observations;
    }
    r.rms_px = r.observations > 0 ? std::sqrt(sum_sq / r.observations) : 0;
    result.push_back(r);
  }
  std::sort(result.begin(), result.end(),
            [](const auto& a, const auto& b) { return a.name < b.name; });
  return result;
}

Markers ReadMarkers(const std::filesystem::path& path) {
  const std::string file = path.string();
  const Json json = ReadJsonFile(path);
  ProblemList problems;
  const JsonCursor root = JsonCursor::Root(json, file, &problems);
  Markers markers;
  if (root.ExpectObject({"format", "version", "points", "pixels"})) {
    root["format"].Enum({"igi-markers"});
    if (root["version"].present()) root["version"].Integer(NumberRule::Between(1, 1));
    for (const std::string& name : root["points"].ObjectKeys()) {
      if (auto p = root["points"][name].Vec3()) markers.points[name] = *p;
    }
    ReadMarkerPixels(root, &markers);
  }
  problems.ThrowIfAny();
  return markers;
}

void TransformModel(const Similarity3d& scene_from_model, ColmapModel* model) {
  const Eigen::Quaterniond& rs = scene_from_model.rotation;
  for (auto& [id, image] : model->images) {
    // x_cam = R x_model + t, x_model = Rs^T (x_scene - ts) / s; camera-frame lengths * s.
    const Eigen::Quaterniond r = QuaternionFromQvec(image.qvec).normalized();
    const Eigen::Quaterniond r_new = (r * rs.conjugate()).normalized();
    const Eigen::Vector3d t_new =
        scene_from_model.scale * image.tvec - (r_new * scene_from_model.translation);
    image.qvec = QvecFromQuaternion(r_new);
    image.tvec = t_new;
  }
  for (auto& [id, point] : model->points3d) point.xyz = scene_from_model * point.xyz;
}

MarkerAlignment AlignByMarkers(const ColmapModel& model, const Markers& markers) {
  std::map<std::string, std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>>> rays;
  for (const auto& [photo, seen] : markers.pixels) {
    const ColmapImage* image = model.FindImageByName(photo);
    if (image == nullptr) continue;  // photo not registered
    const Camera camera = CameraOfImage(model, *image);
    for (const auto& [name, pixel] : seen) {
      rays[name].emplace_back(camera.CenterInWorld(), camera.WorldRayFromImg(pixel));
    }
  }
  MarkerAlignment alignment;
  std::vector<Eigen::Vector3d> from;
  std::vector<Eigen::Vector3d> to;
  for (const auto& [name, marker_rays] : rays) {
    if (marker_rays.size() < 2) continue;
    alignment.used.push_back(name);
    from.push_back(NearestToRays(marker_rays));
    to.push_back(markers.points.at(name));
  }
  if (from.size() < 3) {
    throw Error("only " + std::to_string(from.size()) +
                " markers are seen in two or more registered photos; aligning to the scene "
                "needs at least 3");
  }
  Eigen::Matrix3Xd src(3, from.size());
  Eigen::Matrix3Xd dst(3, to.size());
  for (size_t i = 0; i < from.size(); ++i) {
    src.col(static_cast<Eigen::Index>(i)) = from[i];
    dst.col(static_cast<Eigen::Index>(i)) = to[i];
  }
  const Eigen::Matrix4d t = Eigen::umeyama(src, dst, true);
  const Eigen::Matrix3d sr = t.topLeftCorner<3, 3>();
  Similarity3d& sim = alignment.scene_from_model;
  sim.scale = std::cbrt(sr.determinant());
  sim.rotation = Eigen::Quaterniond(sr / sim.scale).normalized();
  sim.translation = t.topRightCorner<3, 1>();
  double sum_sq = 0;
  for (size_t i = 0; i < from.size(); ++i) {
    const double r = (sim * from[i] - to[i]).norm();
    alignment.residual_m[alignment.used[i]] = r;
    sum_sq += r * r;
  }
  alignment.rms_residual_m = std::sqrt(sum_sq / static_cast<double>(from.size()));
  ColmapModel aligned = model;
  TransformModel(sim, &aligned);
  double px_sq = 0;
  int count = 0;
  for (const auto& [photo, seen] : markers.pixels) {
    const ColmapImage* image = aligned.FindImageByName(photo);
    if (image == nullptr) continue;
    const Camera camera = CameraOfImage(aligned, *image);
    for (const auto& [name, pixel] : seen) {
      const auto projected = camera.ImgFromWorld(markers.points.at(name));
      if (!projected) continue;
      px_sq += (*projected - pixel).squaredNorm();
      ++count;
    }
  }
  alignment.rms_reprojection_px = count > 0 ? std::sqrt(px_sq / count) : 0;
  return alignment;
}

}  // namespace igi::recon
