#include "solver/diagnose/missing_geometry.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <tuple>

#include "solver/render/ray_scene.h"
#include "tools/common/error.h"
#include "tools/common/parallel.h"

namespace igi::diagnose {
namespace fs = std::filesystem;

void MissingGeometryOptions::Validate() const {
  if (!(voxels_per_extent >= 4) || !(min_relative > 0) || !(median_factor > 0) ||
      !(min_area_fraction >= 0) || min_area_px < 1 || min_views < 2 || min_core_voxels < 1 ||
      dilate_px < 0 || folds < 1 || !(min_contrast >= 0) || !(max_surface_slope > 0) ||
      min_agreement_pairs < 0) {
    throw Error("missing geometry: invalid options");
  }
}

Eigen::Vector3i VoxelGrid::Cell(int64_t i) const {
  const int x = int(i % dims.x());
  const int y = int((i / dims.x()) % dims.y());
  const int z = int(i / (int64_t(dims.x()) * dims.y()));
  return {x, y, z};
}

Eigen::Vector3d VoxelGrid::Center(int64_t i) const {
  return origin + voxel_m * (Cell(i).cast<double>() + Eigen::Vector3d::Constant(0.5));
}

VoxelGrid VoxelGrid::Over(const Eigen::AlignedBox3d& box, double voxel_m) {
  VoxelGrid g;
  g.voxel_m = voxel_m;
  g.origin = box.min();
  for (int k = 0; k < 3; ++k) {
    g.dims[k] = std::max(1, int(std::ceil(box.sizes()[k] / voxel_m)));
  }
  return g;
}

namespace {

// 8-connected components of `bin` (W×H, row-major): a label per pixel (−1 outside), and sizes.
std::vector<int> Components2d(const std::vector<uint8_t>& bin, int w, int h,
                              std::vector<int>* sizes) {
  std::vector<int> label(bin.size(), -1);
  sizes->clear();
  std::vector<int> stack;
  for (int start = 0; start < w * h; ++start) {
    if (!bin[start] || label[start] >= 0) continue;
    const int id = int(sizes->size());
    sizes->push_back(0);
    stack.push_back(start);
    label[start] = id;
    while (!stack.empty()) {
      const int p = stack.back();
      stack.pop_back();
      ++(*sizes)[id];
      const int px = p % w, py = p / w;
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const int x = px + dx, y = py + dy;
          if (x < 0 || y < 0 || x >= w || y >= h) continue;
          const int q = y * w + x;
          if (bin[q] && label[q] < 0) label[q] = id, stack.push_back(q);
        }
      }
    }
  }
  return label;
}

// Square dilation (erode = !dilate(!bin)).
std::vector<uint8_t> Dilate(const std::vector<uint8_t>& bin, int w, int h, int r) {
  if (r <= 0) return bin;
  std::vector<uint8_t> rows(bin.size(), 0), out(bin.size(), 0);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      bool any = false;
      for (int k = std::max(0, x - r); k <= std::min(w - 1, x + r) && !any; ++k)
        any = bin[y * w + k];
      rows[y * w + x] = any;
    }
  }
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      bool any = false;
      for (int k = std::max(0, y - r); k <= std::min(h - 1, y + r) && !any; ++k)
        any = rows[k * w + x];
      out[y * w + x] = any;
    }
  }
  return out;
}

std::vector<uint8_t> Erode(const std::vector<uint8_t>& bin, int w, int h, int r) {
  std::vector<uint8_t> inv(bin.size());
  for (size_t i = 0; i < bin.size(); ++i) inv[i] = !bin[i];
  inv = Dilate(inv, w, h, r);
  for (uint8_t& v : inv) v = !v;
  return inv;
}

// Whether `view` sees the point (it lies in front of the modelled surface along its pixel's ray)
// and at which pixel.
bool Sees(const CarveView& view, const Eigen::Vector3d& x, double margin_m, int* u, int* v) {
  const Eigen::Vector3d pc = view.camera.cam_from_world * x;
  if (!(pc.z() > 1e-6)) return false;
  const std::optional<Eigen::Vector2d> px = view.camera.ImgFromCam(pc);
  if (!px) return false;
  *u = int(std::floor(px->x()));
  *v = int(std::floor(px->y()));
  if (*u < 0 || *v < 0 || *u >= view.state.width || *v >= view.state.height) return false;
  const double dist = (x - view.camera.CenterInWorld()).norm();
  return dist < double(view.depth_m.at(*u, *v)) + margin_m;
}

// The photo's mean value per channel over the pixels `usable` marks.
double MeanLevel(const Image& recorded, const Image& usable) {
  double level = 0;
  int n = 0;
  for (int y = 0; y < recorded.height; ++y) {
    for (int x = 0; x < recorded.width; ++x) {
      if (usable.at(x, y) > 0.5f)
        level += recorded.at(x, y, 0) + recorded.at(x, y, 1) + recorded.at(x, y, 2), ++n;
    }
  }
  return n ? level / (3 * n) : 0;
}

}  // namespace

