#include "solver/inverse/albedo_map.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <string>

#include "solver/render/ray_scene.h"
#include "solver/inverse/texel_splat.h"
#include "tools/common/error.h"

namespace igi::solver {

namespace {

// Per texel: numerator (3), denominator (3), summed bilinear weight.
constexpr int kSlots = 7;
constexpr int kWeightSlot = 6;

// One level of the push-pull pyramid, one channel.
struct Level {
  int width = 0, height = 0;
  std::vector<float> value, weight;
  Level(int w, int h)
      : width(w), height(h), value(size_t(w) * h, 0.f), weight(size_t(w) * h, 0.f) {}
  size_t at(int x, int y) const { return size_t(y) * width + x; }
};

// Pull: each coarse texel is the weighted mean of its (up to) 2×2 children; weights add up and
// saturate at 1.
Level Coarser(const Level& fine) {
  Level coarse((fine.width + 1) / 2, (fine.height + 1) / 2);
  for (int y = 0; y < coarse.height; ++y) {
    for (int x = 0; x < coarse.width; ++x) {
      double sum_w = 0, sum_v = 0;
      for (int dy = 0; dy < 2; ++dy) {
        for (int dx = 0; dx < 2; ++dx) {
          const int fx = 2 * x + dx, fy = 2 * y + dy;
          if (fx >= fine.width || fy >= fine.height) continue;
          const size_t i = fine.at(fx, fy);
          sum_w += fine.weight[i];
          sum_v += double(fine.weight[i]) * fine.value[i];
        }
      }
      if (sum_w > 0) coarse.value[coarse.at(x, y)] = float(sum_v / sum_w);
      coarse.weight[coarse.at(x, y)] = float(std::min(1.0, sum_w));
    }
  }
  return coarse;
}

// Bilinear lookup of a coarse level at the centre of fine texel (x, y), indices clamped.
float Upsampled(const Level& coarse, int x, int y) {
  const double cx = (x + 0.5) / 2 - 0.5, cy = (y + 0.5) / 2 - 0.5;
  const int x0 = static_cast<int>(std::floor(cx)), y0 = static_cast<int>(std::floor(cy));
  const double fx = cx - x0, fy = cy - y0;
  auto texel = [&](int xi, int yi) {
    return double(coarse.value[coarse.at(std::clamp(xi, 0, coarse.width - 1),
                                         std::clamp(yi, 0, coarse.height - 1))]);
  };
  return float((1 - fy) * ((1 - fx) * texel(x0, y0) + fx * texel(x0 + 1, y0)) +
               fy * ((1 - fx) * texel(x0, y0 + 1) + fx * texel(x0 + 1, y0 + 1)));
}

// Push-pull fill (Gortler et al. 1996): texels of weight 1 keep their value, the others are
// blended with the filled coarser level. Needs some weight somewhere.
void PushPull(Level* level0) {
  std::vector<Level> pyramid;
  pyramid.push_back(std::move(*level0));
  while (pyramid.back().width > 1 || pyramid.back().height > 1) {
    pyramid.push_back(Coarser(pyramid.back()));
  }
  for (int l = static_cast<int>(pyramid.size()) - 2; l >= 0; --l) {
    Level& fine = pyramid[l];
    const Level& coarse = pyramid[l + 1];
    for (int y = 0; y < fine.height; ++y) {
      for (int x = 0; x < fine.width; ++x) {
        const size_t i = fine.at(x, y);
        const float a = fine.weight[i];
        if (a >= 1) continue;
        fine.value[i] = a * fine.value[i] + (1 - a) * Upsampled(coarse, x, y);
      }
    }
  }
  *level0 = std::move(pyramid.front());
}

// Whether the centre of texel (x, y) (pixel coordinates x right, y down) is inside the triangle.
bool Inside(const std::array<Eigen::Vector2d, 3>& p, double x, double y) {
  double sign = 0;
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector2d& a = p[k];
    const Eigen::Vector2d& b = p[(k + 1) % 3];
    const double e = (b.x() - a.x()) * (y - a.y()) - (b.y() - a.y()) * (x - a.x());
    if (e == 0) continue;
    if (sign == 0) sign = e;
    if ((e > 0) != (sign > 0)) return false;
  }
  return true;
}

}  // namespace

