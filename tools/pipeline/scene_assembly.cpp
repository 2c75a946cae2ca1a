#include "tools/pipeline/scene_assembly.h"

#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "recon/scene_document.h"
#include "tools/common/error.h"
#include "tools/common/image.h"

namespace igi::pipeline {
namespace fs = std::filesystem;

void TonemapForRegistration(const fs::path& radiance, const fs::path& png) {
  const Image image = ReadImage(radiance, 3);
  std::vector<float> values;
  values.reserve(image.pixels.size());
  for (float v : image.pixels) {
    if (std::isfinite(v)) values.push_back(v);
  }
  double white = 1;
  if (!values.empty()) {
    const size_t k = values.size() * 99 / 100;
    std::nth_element(values.begin(), values.begin() + k, values.end());
    if (values[k] > 0) white = values[k] / 0.9;
  }
  cv::Mat out(image.height, image.width, CV_8UC3);
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      for (int c = 0; c < 3; ++c) {
        const float raw = image.pixels[(size_t(y) * image.width + x) * 3 + c];
        const double v = std::isfinite(raw) ? std::clamp(raw / white, 0.0, 1.0) : 0.0;
        out.at<cv::Vec3b>(y, x)[2 - c] =
            static_cast<uint8_t>(std::lround(255 * std::pow(v, 1 / 2.2)));
      }
    }
  }
  cv::Mat filtered;
  cv::medianBlur(out, filtered, 3);
  fs::create_directories(png.parent_path());
  const fs::path tmp = png.string() + ".tmp.png";
  if (!cv::imwrite(tmp.string(), filtered)) throw Error("cannot write " + png.string());
  fs::rename(tmp, png);
}

namespace {

// `target` relative to the folder `base` (both made absolute first).
std::string RelativeTo(const fs::path& target, const fs::path& base) {
  std::error_code ec;
  const fs::path abs = fs::weakly_canonical(fs::absolute(target), ec);
  const fs::path rel = abs.lexically_relative(fs::weakly_canonical(fs::absolute(base), ec));
  return rel.empty() ? abs.string() : rel.generic_string();
}

}  // namespace

Json SolvableScene(const SolvableSceneInputs& in, std::vector<std::string>* unregistered) {
  recon::SceneDocument scene(in.input_scene);
  scene.RebasePaths(in.input_dir, in.out_dir);
  const Json& registered =
      in.registered_scene.contains("cameras") ? in.registered_scene["cameras"] : Json::object();
  if (!registered.is_object()) {
    throw Error("igi-register's scene.json has no camera list (\"cameras\" is not an object)");
  }
  Json cameras = Json::object();
  std::vector<recon::ScenePhotoEntry> photos;
  for (const PhotoSource& p : in.photos) {
    if (!registered.contains(p.name)) {
      unregistered->push_back(p.name);
      continue;
    }
    cameras[p.name] = registered[p.name];
    recon::ScenePhotoEntry photo{RelativeTo(in.hdr_dir / (p.name + ".exr"), in.out_dir), p.name,
                                 p.lighting, std::nullopt};
    const fs::path mask = in.hdr_dir / (p.name + "_mask.png");
    if (fs::exists(mask)) photo.mask = RelativeTo(mask, in.out_dir);
    photos.push_back(std::move(photo));
  }
  scene.SetCameras(std::move(cameras));
  scene.SetPhotos(photos);
  return std::move(scene).json();
}

}  // namespace igi::pipeline