Image FindResidualBlobs(const Image& recorded, const Image& sim, const Image& usable,
                        const MissingGeometryOptions& o, const Image* infer, int infer_px) {
  const int w = recorded.width, h = recorded.height;
  const double level = MeanLevel(recorded, usable);
  // 3×3 means over usable pixels of the photo and the model; their relative difference.
  std::vector<float> t(size_t(w) * h, -1.0f);
  std::vector<float> values;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      if (usable.at(x, y) < 0.5f) continue;
      Eigen::Vector3d mr = Eigen::Vector3d::Zero(), ms = Eigen::Vector3d::Zero();
      int n = 0;
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const int xx = x + dx, yy = y + dy;
          if (xx < 0 || yy < 0 || xx >= w || yy >= h || usable.at(xx, yy) < 0.5f) continue;
          for (int c = 0; c < 3; ++c) mr[c] += recorded.at(xx, yy, c), ms[c] += sim.at(xx, yy, c);
          ++n;
        }
      }
      mr /= n;
      ms /= n;
      const double den = 0.5 * (mr.norm() + ms.norm()) + 0.05 * std::sqrt(3.0) * level;
      const float v = den > 0 && (mr - ms).allFinite() ? float((mr - ms).norm() / den) : 0.0f;
      t[size_t(y) * w + x] = v;
      values.push_back(v);
    }
  }
  Image state(w, h, 1, -1.0f);
  if (values.empty()) return state;
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  const double threshold = std::max(o.min_relative, o.median_factor * values[values.size() / 2]);
  std::vector<uint8_t> bin(t.size(), 0);
  for (size_t i = 0; i < t.size(); ++i) bin[i] = t[i] > threshold;
  // Isolated pixels and thin lines out: a blob pixel keeps at least 3 blob neighbours.
  std::vector<uint8_t> kept(bin.size(), 0);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      if (!bin[y * w + x]) continue;
      int n = 0;
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const int xx = x + dx, yy = y + dy;
          if ((dx || dy) && xx >= 0 && yy >= 0 && xx < w && yy < h) n += bin[yy * w + xx];
        }
      }
      kept[y * w + x] = n >= 3;
    }
  }
  std::vector<int> sizes;
  const std::vector<int> label = Components2d(kept, w, h, &sizes);
  const int min_area = std::max(o.min_area_px, int(std::ceil(o.min_area_fraction * w * h)));
  for (size_t i = 0; i < kept.size(); ++i) kept[i] = label[i] >= 0 && sizes[label[i]] >= min_area;
  kept = Erode(Dilate(kept, w, h, 1), w, h, 1);  // closing: holes of a pixel filled
  // Inferred pixels: blob inside the closing of the blobs over infer_px, clear elsewhere.
  std::vector<uint8_t> closed;
  if (infer) closed = Erode(Dilate(kept, w, h, infer_px), w, h, infer_px);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const size_t k = size_t(y) * w + x;
      if (kept[k] || usable.at(x, y) > 0.5f) {
        state.at(x, y) = kept[k] ? 1.0f : 0.0f;
      } else if (infer && infer->at(x, y) > 0.5f) {
        state.at(x, y) = closed[k] ? 1.0f : 0.0f;
      }
    }
  }
  return state;
}

std::vector<uint8_t> CarveVoxels(const std::vector<CarveView>& views, const VoxelGrid& grid,
                                 int min_views) {
  std::vector<uint8_t> carved(size_t(grid.Count()), 0);
  ParallelFor(0, grid.dims.z(), [&](int64_t z) {
    for (int y = 0; y < grid.dims.y(); ++y) {
      for (int x = 0; x < grid.dims.x(); ++x) {
        const int64_t i = grid.Index(x, y, int(z));
        const Eigen::Vector3d c = grid.Center(i);
        int clear = 0;
        uint64_t blob = 0;
        for (const CarveView& v : views) {
          int u = 0, w = 0;
          if (!Sees(v, c, grid.voxel_m, &u, &w)) continue;
          const float s = v.state.at(u, w);
          if (s > 0.5f) {
            blob |= uint64_t(1) << (v.camera_id & 63);
          } else if (s > -0.5f) {
            ++clear;
          }
        }
        carved[size_t(i)] = clear == 0 && std::popcount(blob) >= min_views;
      }
    }
  });
  return carved;
}

std::vector<uint8_t> NearSurfaceVoxels(const recon::TriangleMesh& mesh, const VoxelGrid& grid) {
  std::vector<uint8_t> on(size_t(grid.Count()), 0);
  auto mark = [&](const Eigen::Vector3d& p) {
    const Eigen::Vector3d q = (p - grid.origin) / grid.voxel_m;
    const Eigen::Vector3i c(int(std::floor(q.x())), int(std::floor(q.y())), int(std::floor(q.z())));
    if ((c.array() < 0).any() || (c.array() >= grid.dims.array()).any()) return;
    on[size_t(grid.Index(c.x(), c.y(), c.z()))] = 1;
  };
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const Eigen::Vector3d a = mesh.positions[t[0]].cast<double>();
    const Eigen::Vector3d b = mesh.positions[t[1]].cast<double>();
    const Eigen::Vector3d c = mesh.positions[t[2]].cast<double>();
    const double len = std::max({(b - a).norm(), (c - a).norm(), (c - b).norm()});
    const int n = std::max(1, int(std::ceil(len / (0.5 * grid.voxel_m))));
    for (int i = 0; i <= n; ++i) {
      for (int j = 0; i + j <= n; ++j)
        mark(a + (b - a) * (double(i) / n) + (c - a) * (double(j) / n));
    }
  }
  // Within 1.5 voxels: the cells the triangles pass through and their 26 neighbours.
  std::vector<uint8_t> near(on.size(), 0);
  for (int64_t i = 0; i < grid.Count(); ++i) {
    if (!on[size_t(i)]) continue;
    const Eigen::Vector3i c = grid.Cell(i);
    for (int dz = -1; dz <= 1; ++dz) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const Eigen::Vector3i d = c + Eigen::Vector3i(dx, dy, dz);
          if ((d.array() < 0).any() || (d.array() >= grid.dims.array()).any()) continue;
          near[size_t(grid.Index(d.x(), d.y(), d.z()))] = 1;
        }
      }
    }
  }
  return near;
}