struct AlbedoMapBuilder::Tile {
  std::array<double, kTile * kTile * kSlots> sums{};
  double* texel(int x, int y) { return &sums[((y % kTile) * kTile + (x % kTile)) * kSlots]; }
  const double* texel(int x, int y) const {
    return &sums[((y % kTile) * kTile + (x % kTile)) * kSlots];
  }
};

AlbedoMapBuilder::AlbedoMapBuilder(const RegionAtlas& atlas, double min_texel_weight)
    : atlas_(&atlas), min_texel_weight_(min_texel_weight) {
  if (atlas.width <= 0 || atlas.height <= 0) {
    throw Error("AlbedoMapBuilder: the atlas of region " + std::to_string(atlas.region) +
                " is empty");
  }
  tiles_x_ = (atlas.width + kTile - 1) / kTile;
  tiles_y_ = (atlas.height + kTile - 1) / kTile;
  tiles_.resize(size_t(tiles_x_) * tiles_y_);
}

AlbedoMapBuilder::~AlbedoMapBuilder() = default;
AlbedoMapBuilder::AlbedoMapBuilder(AlbedoMapBuilder&&) noexcept = default;
AlbedoMapBuilder& AlbedoMapBuilder::operator=(AlbedoMapBuilder&&) noexcept = default;

AlbedoMapBuilder::Tile* AlbedoMapBuilder::TileAt(int x, int y) {
  std::unique_ptr<Tile>& tile = tiles_[size_t(y / kTile) * tiles_x_ + x / kTile];
  if (!tile) tile = std::make_unique<Tile>();
  return tile.get();
}

const AlbedoMapBuilder::Tile* AlbedoMapBuilder::TileAt(int x, int y) const {
  return tiles_[size_t(y / kTile) * tiles_x_ + x / kTile].get();
}

void AlbedoMapBuilder::Add(int triangle, double b1, double b2, const Eigen::Vector3d& numerator,
                           const Eigen::Vector3d& denominator) {
  if (triangle < 0 || triangle >= static_cast<int>(atlas_->corner_uv.size())) {
    throw Error("AlbedoMapBuilder::Add: triangle " + std::to_string(triangle) +
                " is not in the mesh");
  }
  if (!numerator.allFinite() || !denominator.allFinite() || !std::isfinite(b1) ||
      !std::isfinite(b2)) {
    return;
  }
  const TexelSplat splat = BilinearTexelSplat(*atlas_, triangle, b1, b2);
  for (int k = 0; k < 4; ++k) {
    const double w = splat.weight[k];
    if (w <= 0) continue;
    double* t = TileAt(splat.x[k], splat.y[k])->texel(splat.x[k], splat.y[k]);
    for (int c = 0; c < 3; ++c) {
      t[c] += w * numerator[c];
      t[3 + c] += w * denominator[c];
    }
    t[kWeightSlot] += w;
  }
  ++num_samples_;
}

void AlbedoMapBuilder::Merge(const AlbedoMapBuilder& other) {
  if (other.atlas_->width != atlas_->width || other.atlas_->height != atlas_->height) {
    throw Error("AlbedoMapBuilder::Merge: atlases differ in size");
  }
  for (size_t i = 0; i < tiles_.size(); ++i) {
    if (!other.tiles_[i]) continue;
    if (!tiles_[i]) {
      tiles_[i] = std::make_unique<Tile>(*other.tiles_[i]);
      continue;
    }
    for (size_t k = 0; k < tiles_[i]->sums.size(); ++k)
      tiles_[i]->sums[k] += other.tiles_[i]->sums[k];
  }
  num_samples_ += other.num_samples_;
}

bool AlbedoMapBuilder::Direct(int x, int y, int channel) const {
  const Tile* tile = TileAt(x, y);
  if (tile == nullptr) return false;
  const double* t = tile->texel(x, y);
  return t[kWeightSlot] >= min_texel_weight_ && t[3 + channel] > 0;
}

