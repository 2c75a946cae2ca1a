// LoadScene, part 3: cameras (inline, or from a COLMAP model) and photos with masks.
#include <cmath>

#include "recon/colmap_model.h"
#include "recon/registration.h"
#include "recon/scene_loader.h"

namespace igi::recon {
namespace {

namespace fs = std::filesystem;

// |q| may differ from 1 by this much (text files round to ~10 digits); the value is normalised.
constexpr double kUnitQuaternionTolerance = 1e-5;

std::optional<Eigen::Quaterniond> ReadQvec(const JsonCursor& c) {
  auto q = c.Numbers(4);
  if (!q) return std::nullopt;
  const Eigen::Vector4d v((*q)[0], (*q)[1], (*q)[2], (*q)[3]);
  if (std::abs(v.norm() - 1.0) > kUnitQuaternionTolerance) {
    c.Problem("must be a unit quaternion [w, x, y, z] (its norm is " +
              std::to_string(v.norm()) + ")");
    return std::nullopt;
  }
  return QuaternionFromQvec(v.normalized());
}

Camera ReadInlineCamera(const JsonCursor& c, const std::string& name) {
  Camera cam;
  cam.name = name;
  if (!c.ExpectObject({"model", "width", "height", "params", "qvec", "tvec", "vignetting"})) {
    return cam;
  }
  const NumberRule size_rule = NumberRule::Between(1, 1 << 16);
  cam.width = static_cast<int>(c["width"].Integer(size_rule).value_or(0));
  cam.height = static_cast<int>(c["height"].Integer(size_rule).value_or(0));
  auto model = c["model"].Enum({"PINHOLE", "OPENCV", "SIMPLE_PINHOLE", "SIMPLE_RADIAL", "RADIAL"});
  auto params = c["params"].Numbers(0);
  if (model && params) {
    auto converted = ConvertColmapCameraModel(*model, *params);
    if (!converted) {
      c["params"].Problem("wrong number of parameters for " + *model + " (needs " +
                          std::to_string(ColmapModelNumParams(*model)) + ")");
    } else {
      cam.model = converted->first;
      cam.params = converted->second;
      if (!(cam.params[0] > 0) || !(cam.params[1] > 0)) {
        c["params"].Problem("focal lengths must be > 0 pixels");
      }
    }
  }
  if (auto q = ReadQvec(c["qvec"])) cam.cam_from_world.rotation = *q;
  if (auto t = c["tvec"].Vec3()) cam.cam_from_world.translation = *t;
  if (c["vignetting"].present()) {
    const JsonCursor v = c["vignetting"];
    if (v.ExpectObject({"k1", "k2"})) {
      const NumberRule rule = NumberRule::Between(-1, 1);
      cam.vignetting_k1 = v["k1"].present() ? v["k1"].Number(rule).value_or(0) : 0;
      cam.vignetting_k2 = v["k2"].present() ? v["k2"].Number(rule).value_or(0) : 0;
      if (1 + cam.vignetting_k1 + cam.vignetting_k2 < 0.05) {
        v.Problem("1 + k1 + k2 must be at least 0.05 (the factor in the corners)");
      }
    }
  }
  return cam;
}

void ReadColmapCameras(const SceneLoader& ld, const JsonCursor& c, Scene* scene) {
  auto dir_name = c.NonEmptyString();
  if (!dir_name) return;
  const fs::path dir = (ld.dir / *dir_name).lexically_normal();
  if (!fs::is_directory(dir)) {
    c.Problem("COLMAP model folder not found (" + dir.string() + ")");
    return;
  }
  scene->colmap_model = dir;
  ColmapModel model;
  try {
    model = ReadColmapModel(dir);
  } catch (const Error& e) {
    ld.Nested(c, e);
    return;
  }
  for (const auto& [image_id, image] : model.images) {
    try {
      scene->cameras.push_back(CameraOfImage(model, image));
    } catch (const Error& e) {
      c.Problem("image " + image.name + ": " + e.what() +
                " (use PINHOLE, OPENCV, SIMPLE_PINHOLE, SIMPLE_RADIAL, RADIAL)");
    }
  }
}

}  // namespace

void ReadCameras(const SceneLoader& ld, const JsonCursor& root, Scene* scene) {
  if (!root["cameras"].present()) return;
  const JsonCursor cameras = root["cameras"];
  if (cameras["colmap"].IsString()) {
    cameras.ExpectObject({"colmap"});
    ReadColmapCameras(ld, cameras["colmap"], scene);
    return;
  }
  for (const std::string& name : cameras.ObjectKeys()) {
    scene->cameras.push_back(ReadInlineCamera(cameras[name], name));
  }
}

namespace {

// Checks that an image (photo or mask) has the camera's size.
void CheckImageSize(const SceneLoader& ld, const JsonCursor& c, const fs::path& file,
                    const Camera* camera) {
  auto info = ld.ImageHeader(c, file);
  if (!info || camera == nullptr || camera->width == 0) return;
  if (info->width != camera->width || info->height != camera->height) {
    c.Problem("image is " + std::to_string(info->width) + "x" + std::to_string(info->height) +
              " but camera " + camera->name + " is " + std::to_string(camera->width) + "x" +
              std::to_string(camera->height));
  }
}

}  // namespace

void ReadPhotos(const SceneLoader& ld, const JsonCursor& root, Scene* scene) {
  if (!root["photos"].present()) return;
  const JsonCursor photos = root["photos"];
  const size_t n = photos.ArraySize();
  for (size_t i = 0; i < n; ++i) {
    const JsonCursor c = photos[i];
    if (!c.ExpectObject({"file", "camera", "lighting", "mask", "exposure_scale", "response"})) {
      continue;
    }
    Photo photo;
    auto file = ld.File(c["file"]);
    // With a COLMAP model the camera may be left out: the image named like the photo is used.
    if (c["camera"].present() || !scene->colmap_model) {
      if (auto name = c["camera"].String()) {
        photo.camera = scene->FindCamera(*name);
        if (photo.camera < 0) c["camera"].Problem("no camera of that name in cameras");
      }
    } else if (file) {
      photo.camera = scene->FindCamera(file->filename().string());
      if (photo.camera < 0) c["file"].Problem("no image of this file name in the COLMAP model");
    }
    if (auto lighting = c["lighting"].String()) {
      photo.lighting = scene->FindLighting(*lighting);
      if (photo.lighting < 0) c["lighting"].Problem("no lighting of that name in lightings");
    }
    const Camera* camera = photo.camera >= 0 ? &scene->cameras[photo.camera] : nullptr;
    if (file) {
      photo.file = *file;
      CheckImageSize(ld, c["file"], *file, camera);
    }
    if (c["mask"].present()) {
      photo.mask = ld.File(c["mask"]);
      if (photo.mask) CheckImageSize(ld, c["mask"], *photo.mask, camera);
    }
    if (c["exposure_scale"].present()) {
      photo.exposure_scale = c["exposure_scale"].Number(NumberRule::Positive()).value_or(1.0);
    }
    if (c["response"].present()) {
      const JsonCursor r = c["response"];
      if (r.ExpectObject({"exponent", "reference"})) {
        photo.response_exponent = r["exponent"].Number(NumberRule::Between(0.1, 10)).value_or(1);
        photo.response_reference = r["reference"].Number(NumberRule::Positive()).value_or(1);
      }
    }
    scene->photos.push_back(std::move(photo));
  }
}

Json CameraJson(const Camera& camera) {
  const Eigen::Vector4d q = QvecFromQuaternion(camera.cam_from_world.rotation);
  const Eigen::Vector3d& t = camera.cam_from_world.translation;
  Json j{{"model", std::string(CameraModelName(camera.model))},
         {"width", camera.width},
         {"height", camera.height},
         {"params", camera.params},
         {"qvec", Json::array({q[0], q[1], q[2], q[3]})},
         {"tvec", Json::array({t.x(), t.y(), t.z()})}};
  if (camera.HasVignetting()) {
    j["vignetting"] = {{"k1", camera.vignetting_k1}, {"k2", camera.vignetting_k2}};
  }
  return j;
}

}  // namespace igi::recon