namespace {

// 26-neighbours of cell i inside the grid.
template <class F>
void ForNeighbours(const VoxelGrid& g, int64_t i, F fn) {
  const Eigen::Vector3i c = g.Cell(i);
  for (int dz = -1; dz <= 1; ++dz) {
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        if (!dx && !dy && !dz) continue;
        const Eigen::Vector3i d = c + Eigen::Vector3i(dx, dy, dz);
        if ((d.array() < 0).any() || (d.array() >= g.dims.array()).any()) continue;
        fn(g.Index(d.x(), d.y(), d.z()));
      }
    }
  }
}

// Grows the box [lo, hi] (cells) through faces whose next layer is >= 30% carved: the object's
// base on the surface it stands on, which carving leaves among the surface voxels.
void GrowBox(const std::vector<uint8_t>& carved, const VoxelGrid& g, Eigen::Vector3i* lo,
             Eigen::Vector3i* hi) {
  for (int pass = 0; pass < 2; ++pass) {
    for (int axis = 0; axis < 3; ++axis) {
      for (int side = 0; side < 2; ++side) {
        const int layer = side ? (*hi)[axis] + 1 : (*lo)[axis] - 1;
        if (layer < 0 || layer >= g.dims[axis]) continue;
        const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
        int n = 0, hit = 0;
        for (int i = (*lo)[a1]; i <= (*hi)[a1]; ++i) {
          for (int j = (*lo)[a2]; j <= (*hi)[a2]; ++j) {
            Eigen::Vector3i c;
            c[axis] = layer, c[a1] = i, c[a2] = j;
            ++n;
            hit += carved[size_t(g.Index(c.x(), c.y(), c.z()))];
          }
        }
        if (10 * hit >= 3 * n) (side ? (*hi)[axis] : (*lo)[axis]) = layer;
      }
    }
  }
}

}  // namespace

std::vector<CarveView> WithoutSurfaceBlobs(const std::vector<CarveView>& views, double margin_m) {
  std::vector<CarveView> out = views;
  for (size_t a = 0; a < views.size(); ++a) {
    const CarveView& va = views[a];
    const Eigen::Vector3d center = va.camera.CenterInWorld();
    ParallelFor(0, va.state.height, [&](int64_t yy) {
      const int y = int(yy);
      for (int x = 0; x < va.state.width; ++x) {
        const float depth = va.depth_m.at(x, y);
        if (!(va.state.at(x, y) > 0.5f) || !std::isfinite(depth)) continue;
        const Eigen::Vector3d p =
            center + double(depth) * va.camera.WorldRayFromImg(Eigen::Vector2d(x + 0.5, y + 0.5));
        int blob = 0, clear = 0;
        for (const CarveView& vb : views) {
          if (vb.camera_id == va.camera_id) continue;
          int u = 0, v = 0;
          if (!Sees(vb, p, margin_m, &u, &v)) continue;
          const float s = vb.state.at(u, v);
          blob += s > 0.5f;
          clear += s > -0.5f && !(s > 0.5f);
        }
        // Most of the other cameras that see the point (not all: a blob near the threshold is
        // missed here and there by the photo noise, and a texture's blobs would then raise a
        // phantom above the surface).
        if (blob > clear) out[a].state.at(x, y) = -1.0f;
      }
    });
  }
  return out;
}

std::vector<CarvedObject> CarvedObjects(const std::vector<uint8_t>& carved_object,
                                        const std::vector<uint8_t>& carved,
                                        const std::vector<uint8_t>& near_surface,
                                        const VoxelGrid& g, int min_core_voxels) {
  std::vector<int> label(carved.size(), -1);
  std::vector<CarvedObject> out;
  // The box grows through the object's voxels and the surface voxels under it (not through the
  // phantom that surface blobs raise).
  std::vector<uint8_t> grow(carved.size(), 0);
  for (size_t i = 0; i < grow.size(); ++i) {
    grow[i] = carved_object[i] || (carved[i] && near_surface[i]);
  }
  for (int64_t start = 0; start < g.Count(); ++start) {
    if (!carved_object[size_t(start)] || near_surface[size_t(start)] || label[size_t(start)] >= 0) {
      continue;
    }
    const int id = int(out.size()) + 1000000;  // provisional; only used as a visited mark
    std::vector<int64_t> stack{start}, cells;
    label[size_t(start)] = id;
    while (!stack.empty()) {
      const int64_t i = stack.back();
      stack.pop_back();
      cells.push_back(i);
      ForNeighbours(g, i, [&](int64_t j) {
        if (carved_object[size_t(j)] && !near_surface[size_t(j)] && label[size_t(j)] < 0) {
          label[size_t(j)] = id;
          stack.push_back(j);
        }
      });
    }
    if (int(cells.size()) < min_core_voxels) continue;
    Eigen::Vector3i lo = g.Cell(cells[0]), hi = lo;
    for (int64_t i : cells) lo = lo.cwiseMin(g.Cell(i)), hi = hi.cwiseMax(g.Cell(i));
    GrowBox(grow, g, &lo, &hi);
    CarvedObject obj;
    obj.core_voxels = int(cells.size());
    obj.box_min = g.origin + g.voxel_m * lo.cast<double>();
    obj.box_max = g.origin + g.voxel_m * (hi + Eigen::Vector3i::Ones()).cast<double>();
    obj.size_m = obj.box_max - obj.box_min;
    std::vector<uint8_t> in_box(carved.size(), 0);
    int n_volume = 0;
    for (int z = lo.z(); z <= hi.z(); ++z) {
      for (int y = lo.y(); y <= hi.y(); ++y) {
        for (int x = lo.x(); x <= hi.x(); ++x) {
          obj.box_voxels.push_back(g.Index(x, y, z));
          in_box[size_t(obj.box_voxels.back())] = 1;
          if (grow[size_t(obj.box_voxels.back())]) {
            obj.center += g.Center(obj.box_voxels.back()), ++n_volume;
            obj.volume_voxels.push_back(obj.box_voxels.back());
          }
        }
      }
    }
    obj.center /= std::max(1, n_volume);
    // Its shadow: carved surface voxels connected to the box through carved surface voxels.
    std::vector<uint8_t> seen(carved.size(), 0);
    std::vector<int64_t> front;
    for (int64_t i : obj.box_voxels) {
      ForNeighbours(g, i, [&](int64_t j) {
        if (!in_box[size_t(j)] && carved[size_t(j)] && near_surface[size_t(j)] &&
            !seen[size_t(j)]) {
          seen[size_t(j)] = 1;
          front.push_back(j);
        }
      });
    }
    while (!front.empty()) {
      const int64_t i = front.back();
      front.pop_back();
      obj.shadow_voxels.push_back(i);
      ForNeighbours(g, i, [&](int64_t j) {
        if (!in_box[size_t(j)] && carved[size_t(j)] && near_surface[size_t(j)] &&
            !seen[size_t(j)]) {
          seen[size_t(j)] = 1;
          front.push_back(j);
        }
      });
    }
    out.push_back(std::move(obj));
  }
  std::sort(out.begin(), out.end(), [](const CarvedObject& a, const CarvedObject& b) {
    return a.core_voxels > b.core_voxels;
  });
  return out;
}

