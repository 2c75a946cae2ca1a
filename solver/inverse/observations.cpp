#include "solver/inverse/observations.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <mutex>

#include "solver/inverse/observation_draw.h"
#include "solver/inverse/patches.h"
#include "solver/render/ray_scene.h"
#include "tools/common/parallel.h"

namespace igi::solver {

double AutoSaturation(const Image& image) {
  float max_value = 0;
  for (float v : image.pixels) {
    if (std::isfinite(v)) max_value = std::max(max_value, v);
  }
  if (!(max_value > 0)) return std::numeric_limits<double>::infinity();
  int at_max = 0;
  for (int i = 0; i < image.width * image.height; ++i) {
    for (int c = 0; c < image.channels; ++c) {
      if (image.pixels[size_t(i) * image.channels + c] == max_value) {
        ++at_max;
        break;
      }
    }
  }
  return at_max >= 3 ? double(max_value) : std::numeric_limits<double>::infinity();
}

double PixelNormalSpread(const std::array<Eigen::Vector3d, 4>& quarter, const Eigen::Vector3d& n) {
  // The normal's change across the pixel in x and in y (the quarter-pixel samples are half a
  // pixel apart, two pairs each), tangential part; a box of width w has variance w²/12 along it.
  Eigen::Vector3d a = quarter[1] + quarter[3] - quarter[0] - quarter[2];
  Eigen::Vector3d b = quarter[2] + quarter[3] - quarter[0] - quarter[1];
  a -= n * n.dot(a);
  b -= n * n.dot(b);
  return (a.squaredNorm() + b.squaredNorm()) / 12.0;
}

namespace {

// Whether `h` lies on the smooth piece of `centre`'s region: the same region, its normal at a
// cosine above cos_min from the centre's, off the centre's face plane by under max_offset·centre.t.
bool OnPieceOf(const std::optional<render::SurfaceHit>& h, const render::SurfaceHit& centre,
               double cos_min, double max_offset) {
  return h && h->region == centre.region && h->n_s.dot(centre.n_s) > cos_min &&
         std::abs(centre.n_geo.dot(h->position - centre.position)) < max_offset * centre.t;
}

}  // namespace

std::optional<std::array<Eigen::Vector3d, 4>> QuarterPixelNormals(
    const render::RayScene& geometry, const recon::Camera& camera, int x, int y,
    const render::SurfaceHit& centre, double cos_min, double max_offset, int size) {
  const Eigen::Vector3d eye = camera.CenterInWorld();
  std::array<Eigen::Vector3d, 4> normals;
  for (int k = 0; k < 4; ++k) {
    const double ox = ((k & 1) ? 0.75 : 0.25) * size, oy = ((k & 2) ? 0.75 : 0.25) * size;
    const std::optional<render::SurfaceHit> h =
        geometry.TraceSurface(eye, camera.WorldRayFromImg(Eigen::Vector2d(x + ox, y + oy)));
    if (!OnPieceOf(h, centre, cos_min, max_offset)) return std::nullopt;
    normals[k] = h->n_s;
  }
  return normals;
}

PixelUse CheckPixel(const Image& radiance, const std::vector<uint8_t>* mask, int x, int y,
                    double saturation, Eigen::Vector3f* value) {
  if (mask != nullptr && (*mask)[size_t(y) * radiance.width + x] == 0) return PixelUse::kMasked;
  bool finite = true, clipped = false;
  for (int c = 0; c < 3; ++c) {
    const float v = radiance.at(x, y, std::min(c, radiance.channels - 1));
    (*value)[c] = v;
    if (!std::isfinite(v) || v < 0) finite = false;
    if (v >= saturation) clipped = true;
  }
  if (!finite) return PixelUse::kInvalid;
  return clipped ? PixelUse::kClipped : PixelUse::kUsable;
}

std::vector<Observation> CollectObservations(
    const recon::Scene& scene, int photo_index, const Image& radiance,
    const std::vector<uint8_t>* mask, const render::RayScene& geometry, const PatchSet& patches,
    const ObservationOptions& options, PhotoObservationStats* stats) {
  const recon::Photo& photo = scene.photos[photo_index];
  const recon::Camera& camera = scene.cameras[photo.camera];
  const double saturation = options.saturation > 0 ? options.saturation : AutoSaturation(radiance);
  const Eigen::Vector3d center = camera.CenterInWorld();
  const int stride = options.pixel_stride;
  const int rows = (camera.height + stride - 1) / stride;
  std::vector<std::vector<Observation>> per_row(rows);
  std::vector<PhotoObservationStats> row_stats(rows);
  const double cos_edge = std::cos(10.0 * render::kPi / 180.0);
  // The observation of the square of `size` pixels at (x0, y0) whose centre ray `dir` meets
  // `hit`, of radiance `value`, its normals at the square's quarter points `quarter`.
  auto make = [&](int x0, int y0, int size, const render::SurfaceHit& hit,
                  const Eigen::Vector3d& dir, const Eigen::Vector3f& value,
                  const std::array<Eigen::Vector3d, 4>& quarter) {
    Observation o;
    o.photo = photo_index;
    o.x = x0, o.y = y0, o.size = size;
    o.triangle = hit.triangle;
    o.b1 = float(hit.b1), o.b2 = float(hit.b2);
    o.region = hit.region;
    o.patch = patches.PatchOf(hit.triangle, hit.b1, hit.b2);
    o.position = hit.position.cast<float>();
    o.normal = hit.n_s.cast<float>();
    o.view = (-dir).cast<float>();
    o.radiance = value;
    o.lobe_blur2 = float(PixelNormalSpread(quarter, hit.n_s));
    return o;
  };
  // The observation of the block of `size` pixels at (x0, y0): its pixels' mean, when every one
  // is usable and the block lies on one smooth piece of one region (its centre, its stride
  // cells' centres and its quarter points); none otherwise.
  auto block = [&](int x0, int y0, int size) -> std::optional<Observation> {
    if (x0 + size > camera.width || y0 + size > camera.height) return std::nullopt;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (int y = y0; y < y0 + size; ++y) {
      for (int x = x0; x < x0 + size; ++x) {
        Eigen::Vector3f value;
        if (CheckPixel(radiance, mask, x, y, saturation, &value) != PixelUse::kUsable) {
          return std::nullopt;
        }
        sum += value.cast<double>();
      }
    }
    const Eigen::Vector3d dir =
        camera.WorldRayFromImg(Eigen::Vector2d(x0 + 0.5 * size, y0 + 0.5 * size));
    const std::optional<render::SurfaceHit> hit = geometry.TraceSurface(center, dir);
    if (!hit || !recon::IsReflective(scene.materials[hit->region].brdf)) return std::nullopt;
    for (int y = y0 + stride / 2; y < y0 + size; y += stride) {
      for (int x = x0 + stride / 2; x < x0 + size; x += stride) {
        const Eigen::Vector2d px(x + 0.5, y + 0.5);
        if (!OnPieceOf(geometry.TraceSurface(center, camera.WorldRayFromImg(px)), *hit, cos_edge,
                       0.01)) {
          return std::nullopt;
        }
      }
    }
    const auto quarter = QuarterPixelNormals(geometry, camera, x0, y0, *hit, cos_edge, 0.01, size);
    if (!quarter) return std::nullopt;
    return make(x0, y0, size, *hit, dir, (sum / (double(size) * size)).cast<float>(), *quarter);
  };
  ParallelFor(
      0, rows,
      [&](int64_t r) {
        const int y = int(r) * stride;
        PhotoObservationStats& st = row_stats[r];
        for (int x = stride / 2; x < camera.width; x += stride) {
          const int yy = std::min(y + stride / 2, camera.height - 1);
          ++st.pixels;
          Eigen::Vector3f value;
          const PixelUse use = CheckPixel(radiance, mask, x, yy, saturation, &value);
          if (use != PixelUse::kUsable) {
            ++(use == PixelUse::kMasked    ? st.masked
               : use == PixelUse::kInvalid ? st.invalid
                                           : st.clipped);
            continue;
          }
          const Eigen::Vector3d dir = camera.WorldRayFromImg(Eigen::Vector2d(x + 0.5, yy + 0.5));
          const std::optional<render::SurfaceHit> hit = geometry.TraceSurface(center, dir);
          if (!hit || !recon::IsReflective(scene.materials[hit->region].brdf)) {
            ++st.background;
            continue;
          }
          int x0 = x, y0 = yy, size = 1;
          if (options.draw != nullptr) {
            const bool near = options.draw->lobe_class[hit->region] &&
                              NearHighlight(geometry, hit->position, -dir, hit->n_s);
            if (!options.draw->Draws(photo_index, x, yy, stride, hit->region, near, &x0, &y0,
                                     &size)) {
              ++st.undrawn;
              continue;
            }
            if (size > 1) {
              if (std::optional<Observation> o = block(x0, y0, size)) {
                per_row[r].push_back(*o);
                ++st.valid;
                ++st.blocks;
                continue;
              }
            }
          }
          // The pixel's footprint must lie on one smooth piece of one region.
          const auto corner_normal =
              QuarterPixelNormals(geometry, camera, x, yy, *hit, cos_edge, 0.01);
          if (!corner_normal) {
            ++st.edge;
            continue;
          }
          const Observation o = make(x, yy, 1, *hit, dir, value, *corner_normal);
          per_row[r].push_back(o);
          ++st.valid;
        }
      },
      options.num_threads);
  std::vector<Observation> out;
  PhotoObservationStats total;
  total.saturation = saturation;
  for (int r = 0; r < rows; ++r) {
    out.insert(out.end(), per_row[r].begin(), per_row[r].end());
    total.pixels += row_stats[r].pixels;
    total.valid += row_stats[r].valid;
    total.masked += row_stats[r].masked;
    total.clipped += row_stats[r].clipped;
    total.invalid += row_stats[r].invalid;
    total.background += row_stats[r].background;
    total.edge += row_stats[r].edge;
    total.undrawn += row_stats[r].undrawn;
    total.blocks += row_stats[r].blocks;
  }
  if (stats != nullptr) *stats = total;
  return out;
}

}  // namespace igi::solver
