#include "solver/inverse/scene_scale.h"

#include <algorithm>
#include <cmath>

#include "solver/render/sampling.h"

namespace igi::solver {

SceneScale MeasureSceneScale(const recon::Scene& scene, const render::RayScene* geometry,
                             int pixels_per_camera) {
  SceneScale out;
  Eigen::Vector3f lo = Eigen::Vector3f::Constant(INFINITY), hi = -lo;
  for (const Eigen::Vector3f& p : scene.mesh.positions) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  out.diagonal_m = scene.mesh.positions.empty() ? 0.0 : double((hi - lo).norm());
  out.scale_m = out.diagonal_m;
  double weighted = 0, weights = 0;
  int64_t rays = 0, hits = 0;
  for (size_t c = 0; geometry && c < scene.cameras.size(); ++c) {
    const recon::Camera& cam = scene.cameras[c];
    if (cam.width <= 0 || cam.height <= 0) continue;
    const double aspect = double(cam.width) / cam.height;
    const int nx = std::max(1, int(std::round(std::sqrt(pixels_per_camera * aspect))));
    const int ny = std::max(1, int(std::round(double(pixels_per_camera) / nx)));
    const Eigen::Vector3d centre = cam.CenterInWorld();
    for (int j = 0; j < ny; ++j) {
      for (int i = 0; i < nx; ++i) {
        const Eigen::Vector2d pixel((i + 0.5) * cam.width / nx, (j + 0.5) * cam.height / ny);
        const Eigen::Vector3d dir = cam.WorldRayFromImg(pixel);
        const std::optional<render::RayHit> hit = geometry->Intersect(centre, dir);
        if (!hit || hit->triangle < 0) continue;
        Eigen::Vector3d n = geometry->face_normal(hit->triangle);
        if (n.dot(dir) > 0) n = -n;  // the side the camera sees
        const double cos_surface = std::max(0.05, -n.dot(dir));
        // The pixel's solid angle relative to the axis' (pinhole: cos³ of the off-axis angle).
        const double cos_axis = std::abs(cam.CamRayFromImg(pixel).z());
        const double w = hit->t * hit->t / cos_surface * cos_axis * cos_axis * cos_axis;
        const uint64_t key = (uint64_t(c) << 40) ^ (uint64_t(j) << 20) ^ uint64_t(i);
        const Eigen::Vector2d u(
            double(render::MixBits(key) >> 11) * 0x1.0p-53,
            double(render::MixBits(key ^ 0x5851f42d4c957f2dULL) >> 11) * 0x1.0p-53);
        const Eigen::Vector3d wi =
            render::Frame::FromNormal(n).ToWorld(render::SampleCosineHemisphere(u));
        const Eigen::Vector3d origin = centre + dir * hit->t + n * geometry->ray_epsilon();
        ++rays;
        const std::optional<render::RayHit> next = geometry->Intersect(origin, wi);
        if (!next) continue;
        ++hits;
        weighted += w * next->t;
        weights += w;
      }
    }
  }
  out.hit_fraction = rays > 0 ? double(hits) / double(rays) : 0.0;
  if (out.hit_fraction >= 0.5 && weights > 0) {
    out.free_path_m = weighted / weights;
    out.scale_m = std::min(out.diagonal_m, kDiagonalPerFreePath * out.free_path_m);
  }
  return out;
}

SceneScale MeasureSceneScale(const recon::Scene& scene) {
  if (scene.lightings.empty()) return MeasureSceneScale(scene, nullptr);
  const render::RayScene geometry(scene, 0);
  return MeasureSceneScale(scene, &geometry);
}

}  // namespace igi::solver
