#include "solver/diagnose/analysis_capture.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <utility>

#include "recon/scene_document.h"
#include "solver/diagnose/pixel_records.h"
#include "solver/inverse/observations.h"
#include "tools/common/image.h"
#include "tools/common/parallel.h"
#include "tools/common/progress.h"

namespace igi::diagnose {
namespace fs = std::filesystem;

namespace {

// Writes the f × f block means of photo `p` to `file`, and its mask to `mask_file` when a block
// is invalid or the photo has a mask. Returns whether the mask was written.
bool ReducePhoto(const recon::Photo& p, int f, const fs::path& file, const fs::path& mask_file) {
  const Image img = ReadImage(p.file, 3);
  std::optional<Image> mask;
  if (p.mask) mask = ReadImage(*p.mask, 1);
  const double clip = solver::AutoSaturation(img);
  const int w = img.width / f, h = img.height / f;
  Image out(w, h, 3), valid(w, h, 1);
  ParallelFor(0, h, [&](int64_t yy) {
    const int y = int(yy);
    for (int x = 0; x < w; ++x) {
      double sum[3] = {0, 0, 0};
      bool ok = true;
      for (int v = y * f; v < (y + 1) * f && ok; ++v) {
        for (int u = x * f; u < (x + 1) * f && ok; ++u) {
          ok = UsablePixel(img, mask ? &*mask : nullptr, clip, u, v);
          for (int c = 0; c < 3 && ok; ++c) sum[c] += p.LinearFromRecorded(img.at(u, v, c));
        }
      }
      for (int c = 0; c < 3; ++c) {
        const double mean = sum[c] / (f * f);
        out.at(x, y, c) = ok ? float(p.RecordedFromLinear(mean)) : 0.0f;
      }
      valid.at(x, y, 0) = ok ? 1.0f : 0.0f;
    }
  });
  WriteImage(file, out);
  const bool any_invalid =
      std::any_of(valid.pixels.begin(), valid.pixels.end(), [](float v) { return v < 0.5f; });
  if (!any_invalid && !mask) return false;
  WriteImageOptions png;
  png.type = PixelType::kUInt8;
  WriteImage(mask_file, valid, png);
  return true;
}

}  // namespace

AnalysisCapture ReduceCapture(const recon::Scene& scene, const Json& declared,
                              double max_megapixels, const fs::path& dir, bool show_progress) {
  AnalysisCapture capture;
  std::vector<int> factor(scene.cameras.size(), 1);
  for (size_t k = 0; k < scene.cameras.size(); ++k) {
    const recon::Camera& cam = scene.cameras[k];
    factor[k] = ReductionFactor(cam.width, cam.height, max_megapixels);
    if (factor[k] > 1) {
      capture.cameras[cam.name] = {factor[k], cam.width / factor[k], cam.height / factor[k]};
    }
  }
  if (capture.cameras.empty()) return capture;
  capture.reduced = true;
  recon::SceneDocument doc(declared);
  doc.SetCameras(Json::object());
  for (size_t k = 0; k < scene.cameras.size(); ++k) {
    recon::Camera cam = scene.cameras[k];
    const int f = factor[k];
    cam.width /= f;
    cam.height /= f;
    for (int i = 0; i < 4; ++i) cam.params[i] /= f;
    doc.SetCamera(cam.name, cam);
  }
  fs::create_directories(dir);
  Progress progress("igi-diagnose: reducing the photos", int64_t(scene.photos.size()), 2.0,
                    show_progress && ProgressAllowed());
  for (size_t i = 0; i < scene.photos.size(); ++i) {
    const recon::Photo& p = scene.photos[i];
    doc.SetPhotoCamera(i, scene.cameras[p.camera].name);
    const int f = factor[p.camera];
    if (f == 1) continue;
    const fs::path sub = dir / "photos" / std::to_string(i);
    fs::create_directories(sub);
    const fs::path file = fs::absolute(sub / p.file.filename().replace_extension(".exr"));
    const fs::path mask = fs::absolute(sub / "mask.png");
    const bool masked = ReducePhoto(p, f, file, mask);
    doc.SetPhotoFile(i, file);
    doc.SetPhotoMask(i, masked ? std::optional<fs::path>(mask) : std::nullopt);
    progress.Add();
  }
  progress.Finish();
  capture.scene_file = dir / "scene.json";
  WriteJsonFile(capture.scene_file, doc.json(), 1);
  return capture;
}

Json AtDeclaredSize(Json document, const recon::Scene& declared) {
  recon::SceneDocument doc(std::move(document));
  for (const recon::Camera& cam : declared.cameras) {
    if (doc.HasCamera(cam.name)) doc.SetCameraIntrinsics(cam.name, cam);
  }
  for (size_t i = 0; i < declared.photos.size() && i < doc.NumPhotos(); ++i) {
    const recon::Photo& p = declared.photos[i];
    doc.SetPhotoFile(i, fs::absolute(p.file).lexically_normal());
    doc.SetPhotoMask(i, p.mask ? std::optional<fs::path>(fs::absolute(*p.mask).lexically_normal())
                               : std::nullopt);
  }
  return std::move(doc).json();
}

Json AnalysisCaptureJson(const AnalysisCapture& capture, double max_megapixels) {
  Json cams = Json::object();
  for (const auto& [name, r] : capture.cameras) {
    cams[name] = {{"factor", r.factor}, {"width", r.width}, {"height", r.height}};
  }
  return {{"max_megapixels", max_megapixels},
          {"cameras", cams},
          {"rule",
           "photos over max_megapixels are analysed as the means of their factor x factor pixel "
           "blocks (camera intrinsics divided by the factor); the final scene.json names the "
           "photos and intrinsics as declared"}};
}

}  // namespace igi::diagnose