Image ProjectVoxels(const CarveView& view, const VoxelGrid& g, const std::vector<int64_t>& voxels,
                    int dilate_px) {
  const int w = view.state.width, h = view.state.height;
  std::vector<uint8_t> bin(size_t(w) * h, 0);
  const double half = 0.5 * g.voxel_m;
  for (int64_t i : voxels) {
    const Eigen::Vector3d c = g.Center(i);
    int u = 0, v = 0;
    if (!Sees(view, c, g.voxel_m, &u, &v)) continue;
    double x0 = 1e30, x1 = -1e30, y0 = 1e30, y1 = -1e30;
    for (int k = 0; k < 8; ++k) {
      const Eigen::Vector3d corner =
          c + half * Eigen::Vector3d(k & 1 ? 1 : -1, k & 2 ? 1 : -1, k & 4 ? 1 : -1);
      const Eigen::Vector3d pc = view.camera.cam_from_world * corner;
      const std::optional<Eigen::Vector2d> px =
          pc.z() > 1e-6 ? view.camera.ImgFromCam(pc) : std::nullopt;
      if (!px) continue;
      x0 = std::min(x0, px->x()), x1 = std::max(x1, px->x());
      y0 = std::min(y0, px->y()), y1 = std::max(y1, px->y());
    }
    const int ux0 = std::max(0, int(std::floor(std::max(x0, -1.0))));
    const int ux1 = std::min(w - 1, int(std::floor(std::min(x1, double(w)))));
    const int vy0 = std::max(0, int(std::floor(std::max(y0, -1.0))));
    const int vy1 = std::min(h - 1, int(std::floor(std::min(y1, double(h)))));
    for (int y = vy0; y <= vy1; ++y) {
      for (int x = ux0; x <= ux1; ++x) bin[size_t(y) * w + x] = 1;
    }
  }
  bin = Dilate(bin, w, h, dilate_px);
  Image out(w, h, 1);
  for (size_t k = 0; k < bin.size(); ++k) out.pixels[k] = bin[k];
  return out;
}

PhotoSet MaskedPhotoSet(const PhotoSet& photos, const std::vector<Image>& excluded) {
  PhotoSet out = photos;
  for (size_t i = 0; i < out.valid.size() && i < excluded.size(); ++i) {
    for (size_t k = 0; k < out.valid[i].pixels.size(); ++k) {
      if (excluded[i].pixels[k] > 0.5f) out.valid[i].pixels[k] = 0;
    }
  }
  return out;
}

namespace {

// The modelled surface's distance along each pixel's ray (infinity where it escapes).
Image DepthOf(const render::RayScene& impl, const recon::Camera& cam) {
  Image depth(cam.width, cam.height, 1, std::numeric_limits<float>::infinity());
  const Eigen::Vector3d center = cam.CenterInWorld();
  ParallelFor(0, cam.height, [&](int64_t y) {
    for (int x = 0; x < cam.width; ++x) {
      const std::optional<render::SurfaceHit> hit =
          impl.TraceSurface(center, cam.WorldRayFromImg(Eigen::Vector2d(x + 0.5, y + 0.5)));
      if (hit) depth.at(x, int(y)) = float(hit->t);
    }
  });
  return depth;
}

// Adds to `excluded` the blob components of `state` that it touches (dilated by r).
void AddTouchedBlobs(const Image& state, int r, Image* excluded) {
  const int w = state.width, h = state.height;
  std::vector<uint8_t> bin(size_t(w) * h);
  for (size_t k = 0; k < bin.size(); ++k) bin[k] = state.pixels[k] > 0.5f;
  std::vector<int> sizes;
  const std::vector<int> label = Components2d(bin, w, h, &sizes);
  std::vector<uint8_t> touched(sizes.size(), 0);
  for (size_t k = 0; k < bin.size(); ++k) {
    if (label[k] >= 0 && excluded->pixels[k] > 0.5f) touched[label[k]] = 1;
  }
  std::vector<uint8_t> add(bin.size(), 0);
  for (size_t k = 0; k < bin.size(); ++k) add[k] = label[k] >= 0 && touched[label[k]];
  add = Dilate(add, w, h, r);
  for (size_t k = 0; k < bin.size(); ++k) {
    if (add[k]) excluded->pixels[k] = 1;
  }
}

// The pixels of one view that the object's voxels and its shadow's cover, dilated by r, with the
// blobs they touch; the pixel counts of the object and of the shadow alone, when asked.
Image Exclusion(const CarveView& view, const VoxelGrid& grid, const std::vector<int64_t>& object,
                const std::vector<int64_t>& shadow, int r, int* n_object = nullptr,
                int* n_shadow = nullptr) {
  const Image object_px = ProjectVoxels(view, grid, object, r);
  Image excluded = ProjectVoxels(view, grid, shadow, r);
  int objects = 0, shadows = 0;
  for (size_t k = 0; k < excluded.pixels.size(); ++k) {
    objects += object_px.pixels[k] > 0.5f;
    shadows += excluded.pixels[k] > 0.5f && !(object_px.pixels[k] > 0.5f);
    excluded.pixels[k] = std::max(excluded.pixels[k], object_px.pixels[k]);
  }
  if (n_object) *n_object = objects;
  if (n_shadow) *n_shadow = shadows;
  AddTouchedBlobs(view.state, r, &excluded);
  return excluded;
}

// How much higher the residual² per pixel is inside the exclusion than outside it over the
// pixels of one fold, with its blocks as units (each block's mean inside and mean outside);
// residual² relative to the photo's mean photo². The Mann–Whitney U of the inside blocks against
// the outside ones (the residual² is heavy-tailed: a rank test, not a t test), its mean and
// variance under no contrast, and the sums of the block means.
struct Contrast {
  double u = 0, mean = 0, variance = 0;
  double sum_in = 0, sum_out = 0;
  int n_in = 0, n_out = 0;