Image AlbedoMapBuilder::Finish(const Eigen::Vector3d& fallback) const {
  const int width = atlas_->width, height = atlas_->height;
  Image out(width, height, 3);
  for (int c = 0; c < 3; ++c) {
    Level level(width, height);
    bool any = false;
    for (int y = 0; y < height; ++y) {
      for (int x = 0; x < width; ++x) {
        if (!Direct(x, y, c)) continue;
        const double* t = TileAt(x, y)->texel(x, y);
        level.value[level.at(x, y)] = float(t[c] / t[3 + c]);
        level.weight[level.at(x, y)] = 1.f;
        any = true;
      }
    }
    if (any) PushPull(&level);
    for (int y = 0; y < height; ++y) {
      for (int x = 0; x < width; ++x) {
        out.at(x, y, c) = any ? level.value[level.at(x, y)] : float(fallback[c]);
      }
    }
  }
  return out;
}

void AlbedoMapBuilder::ForEachTexelCentre(
    const std::function<void(int triangle, int x, int y, double b1, double b2)>& f) const {
  const int width = atlas_->width, height = atlas_->height;
  for (int t : atlas_->triangles) {
    std::array<Eigen::Vector2d, 3> p;  // pixel coordinates: x right, y down, texel i = [i, i+1)
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector2f& uv = atlas_->corner_uv[t][k];
      p[k] = Eigen::Vector2d(uv.x() * width, (1.0 - uv.y()) * height);
    }
    const Eigen::Vector2d e1 = p[1] - p[0], e2 = p[2] - p[0];
    const double det = e1.x() * e2.y() - e1.y() * e2.x();
    if (!(std::abs(det) > 0)) continue;  // a triangle of no area in UV holds no texel centre
    const Eigen::Vector2d lo = p[0].cwiseMin(p[1]).cwiseMin(p[2]);
    const Eigen::Vector2d hi = p[0].cwiseMax(p[1]).cwiseMax(p[2]);
    const int x_begin = std::max(0, static_cast<int>(std::floor(lo.x() - 0.5)));
    const int x_end = std::min(width - 1, static_cast<int>(std::ceil(hi.x() - 0.5)));
    const int y_begin = std::max(0, static_cast<int>(std::floor(lo.y() - 0.5)));
    const int y_end = std::min(height - 1, static_cast<int>(std::ceil(hi.y() - 0.5)));
    for (int y = y_begin; y <= y_end; ++y) {
      for (int x = x_begin; x <= x_end; ++x) {
        if (!Inside(p, x + 0.5, y + 0.5)) continue;
        const Eigen::Vector2d d(x + 0.5 - p[0].x(), y + 0.5 - p[0].y());
        const double b1 = (d.x() * e2.y() - d.y() * e2.x()) / det;
        const double b2 = (e1.x() * d.y() - e1.y() * d.x()) / det;
        f(t, x, y, b1, b2);
      }
    }
  }
}

void AlbedoMapBuilder::FillTexelCentres(
    const std::function<Eigen::Vector3d(int triangle, double b1, double b2)>& value) {
  ForEachTexelCentre([&](int t, int x, int y, double b1, double b2) {
    if (Direct(x, y, 0) && Direct(x, y, 1) && Direct(x, y, 2)) return;
    const Eigen::Vector3d v = value(t, b1, b2);
    if (!v.allFinite()) return;
    double* texel = TileAt(x, y)->texel(x, y);
    for (int c = 0; c < 3; ++c) {
      texel[c] += v[c];
      texel[3 + c] += 1;
    }
    texel[kWeightSlot] += 1;
    ++num_samples_;
  });
}

double AlbedoMapBuilder::Coverage() const {
  const int width = atlas_->width, height = atlas_->height;
  std::vector<char> inside(size_t(width) * height, 0);
  ForEachTexelCentre([&](int, int x, int y, double, double) { inside[size_t(y) * width + x] = 1; });
  int64_t total = 0, direct = 0;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      if (!inside[size_t(y) * width + x]) continue;
      ++total;
      if (Direct(x, y, 0) && Direct(x, y, 1) && Direct(x, y, 2)) ++direct;
    }
  }
  return total == 0 ? 0.0 : double(direct) / double(total);
}

Image AlbedoMapBuilder::DirectMask() const {
  Image mask(atlas_->width, atlas_->height, 1);
  for (int y = 0; y < atlas_->height; ++y) {
    for (int x = 0; x < atlas_->width; ++x) {
      mask.at(x, y, 0) = Direct(x, y, 0) && Direct(x, y, 1) && Direct(x, y, 2) ? 1.f : 0.f;
    }
  }
  return mask;
}

