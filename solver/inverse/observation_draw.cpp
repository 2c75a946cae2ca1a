#include "solver/inverse/observation_draw.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "solver/render/brdf.h"
#include "solver/render/ray_scene.h"
#include "solver/render/sampling.h"
#include "tools/common/parallel.h"

namespace igi::solver {

bool NearHighlight(const render::RayScene& lighting, const Eigen::Vector3d& position,
                   const Eigen::Vector3d& view, const Eigen::Vector3d& normal) {
  for (int l = 0; l < lighting.num_lights(); ++l) {
    if (lighting.light_type(l) == recon::LightType::kAmbient) continue;
    const render::LightSample s = lighting.SampleLight(l, position, Eigen::Vector3d(0.5, 0.5, 0.5));
    const Eigen::Vector3d h = (s.wi + view).normalized();
    const double c = h.dot(normal);
    if (c > 0 && (1 - c * c) < 0.36 * c * c) return true;
  }
  return false;
}

bool ObservationDraw::Draws(int photo, int x, int y, int stride, int region, bool near, int* x0,
                            int* y0, int* size) const {
  const int b = Block(region, near);
  if (b <= 1) {
    *x0 = x, *y0 = y, *size = 1;
  } else {
    const int cx = x / stride, cy = y / stride;
    if (cx % b != b / 2 || cy % b != b / 2) return false;  // not the centre of its block
    *x0 = (cx - b / 2) * stride, *y0 = (cy - b / 2) * stride, *size = b * stride;
  }
  return render::InHashedSubset(PixelKey(photo, *x0, *y0), Threshold(region, near));
}

double PixelsAtStride(const recon::Scene& scene, int pixel_stride) {
  double n = 0;
  for (const recon::Photo& p : scene.photos) {
    const recon::Camera& cam = scene.cameras[p.camera];
    n += double((cam.width + pixel_stride - 1) / pixel_stride) *
         double((cam.height + pixel_stride - 1) / pixel_stride);
  }
  return n;
}

std::vector<RegionPixelCensus> CensusPixels(
    const recon::Scene& scene, const std::vector<const render::RayScene*>& lighting_scenes,
    const std::vector<char>& lobe_class, const ObservationDrawOptions& options) {
  const size_t regions = scene.materials.size();
  std::vector<RegionPixelCensus> census(regions);
  const int stride = options.pixel_stride;
  for (size_t i = 0; i < scene.photos.size(); ++i) {
    const recon::Photo& photo = scene.photos[i];
    const recon::Camera& cam = scene.cameras[photo.camera];
    const render::RayScene* geometry = lighting_scenes[photo.lighting];
    if (geometry == nullptr) continue;
    const int cols = (cam.width + stride - 1) / stride, rows = (cam.height + stride - 1) / stride;
    // Every step-th pixel of the stride's grid in x and y, each standing for step² of them.
    const int step =
        std::max(1, int(std::ceil(std::sqrt(double(cols) * rows / options.census_rays_per_photo))));
    const double weight = double(step) * step;
    const int grid_rows = (rows + step - 1) / step;
    std::vector<std::vector<RegionPixelCensus>> per_row(grid_rows);
    const Eigen::Vector3d center = cam.CenterInWorld();
    ParallelFor(
        0, grid_rows,
        [&](int64_t gr) {
          std::vector<RegionPixelCensus>& counts = per_row[gr];
          counts.assign(regions, {});
          const int y = std::min(int(gr) * step * stride + stride / 2, cam.height - 1);
          for (int gx = 0; gx * step < cols; ++gx) {
            const int x = gx * step * stride + stride / 2;
            if (x >= cam.width) break;
            const Eigen::Vector3d dir = cam.WorldRayFromImg(Eigen::Vector2d(x + 0.5, y + 0.5));
            const std::optional<render::SurfaceHit> hit = geometry->TraceSurface(center, dir);
            if (!hit || !recon::IsReflective(scene.materials[hit->region].brdf)) continue;
            const bool near =
                lobe_class[hit->region] && NearHighlight(*geometry, hit->position, -dir, hit->n_s);
            (near ? counts[hit->region].near : counts[hit->region].rest) += weight;
          }
        },
        options.num_threads);
    for (const std::vector<RegionPixelCensus>& counts : per_row) {
      for (size_t r = 0; r < regions; ++r) {
        census[r].near += counts[r].near;
        census[r].rest += counts[r].rest;
      }
    }
  }
  return census;
}

ObservationDraw PlanObservationDraw(const std::vector<RegionPixelCensus>& census,
                                    const std::vector<char>& lobe_class,
                                    const ObservationDrawOptions& options) {
  const size_t regions = census.size();
  ObservationDraw d;
  d.lobe_class = lobe_class;
  d.lobe_class.resize(regions, 0);
  d.p_near.assign(regions, 1.0);
  d.p_rest.assign(regions, 1.0);
  d.block_near.assign(regions, 1);
  d.block_rest.assign(regions, 1);
  // Each class's block side: ⌊1/√p⌋ stride cells, within [1, max_block].
  auto blocks = [&] {
    auto side = [&](double p) {
      return p > 0 ? std::clamp(int(std::floor(1.0 / std::sqrt(p) + 1e-9)), 1,
                                std::max(1, options.max_block))
                   : 1;
    };
    for (size_t r = 0; r < regions; ++r) {
      d.block_near[r] = side(d.p_near[r]);
      d.block_rest[r] = side(d.p_rest[r]);
    }
  };
  d.budget = options.budget > 0 ? options.budget : std::numeric_limits<double>::infinity();
  // Per region and class: the pixels, and how many the region's fit needs.
  std::vector<double> n_near(regions), n_rest(regions), need_near(regions), need_rest(regions);
  double near_sum = 0, rest_sum = 0;  // the needs of each class
  for (size_t r = 0; r < regions; ++r) {
    n_near[r] = d.lobe_class[r] ? census[r].near : 0.0;
    n_rest[r] = census[r].rest + (d.lobe_class[r] ? 0.0 : census[r].near);
    need_near[r] = std::min(n_near[r], double(options.max_highlight_samples));
    need_rest[r] = std::min(n_rest[r], double(options.max_fit_samples));
    d.available += n_near[r] + n_rest[r];
    near_sum += need_near[r];
    rest_sum += need_rest[r];
  }
  d.expected = d.available;
  if (d.available <= d.budget) return d;
  auto share = [](double keep, double n) { return n > 0 ? std::min(1.0, keep / n) : 1.0; };
  // The needs within their share of the budget, so that the even draw below still covers every
  // surface: each region's fit samples first (a region seen by few pixels has only those), up
  // to the share less what the highlight candidates keep at least (half of it), the highlight
  // candidates in what is left; each class scaled down alike where it exceeds its part.
  const double limit = kNeedsShare * d.budget;
  if (near_sum + rest_sum > limit) {
    const double rest_part = std::min(rest_sum, limit - std::min(near_sum, 0.5 * limit));
    const double near_part = std::min(near_sum, limit - rest_part);
    for (size_t r = 0; r < regions; ++r) {
      if (rest_sum > 0) need_rest[r] *= rest_part / rest_sum;
      if (near_sum > 0) need_near[r] *= near_part / near_sum;
    }
  }
  // One probability q for every pixel beyond the needs: the total kept is increasing in q.
  auto kept = [&](double q) {
    double k = 0;
    for (size_t r = 0; r < regions; ++r) {
      k += std::max(need_near[r], q * n_near[r]) + std::max(need_rest[r], q * n_rest[r]);
    }
    return k;
  };
  double lo = 0, hi = 1;
  for (int it = 0; it < 60; ++it) {
    const double mid = 0.5 * (lo + hi);
    (kept(mid) <= d.budget ? lo : hi) = mid;
  }
  for (size_t r = 0; r < regions; ++r) {
    d.p_near[r] = share(std::max(need_near[r], lo * n_near[r]), n_near[r]);
    d.p_rest[r] = share(std::max(need_rest[r], lo * n_rest[r]), n_rest[r]);
  }
  d.expected = kept(lo);
  blocks();
  return d;
}

}  // namespace igi::solver