  void Add(const Contrast& c) {
    u += c.u, mean += c.mean, variance += c.variance;
    sum_in += c.sum_in, sum_out += c.sum_out, n_in += c.n_in, n_out += c.n_out;
  }
  double Z() const { return variance > 0 ? (u - mean) / std::sqrt(variance) : 0; }
  double Ratio() const {
    return n_in && n_out && sum_out > 0 ? (sum_in / n_in) / (sum_out / n_out) : 0;
  }
};

Contrast InsideContrast(const PhotoSet& photos, const std::vector<Image>& sims,
                        const std::vector<Image>& excluded, const solver::PixelHoldout& holdout,
                        int fold, int folds) {
  struct Acc {
    double in = 0, out = 0;
    int n_in = 0, n_out = 0;
  };
  std::map<std::tuple<int, int, int>, Acc> blocks;
  for (size_t i = 0; i < sims.size(); ++i) {
    const Image& rec = photos.recorded[i];
    double level = 0;
    int n = 0;
    for (size_t k = 0; k < rec.pixels.size(); ++k) {
      if (photos.valid[i].pixels[k / 3] > 0.5f) level += double(rec.pixels[k]) * rec.pixels[k], ++n;
    }
    level = n ? 3 * level / n : 1;
    for (int y = 0; y < rec.height; ++y) {
      for (int x = 0; x < rec.width; ++x) {
        if (photos.valid[i].at(x, y) < 0.5f || holdout.Fold(int(i), x, y, folds) != fold) continue;
        double e = 0;
        for (int c = 0; c < 3; ++c) {
          const double d = double(sims[i].at(x, y, c)) - rec.at(x, y, c);
          if (std::isfinite(d)) e += d * d;
        }
        e /= std::max(level, 1e-30);
        Acc& a = blocks[{int(i), y / holdout.block_px, x / holdout.block_px}];
        if (excluded[i].at(x, y) > 0.5f) {
          a.in += e, ++a.n_in;
        } else {
          a.out += e, ++a.n_out;
        }
      }
    }
  }
  std::vector<double> in, out;
  for (const auto& [k, a] : blocks) {
    // A block's side with a few pixels only is too noisy to rank.
    if (a.n_in >= 4) in.push_back(a.in / a.n_in);
    if (a.n_out >= 4) out.push_back(a.out / a.n_out);
  }
  Contrast c;
  if (in.empty() || out.empty()) return c;
  for (double v : in) c.sum_in += v;
  for (double v : out) c.sum_out += v;
  c.n_in = int(in.size()), c.n_out = int(out.size());
  std::vector<std::pair<double, int>> all;
  for (double v : in) all.emplace_back(v, 1);
  for (double v : out) all.emplace_back(v, 0);
  std::sort(all.begin(), all.end());
  double rank_sum = 0;
  for (size_t k = 0; k < all.size(); ++k) {
    if (all[k].second) rank_sum += double(k + 1);
  }
  const double n1 = double(in.size()), n2 = double(out.size());
  c.u = rank_sum - n1 * (n1 + 1) / 2;
  c.mean = n1 * n2 / 2;
  c.variance = n1 * n2 * (n1 + n2 + 1) / 12;
  return c;
}

// The blob state of every view with the pixels of fold `fold` unknown: they get a state from the
// pixels around them (never from their own values), so that carving is not left free inside
// every block the fold holds.
void FindBlobsWithoutFold(const PhotoSet& photos, const std::vector<Image>& sims,
                          const solver::PixelHoldout& holdout, int fold, int folds,
                          const MissingGeometryOptions& o, std::vector<CarveView>* views) {
  for (size_t i = 0; i < views->size(); ++i) {
    Image usable = photos.valid[i];
    for (int y = 0; y < usable.height; ++y) {
      for (int x = 0; x < usable.width; ++x) {
        if (holdout.Fold(int(i), x, y, folds) == fold) usable.at(x, y) = 0;
      }
    }
    (*views)[i].state = FindResidualBlobs(photos.recorded[i], sims[i], usable, o, &photos.valid[i],
                                          holdout.block_px / 2 + 1);
  }
}

// The objects carved from the views, and their voxels and shadows' voxels together.
struct Carving {
  std::vector<CarvedObject> objects;
  std::vector<int64_t> voxels, shadow;
};

Carving Carve(const std::vector<CarveView>& views, const VoxelGrid& grid,
              const std::vector<uint8_t>& near, const MissingGeometryOptions& o) {
  const std::vector<uint8_t> carved = CarveVoxels(views, grid, o.min_views);
  const std::vector<uint8_t> carved_object =
      CarveVoxels(WithoutSurfaceBlobs(views, grid.voxel_m), grid, o.min_views);
  Carving c;
  c.objects = CarvedObjects(carved_object, carved, near, grid, o.min_core_voxels);
  for (const CarvedObject& obj : c.objects) {
    c.voxels.insert(c.voxels.end(), obj.volume_voxels.begin(), obj.volume_voxels.end());
    c.shadow.insert(c.shadow.end(), obj.shadow_voxels.begin(), obj.shadow_voxels.end());
  }
  return c;
}

// The carving's exclusions in every view, undilated (what the significance test scores), and
// when asked each view's pixel counts of the object and of its shadow.
std::vector<Image> CoreExclusions(const std::vector<CarveView>& views, const VoxelGrid& grid,
                                  const Carving& c,
                                  std::vector<std::pair<int, int>>* counts = nullptr) {
  std::vector<Image> core;
  for (const CarveView& v : views) {
    int n_object = 0, n_shadow = 0;
    core.push_back(Exclusion(v, grid, c.voxels, c.shadow, 0, &n_object, &n_shadow));
    if (counts) counts->emplace_back(n_object, n_shadow);
  }
  return core;
}

// Where a light of a lighting lies as seen from the scene, for a shadow test: a point (point,
// spot and sphere lights, an area light's centroid) or, for a directional light, the direction
// toward it. Ambient light has no direction and casts no shadow.
struct LightAnchor {
  Eigen::Vector3d at = Eigen::Vector3d::Zero();
  bool directional = false;
};

std::vector<LightAnchor> LightAnchors(const recon::Scene& model, int lighting) {
  std::vector<LightAnchor> out;
  for (int li : model.lightings[size_t(lighting)].lights) {
    const recon::Light& light = model.lights[size_t(li)];
    if (light.type == recon::LightType::kPoint || light.type == recon::LightType::kSpot) {
      out.push_back({light.position, false});
    } else if (light.type == recon::LightType::kSphere) {
      out.push_back({light.center, false});
    } else if (light.type == recon::LightType::kArea && !light.mesh.positions.empty()) {
      Eigen::Vector3d c = Eigen::Vector3d::Zero();
      for (const Eigen::Vector3f& p : light.mesh.positions) c += p.cast<double>();
      out.push_back({c / double(light.mesh.positions.size()), false});
    } else if (light.type == recon::LightType::kDirectional) {
      out.push_back({-light.direction.normalized(), true});
    }
  }
  return out;
}

// Whether the segment from x toward one of the lights passes through one of the objects' boxes
// (x lies in their shadow).
bool ShadowedByObjects(const std::vector<LightAnchor>& lights, const Eigen::Vector3d& x,
                       const std::vector<CarvedObject>& objects) {
  for (const LightAnchor& light : lights) {
    const Eigen::Vector3d to = light.directional ? light.at : Eigen::Vector3d(light.at - x);
    const double reach = light.directional ? std::numeric_limits<double>::infinity() : to.norm();
    const Eigen::Vector3d d = to.normalized();
    for (const CarvedObject& obj : objects) {
      // Slab test of the ray x + t d, 0 < t < reach, against the box.
      double t0 = 1e-6, t1 = reach;
      for (int k = 0; k < 3 && t0 <= t1; ++k) {
        if (std::abs(d[k]) < 1e-12) {
          if (x[k] < obj.box_min[k] || x[k] > obj.box_max[k]) t0 = t1 + 1;
          continue;
        }
        double a = (obj.box_min[k] - x[k]) / d[k], b = (obj.box_max[k] - x[k]) / d[k];
        if (a > b) std::swap(a, b);
        t0 = std::max(t0, a), t1 = std::min(t1, b);
      }
      if (t0 <= t1) return true;
    }
  }
  return false;
}

// 3×3 means over valid pixels of the relative residual (model − photo, channels summed) over the
// model plus 5% of the photo's mean level (as the blobs'); NaN where the pixel is not valid.
Image SmoothedRelativeResidual(const Image& rec, const Image& sim, const Image& valid) {
  const int w = rec.width, h = rec.height;
  const double level = MeanLevel(rec, valid);
  Image out(w, h, 1, std::numeric_limits<float>::quiet_NaN());
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      if (valid.at(x, y) < 0.5f) continue;
      double r = 0, s = 0;
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const int xx = x + dx, yy = y + dy;
          if (xx < 0 || yy < 0 || xx >= w || yy >= h || valid.at(xx, yy) < 0.5f) continue;
          for (int c = 0; c < 3; ++c) r += rec.at(xx, yy, c), s += sim.at(xx, yy, c);
        }
      }
      const double den = std::abs(s) + 0.05 * 27 * level;
      if (std::isfinite(s - r) && den > 0) out.at(x, y) = float((s - r) / den);
    }
  }
  return out;
}