double AlbedoPsnr(const Image& estimate, const Image& truth, double peak) {
  if (estimate.width != truth.width || estimate.height != truth.height ||
      estimate.channels != truth.channels || estimate.pixels.size() != truth.pixels.size()) {
    throw Error("AlbedoPsnr: image sizes differ (" + std::to_string(estimate.width) + "x" +
                std::to_string(estimate.height) + "x" + std::to_string(estimate.channels) + " vs " +
                std::to_string(truth.width) + "x" + std::to_string(truth.height) + "x" +
                std::to_string(truth.channels) + ")");
  }
  if (estimate.pixels.empty()) throw Error("AlbedoPsnr: empty images");
  if (!(peak > 0)) throw Error("AlbedoPsnr: peak must be > 0");
  double sum = 0;
  for (size_t i = 0; i < estimate.pixels.size(); ++i) {
    const double d = double(estimate.pixels[i]) - truth.pixels[i];
    sum += d * d;
  }
  const double mse = sum / double(estimate.pixels.size());
  return mse == 0 ? INFINITY : 10.0 * std::log10(peak * peak / mse);
}

namespace {

// Whether every texel that a bilinear lookup at `uv` reads with a non-zero weight is seen.
bool LookupSeen(const Image& seen, const Eigen::Vector2d& uv) {
  const double x = uv.x() * seen.width - 0.5, y = (1.0 - uv.y()) * seen.height - 0.5;
  const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
  const double fx = x - x0, fy = y - y0;
  for (int dy = 0; dy < 2; ++dy) {
    for (int dx = 0; dx < 2; ++dx) {
      if ((dx ? fx : 1 - fx) * (dy ? fy : 1 - fy) <= 0) continue;
      const int xi = std::clamp(x0 + dx, 0, seen.width - 1);
      const int yi = std::clamp(y0 + dy, 0, seen.height - 1);
      if (!(seen.at(xi, yi, 0) > 0.5f)) return false;
    }
  }
  return true;
}

}  // namespace

AlbedoComparison CompareAlbedoMaps(const Image& estimate, const Image* seen, const Image& truth,
                                   double peak) {
  if (estimate.empty() || truth.empty()) throw Error("CompareAlbedoMaps: empty image");
  if (seen != nullptr && (seen->width != estimate.width || seen->height != estimate.height)) {
    throw Error("CompareAlbedoMaps: the seen mask differs in size from the estimate");
  }
  if (!(peak > 0)) throw Error("CompareAlbedoMaps: peak must be > 0");
  double sum = 0;
  int64_t count = 0, texels = 0;
  for (int y = 0; y < truth.height; ++y) {
    for (int x = 0; x < truth.width; ++x) {
      ++texels;
      const Eigen::Vector2d uv((x + 0.5) / truth.width, 1.0 - (y + 0.5) / truth.height);
      if (seen != nullptr && !LookupSeen(*seen, uv)) continue;
      const Eigen::Vector3d v = render::SampleTexture(estimate, uv);
      for (int c = 0; c < 3; ++c) {
        const double d = v[c] - truth.at(x, y, std::min(c, truth.channels - 1));
        sum += d * d;
      }
      ++count;
    }
  }
  if (count == 0) throw Error("CompareAlbedoMaps: no texel compared (nothing seen)");
  AlbedoComparison out;
  const double mse = sum / double(3 * count);
  out.rms = std::sqrt(mse);
  out.psnr_db = mse == 0 ? INFINITY : 10.0 * std::log10(peak * peak / mse);
  out.compared = double(count) / double(texels);
  return out;
}

Eigen::Vector3d SeenTexelMean(const Image& map, const Image& seen) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double count = 0;
  for (int y = 0; y < seen.height; ++y) {
    for (int x = 0; x < seen.width; ++x) {
      if (!(seen.at(x, y) > 0.5f)) continue;
      for (int c = 0; c < 3; ++c) sum[c] += map.at(x, y, std::min(c, map.channels - 1));
      ++count;
    }
  }
  return count > 0 ? Eigen::Vector3d(sum / count) : Eigen::Vector3d::Constant(NAN);
}

