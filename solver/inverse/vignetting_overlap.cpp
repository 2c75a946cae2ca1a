#include "solver/inverse/vignetting_overlap.h"

#include <algorithm>
#include <cmath>
#include <mutex>

#include "solver/inverse/photo_model.h"
#include "solver/render/ray_scene.h"
#include "tools/common/error.h"
#include "tools/common/image.h"
#include "tools/common/parallel.h"

namespace igi::solver {
namespace {

// A pair before its values are read: where each photo sees the point.
struct PairRef {
  int photo_a, photo_b;
  Eigen::Vector2d pixel_a, pixel_b;
};

// The mean of the channels at continuous pixel p (bilinear between pixel centres); 0 where the
// mask (if any) is 0 at one of the four pixels, so that the pair is dropped.
double Luminance(const Image& image, const Image* mask, const Eigen::Vector2d& p) {
  const double fx = p.x() - 0.5, fy = p.y() - 0.5;
  const int x0 = std::clamp(int(std::floor(fx)), 0, image.width - 2);
  const int y0 = std::clamp(int(std::floor(fy)), 0, image.height - 2);
  const double tx = std::clamp(fx - x0, 0.0, 1.0), ty = std::clamp(fy - y0, 0.0, 1.0);
  double sum = 0;
  for (int dy = 0; dy < 2; ++dy) {
    for (int dx = 0; dx < 2; ++dx) {
      const int x = x0 + dx, y = y0 + dy;
      if (mask != nullptr && mask->at(x, y) <= 0) return 0;
      const double w = (dx ? tx : 1 - tx) * (dy ? ty : 1 - ty);
      double mean = 0;
      for (int c = 0; c < image.channels; ++c) mean += image.at(x, y, c);
      sum += w * mean / image.channels;
    }
  }
  return sum;
}

// The mean Luminance over the 3 × 3 pixels centred on p (the region_around check of the collector
// has made sure they see one surface): nine times fewer noise variance than one pixel, for
// photos of sensor or render noise. 0 when any of them is masked.
double LuminanceNear(const Image& image, const Image* mask, const Eigen::Vector2d& p) {
  double sum = 0;
  for (int dy = -1; dy <= 1; ++dy) {
    for (int dx = -1; dx <= 1; ++dx) {
      const double v = Luminance(image, mask, p + Eigen::Vector2d(dx, dy));
      if (!(v > 0)) return 0;
      sum += v;
    }
  }
  return sum / 9;
}

// Whether continuous pixel p lies at least `margin` pixels inside the image.
bool Inside(const recon::Camera& camera, const Eigen::Vector2d& p, double margin) {
  return p.x() >= margin && p.y() >= margin && p.x() <= camera.width - margin &&
         p.y() <= camera.height - margin;
}

// The sampling grid of a photo: about `samples` pixels, as many per row as the aspect gives.
std::pair<int, int> GridSize(const recon::Camera& camera, int samples) {
  const double aspect = double(camera.width) / camera.height;
  const int cols = std::max(2, int(std::lround(std::sqrt(samples * aspect))));
  return {cols, std::max(2, samples / cols)};
}

}  // namespace

OverlapPairs CollectOverlapPairs(const recon::Scene& scene, const OverlapOptions& options) {
  OverlapPairs out;
  const int num_photos = int(scene.photos.size());
  if (num_photos < 2 || scene.lightings.empty()) return out;
  // The geometry is the same under every lighting; the first photo's lighting's scene traces it.
  const render::RayScene rays(scene, scene.photos[0].lighting);
  // Only diffuse surfaces record the same radiance toward every camera: the Lambertian regions,
  // when the scene declares any.
  std::vector<bool> compared(scene.materials.size(), false);
  for (size_t m = 0; m < scene.materials.size(); ++m) {
    compared[m] = scene.materials[m].brdf == recon::BrdfModel::kLambert;
  }
  if (std::none_of(compared.begin(), compared.end(), [](bool c) { return c; })) {
    compared.assign(scene.materials.size(), true);
  }
  // Whether the pixels one pixel away (diagonally) from continuous pixel p of `camera` see
  // `region` as p does: a value read there is not a mix of two surfaces, nor of a surface and
  // a light.
  auto region_around = [&](const recon::Camera& camera, const Eigen::Vector2d& p, int region) {
    const Eigen::Vector3d origin = camera.CenterInWorld();
    for (const Eigen::Vector2d& d : {Eigen::Vector2d(-1, -1), Eigen::Vector2d(1, -1),
                                     Eigen::Vector2d(-1, 1), Eigen::Vector2d(1, 1)}) {
      const auto hit = rays.TraceSurface(origin, camera.WorldRayFromImg(p + d).normalized());
      if (!hit || hit->region != region) return false;
    }
    return true;
  };
  std::vector<std::vector<PairRef>> refs(static_cast<size_t>(num_photos));
  std::vector<int> hits(static_cast<size_t>(num_photos), 0);
  ParallelFor(0, num_photos, [&](int64_t ia) {
    const int a = int(ia);
    const recon::Photo& photo_a = scene.photos[size_t(a)];
    const recon::Camera& cam_a = scene.cameras[size_t(photo_a.camera)];
    const Eigen::Vector3d origin = cam_a.CenterInWorld();
    const auto [cols, rows] = GridSize(cam_a, options.samples_per_photo);
    for (int row = 0; row < rows; ++row) {
      for (int col = 0; col < cols; ++col) {
        const Eigen::Vector2d pixel_a((col + 0.5) * cam_a.width / cols,
                                      (row + 0.5) * cam_a.height / rows);
        if (!Inside(cam_a, pixel_a, 2)) continue;
        const Eigen::Vector3d dir = cam_a.WorldRayFromImg(pixel_a).normalized();
        const auto hit = rays.TraceSurface(origin, dir);
        if (!hit || !compared[size_t(hit->region)] ||
            std::abs(dir.dot(hit->n_geo)) < options.min_cos ||
            !region_around(cam_a, pixel_a, hit->region)) {
          continue;
        }
        ++hits[size_t(a)];
        const Eigen::Vector3d start = hit->position + hit->n_geo * rays.ray_epsilon();
        for (int b = a + 1; b < num_photos; ++b) {
          const recon::Photo& photo_b = scene.photos[size_t(b)];
          if (photo_b.lighting != photo_a.lighting) continue;
          const recon::Camera& cam_b = scene.cameras[size_t(photo_b.camera)];
          const Eigen::Vector3d to_b = cam_b.CenterInWorld() - start;
          const double distance = to_b.norm();
          // The same side of the surface (n_geo faces photo a), not too grazing.
          if (to_b.dot(hit->n_geo) < options.min_cos * distance) continue;
          const auto pixel_b = cam_b.ImgFromWorld(hit->position);
          if (!pixel_b || !Inside(cam_b, *pixel_b, 2)) continue;
          if (rays.Occluded(start, to_b / distance, distance)) continue;
          if (!region_around(cam_b, *pixel_b, hit->region)) continue;
          refs[size_t(a)].push_back({a, b, pixel_a, *pixel_b});
        }
      }
    }
  });
  std::vector<PairRef> all;
  for (int a = 0; a < num_photos; ++a) {
    all.insert(all.end(), refs[size_t(a)].begin(), refs[size_t(a)].end());
    out.surface_hits += hits[size_t(a)];
  }
  for (const recon::Photo& photo : scene.photos) {
    const auto [cols, rows] =
        GridSize(scene.cameras[size_t(photo.camera)], options.samples_per_photo);
    out.traced += cols * rows;
  }
  // The values, one photo in memory at a time: ln_a for the pairs that start at the photo,
  // ln_b for those that end there. Non-positive means "dropped".
  std::vector<double> value_a(all.size(), 0.0), value_b(all.size(), 0.0);
  std::vector<std::vector<size_t>> at_a(static_cast<size_t>(num_photos)), at_b(at_a);
  for (size_t i = 0; i < all.size(); ++i) {
    at_a[size_t(all[i].photo_a)].push_back(i);
    at_b[size_t(all[i].photo_b)].push_back(i);
  }
  for (int p = 0; p < num_photos; ++p) {
    if (at_a[size_t(p)].empty() && at_b[size_t(p)].empty()) continue;
    const recon::Photo& photo = scene.photos[size_t(p)];
    // The recorded values made linear, with the scene's declared vignetting left in: it is
    // what is being measured.
    recon::Camera camera = scene.cameras[size_t(photo.camera)];
    camera.vignetting_k1 = camera.vignetting_k2 = 0;
    const Image recorded = ReadImage(photo.file, 3);
    if (recorded.width != camera.width || recorded.height != camera.height) {
      throw InputError(
          DescribeProblem(photo.file.string(), "",
                          std::to_string(recorded.width) + "x" + std::to_string(recorded.height),
                          "must be the size of camera " + camera.name));
    }
    const Image linear = LinearRadianceOfPhoto(photo, camera, recorded);
    std::optional<Image> mask;
    if (photo.mask) mask = ReadImage(*photo.mask, 1);
    const Image* m = mask ? &*mask : nullptr;
    for (size_t i : at_a[size_t(p)]) value_a[i] = LuminanceNear(linear, m, all[i].pixel_a);
    for (size_t i : at_b[size_t(p)]) value_b[i] = LuminanceNear(linear, m, all[i].pixel_b);
  }
  for (size_t i = 0; i < all.size(); ++i) {
    if (!(value_a[i] > 0) || !(value_b[i] > 0)) continue;
    const recon::Camera& cam_a = scene.cameras[size_t(scene.photos[size_t(all[i].photo_a)].camera)];
    const recon::Camera& cam_b = scene.cameras[size_t(scene.photos[size_t(all[i].photo_b)].camera)];
    out.pairs.push_back(
        {all[i].photo_a, all[i].photo_b,
         calib::VignettingRadius2(all[i].pixel_a.x(), all[i].pixel_a.y(), cam_a.principal_x_px(),
                                  cam_a.principal_y_px(), cam_a.width, cam_a.height),
         calib::VignettingRadius2(all[i].pixel_b.x(), all[i].pixel_b.y(), cam_b.principal_x_px(),
                                  cam_b.principal_y_px(), cam_b.width, cam_b.height),
         std::log(value_a[i]), std::log(value_b[i])});
  }
  return out;
}

}  // namespace igi::solver