// How far the other photos reproduce, on the modelled surface behind the object, the residual
// inside its projection: pairs of (the residual at a pixel of the object's projection in one
// photo, the residual where another photo sees the modelled surface point behind it, unoccluded
// by the object, outside its shadow from that photo's lights), and the regression slope of the
// second on the first. A change on the surface (a texture, a stain) shows alike from every side:
// a slope near 1; an object hides the surface from one side only: near 0.
struct SurfaceAgreement {
  double ab = 0, aa = 0;
  int pairs = 0;
  double Slope() const { return aa > 0 ? ab / aa : 0; }
};

SurfaceAgreement AgreementBehind(const recon::Scene& model, const PhotoSet& photos,
                                 const std::vector<Image>& sims,
                                 const std::vector<CarveView>& views, const VoxelGrid& grid,
                                 const Carving& c) {
  std::vector<int64_t> object_and_shadow = c.voxels;
  object_and_shadow.insert(object_and_shadow.end(), c.shadow.begin(), c.shadow.end());
  std::vector<Image> rel, object, hidden;
  std::vector<std::vector<LightAnchor>> lights;  // per photo
  for (size_t i = 0; i < views.size(); ++i) {
    rel.push_back(SmoothedRelativeResidual(photos.recorded[i], sims[i], photos.valid[i]));
    object.push_back(ProjectVoxels(views[i], grid, c.voxels, 0));
    // Where a photo's view of the surface is the object's or its shadow's (with a margin).
    hidden.push_back(ProjectVoxels(views[i], grid, object_and_shadow, 1));
    lights.push_back(LightAnchors(model, model.photos[i].lighting));
  }
  SurfaceAgreement out;
  for (size_t a = 0; a < views.size(); ++a) {
    const CarveView& va = views[a];
    const Eigen::Vector3d center = va.camera.CenterInWorld();
    for (int y = 0; y < va.state.height; ++y) {
      for (int x = 0; x < va.state.width; ++x) {
        const float ra = rel[a].at(x, y), depth = va.depth_m.at(x, y);
        if (!(object[a].at(x, y) > 0.5f) || !std::isfinite(ra) || !std::isfinite(depth)) continue;
        const Eigen::Vector3d p =
            center + double(depth) * va.camera.WorldRayFromImg(Eigen::Vector2d(x + 0.5, y + 0.5));
        for (size_t b = 0; b < views.size(); ++b) {
          const CarveView& vb = views[b];
          int u = 0, v = 0;
          if (vb.camera_id == va.camera_id || !Sees(vb, p, grid.voxel_m, &u, &v)) continue;
          const float rb = rel[b].at(u, v);
          if (!std::isfinite(rb) || hidden[b].at(u, v) > 0.5f ||
              ShadowedByObjects(lights[b], p, c.objects)) {
            continue;
          }
          out.ab += double(ra) * rb, out.aa += double(ra) * ra;
          ++out.pairs;
        }
      }
    }
  }
  return out;
}