Eigen::Vector3d TextureMeanOverSeenTexels(const Image& texture, const Image& seen) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double count = 0;
  for (int y = 0; y < texture.height; ++y) {
    const int sy = std::min(seen.height - 1, int((y + 0.5) * seen.height / texture.height));
    for (int x = 0; x < texture.width; ++x) {
      const int sx = std::min(seen.width - 1, int((x + 0.5) * seen.width / texture.width));
      if (!(seen.at(sx, sy) > 0.5f)) continue;
      for (int c = 0; c < 3; ++c) sum[c] += texture.at(x, y, std::min(c, texture.channels - 1));
      ++count;
    }
  }
  return count > 0 ? Eigen::Vector3d(sum / count) : Eigen::Vector3d::Constant(NAN);
}

namespace {

// Mean of `map`'s channel c over the texels of `mask` in the (2k+1)² window around (x, y).
double LocalMean(const Image& map, const std::vector<char>& mask, int x, int y, int c, int k) {
  double sum = 0;
  int n = 0;
  for (int yy = std::max(0, y - k); yy <= std::min(map.height - 1, y + k); ++yy) {
    for (int xx = std::max(0, x - k); xx <= std::min(map.width - 1, x + k); ++xx) {
      if (!mask[size_t(yy) * map.width + xx]) continue;
      sum += map.at(xx, yy, c);
      ++n;
    }
  }
  return n > 0 ? sum / n : map.at(x, y, c);
}

}  // namespace

TexelDetail SharedTexelDetail(const Image& a, const Image& b, const std::vector<int>& both) {
  TexelDetail out;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (int i : both) {
    for (int c = 0; c < 3; ++c) mean[c] += a.pixels[size_t(i) * 3 + c] + b.pixels[size_t(i) * 3 + c];
  }
  if (!both.empty()) mean /= 2.0 * double(both.size());
  if (both.size() < 64 || !(mean.minCoeff() > 0)) return out;
  const int w = a.width;
  std::vector<char> in_both(size_t(w) * a.height, 0);
  for (int i : both) in_both[i] = 1;
  // Per tile: the sum of the texels' products and their count.
  const int tiles_x = (w + kTexelDetailTile - 1) / kTexelDetailTile;
  std::vector<double> tile_sum(size_t(tiles_x) * ((a.height + kTexelDetailTile - 1) / kTexelDetailTile));
  std::vector<int> tile_n(tile_sum.size(), 0);
  std::vector<double> products(both.size());
  double covariance = 0;
  for (size_t k = 0; k < both.size(); ++k) {
    const int i = both[k], x = i % w, y = i / w;
    double product = 0;
    for (int c = 0; c < 3; ++c) {
      const double da = a.at(x, y, c) - LocalMean(a, in_both, x, y, c, kTexelDetailHalfWidth);
      const double db = b.at(x, y, c) - LocalMean(b, in_both, x, y, c, kTexelDetailHalfWidth);
      product += da * db;
    }
    const size_t t = size_t(y / kTexelDetailTile) * tiles_x + x / kTexelDetailTile;
    tile_sum[t] += product;
    ++tile_n[t];
    products[k] = product;
    covariance += product;
  }
  const double n = double(both.size());
  covariance /= n;
  out.variation = std::sqrt(std::max(0.0, covariance / mean.squaredNorm()));
  // The ratio estimator's variance, Σ (S_t − cov·n_t)² / n² · T / (T − 1), over the tiles when
  // there are at least kMinTiles, else over the texels (which their local means correlate, so
  // that the z of a small region is overstated).
  constexpr int kMinTiles = 8;
  double spread = 0;
  int samples = 0;
  for (size_t t = 0; t < tile_sum.size(); ++t) {
    if (tile_n[t] == 0) continue;
    spread += std::pow(tile_sum[t] - covariance * tile_n[t], 2);
    ++samples;
  }
  if (samples < kMinTiles) {
    spread = 0;
    for (size_t k = 0; k < both.size(); ++k) spread += std::pow(products[k] - covariance, 2);
    samples = int(both.size());
  }
  out.z = spread > 0 ? covariance / std::sqrt(spread / (n * n) * samples / (samples - 1.0))
                     : (covariance > 0 ? INFINITY : 0.0);
  return out;
}

}  // namespace igi::solver