Json Vec(const Eigen::Vector3d& v, double unit = 1e-3) {
  auto r = [unit](double x) { return std::round(x / unit) * unit; };
  return Json::array({r(v.x()), r(v.y()), r(v.z())});
}

}  // namespace

MissingGeometryResult LocateMissingGeometry(const recon::Scene& model, const PhotoSet& photos,
                                            const std::vector<Image>& sims,
                                            const std::vector<PixelRecord>& records,
                                            const solver::PixelHoldout& holdout,
                                            const fs::path& mask_dir,
                                            const MissingGeometryOptions& o) {
  o.Validate();
  MissingGeometryResult res;
  CandidateResult& out = res.candidate;
  out.effect = "missing_geometry";
  Eigen::AlignedBox3d box;
  for (const Eigen::Vector3f& p : model.mesh.positions) box.extend(p.cast<double>());
  if (box.isEmpty() || model.photos.size() < 2) {
    out.note = "fewer than two photos or no geometry: nothing to triangulate";
    return res;
  }
  const double voxel = box.sizes().maxCoeff() / o.voxels_per_extent;
  box.extend(box.min() - Eigen::Vector3d::Constant(voxel));
  box.extend(box.max() + Eigen::Vector3d::Constant(voxel));
  const VoxelGrid grid = VoxelGrid::Over(box, voxel);
  std::vector<std::unique_ptr<render::RayScene>> scenes(model.lightings.size());
  std::vector<CarveView> views(model.photos.size());
  for (size_t i = 0; i < model.photos.size(); ++i) {
    const recon::Photo& p = model.photos[i];
    if (!scenes[p.lighting])
      scenes[p.lighting] = std::make_unique<render::RayScene>(model, p.lighting);
    CarveView& v = views[i];
    v.camera = model.cameras[p.camera];
    v.camera_id = p.camera;
    v.depth_m = DepthOf(*scenes[p.lighting], v.camera);
  }
  // The masks: from the fitted pixels (fold 0 is the held-out blocks).
  const int folds = o.folds;
  FindBlobsWithoutFold(photos, sims, holdout, 0, folds, o, &views);
  const std::vector<uint8_t> near = NearSurfaceVoxels(model.mesh, grid);
  const Carving carving = Carve(views, grid, near, o);
  const std::vector<CarvedObject>& objects = carving.objects;
  if (objects.empty()) {
    out.note = "no residual blob is seen by two photos in one place off the modelled surfaces";
    return res;
  }
  const CarvedObject& largest = objects[0];
  // Its significance: each fold scored with masks carved without it (see the header).
  std::vector<std::pair<int, int>> counts;  // per view: the object's pixels, its shadow's
  Contrast contrast = InsideContrast(photos, sims, CoreExclusions(views, grid, carving, &counts),
                                     holdout, 0, folds);
  for (int fold = 1; fold < folds; ++fold) {
    std::vector<CarveView> fold_views = views;
    FindBlobsWithoutFold(photos, sims, holdout, fold, folds, o, &fold_views);
    const std::vector<Image> core =
        CoreExclusions(fold_views, grid, Carve(fold_views, grid, near, o));
    contrast.Add(InsideContrast(photos, sims, core, holdout, fold, folds));
  }
  const double ratio = contrast.Ratio();
  out.z = contrast.Z();
  if (!(ratio >= o.min_contrast)) {
    // Ranks alone let blocks a little above the median everywhere outweigh a heavy tail outside
    // (a phantom of 12 voxels over a grazing floor's highlights: z 3.8 at 0.5x the level).
    out.note = fmt::format(
        "residual blobs carve to an object of {} voxels, but the residual² per pixel inside its "
        "masks is {:.1f}x the level outside them (an object the geometry lacks: at least {:.1f}x)",
        largest.core_voxels, ratio, o.min_contrast);
    return res;
  }
  const SurfaceAgreement behind = AgreementBehind(model, photos, sims, views, grid, carving);
  const bool judged = behind.pairs >= o.min_agreement_pairs;
  if (judged && behind.Slope() >= o.max_surface_slope) {
    // A change on a surface (an unmodelled texture's tiles) whose blobs in a few photos happen to
    // carve together off the surface: the other photos show the same residual on the surface.
    out.note = fmt::format(
        "residual blobs carve to an object of {} voxels, but where other photos see the modelled "
        "surface behind it they show {:.0f}% of the residual inside its projections ({} pairs of "
        "pixels): a change on the surface, not an object (which hides the surface from one side "
        "only: at most {:.0f}%)",
        largest.core_voxels, 100 * behind.Slope(), behind.pairs, 100 * o.max_surface_slope);
    return res;
  }
  Json photo_files = Json::array(), pixels = Json::object(), shadow_pixels = Json::object();
  fs::create_directories(mask_dir);
  Json mask_files = Json::array();  // {"photo": index, "file": its mask}
  for (size_t i = 0; i < views.size(); ++i) {
    // The pixels counted are the undilated object's and shadow's; the masks add their margin.
    const auto [n_object, n_shadow] = counts[i];
    Image excluded = Exclusion(views[i], grid, carving.voxels, carving.shadow, o.dilate_px);
    const std::string file = model.photos[i].file.filename().string();
    if (n_object > 0) {
      photo_files.push_back(file);
      pixels[file] = n_object;
      shadow_pixels[file] = n_shadow;
    }
    Image keep(excluded.width, excluded.height, 1, 1.0f);
    std::optional<Image> old;
    if (model.photos[i].mask) old = ReadImage(*model.photos[i].mask, 1);
    for (int y = 0; y < keep.height; ++y) {
      for (int x = 0; x < keep.width; ++x) {
        const bool was = !old || old->at(x, y) > 0.5f;
        keep.at(x, y) = was && !(excluded.at(x, y) > 0.5f) ? 1.0f : 0.0f;
      }
    }
    const fs::path path =
        fs::absolute(mask_dir / (model.photos[i].file.stem().string() + "_mask.png"));
    WriteImage(path, keep);
    mask_files.push_back({{"photo", i}, {"file", path.string()}});
    res.excluded.push_back(std::move(excluded));
    res.keep_masks.push_back(std::move(keep));
  }
  // Predicted effect of excluding them, on the records (outliers too: the object's pixels are).
  for (const PixelRecord& r : records) {
    const double e = double((r.sim - r.recorded).squaredNorm());
    const bool in = res.excluded[size_t(r.photo)].at(r.x, r.y) > 0.5f;
    (r.held_out ? out.held_before : out.train_before) += e;
    if (!in) (r.held_out ? out.held_after : out.train_after) += e;
    if (r.held_out) out.held_photo += double(r.recorded.squaredNorm());
  }
  out.params = {{"center", Vec(largest.center)},
                {"size_m", Vec(largest.size_m)},
                {"box_min", Vec(largest.box_min)},
                {"box_max", Vec(largest.box_max)},
                {"voxel_m", std::round(voxel * 1e4) / 1e4},
                {"objects", int(objects.size())},
                {"masks", "photo masks exclude the object and its shadow"},
                {"mask_files", mask_files}};
  out.where = {{"center", Vec(largest.center)},
               {"size_m", Vec(largest.size_m)},
               {"photos", photo_files},
               {"pixels", pixels},
               {"shadow_pixels", shadow_pixels},
               {"frame", "position in 3D (the residual's blobs carved from every photo)"}};
  out.num_params = 6 * int(objects.size());
  out.evidence = fmt::format(
      "coherent residual blobs in {} photos carve to one place off the modelled surfaces: an "
      "object of about {:.2f} x {:.2f} x {:.2f} m at ({:.2f}, {:.2f}, {:.2f}) that the geometry "
      "lacks ({} voxels of {:.3f} m), with {} voxels of its shadow on the modelled surfaces; "
      "fitted on the fitted pixels, its masks hold {:.1f}% of the held-out residual²; over {} "
      "folds of pixels, each scored by masks carved without it, the residual² per pixel inside "
      "is {:.1f}x the level outside ({} blocks inside); {}",
      photo_files.size(), largest.size_m.x(), largest.size_m.y(), largest.size_m.z(),
      largest.center.x(), largest.center.y(), largest.center.z(), largest.core_voxels, voxel,
      largest.shadow_voxels.size(), 100 * out.Gain(), folds, ratio, contrast.n_in,
      judged
          ? fmt::format("where other photos see the modelled surface behind it they show {:.0f}% "
                        "of the residual inside its projections ({} pairs of pixels)",
                        100 * behind.Slope(), behind.pairs)
          : fmt::format("too few other photos see the modelled surface behind it ({} pairs of "
                        "pixels) to tell it from a change on the surface",
                        behind.pairs));
  spdlog::info("igi-diagnose: missing geometry: {}", out.evidence);
  out.valid = true;
  return res;
}

}  // namespace igi::diagnose
