#include "solver/inverse/uv_charts.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <map>
#include <numeric>
#include <string>

#include "tools/common/atomic_file.h"
#include "tools/common/error.h"

namespace igi::solver {

namespace {

// The mesh's UVs are used when triangles with non-degenerate UVs cover this much of the region.
constexpr double kUsableUvAreaFraction = 0.99;
// A chart member whose normal is this far from the chart's final mean (cos < kMinProjectedCos,
// about 84 degrees) is given back and starts a chart of its own: its projection would fold.
constexpr double kMinProjectedCos = 0.1;
constexpr int kMaxGrowAttempts = 40;  // doublings of the texel size

// Shortest text that reads back to the same value.
template <typename T>
std::string ShortestText(T value) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  return std::string(buffer, result.ptr);
}
std::string Num(float value) { return ShortestText(value); }

// Face normal and area in double precision; a degenerate face has a zero normal.
struct Face {
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  double area_m2 = 0;
};

Face MakeFace(const recon::TriangleMesh& mesh, int t) {
  const Eigen::Vector3i& tri = mesh.triangles[t];
  const Eigen::Vector3d p0 = mesh.positions[tri[0]].cast<double>();
  const Eigen::Vector3d cross = (mesh.positions[tri[1]].cast<double>() - p0)
                                    .cross(mesh.positions[tri[2]].cast<double>() - p0);
  Face face;
  face.area_m2 = 0.5 * cross.norm();
  if (face.area_m2 > 0 && std::isfinite(face.area_m2)) face.normal = cross.normalized();
  return face;
}

// ---- Mesh UVs ------------------------------------------------------------------------------

// Area-weighted world length (metres) of a unit step in u and in v, or nullopt-like false when
// the region's UVs are not usable.
bool MeshUvScale(const recon::TriangleMesh& mesh, const std::vector<int>& tris,
                 Eigen::Vector2d* scale_m) {
  if (!mesh.has_uvs() || mesh.uvs.size() != mesh.positions.size()) return false;
  double good_area = 0, bad_area = 0;
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  for (int t : tris) {
    const Eigen::Vector3i& tri = mesh.triangles[t];
    const double area = mesh.TriangleArea(t);
    const Eigen::Vector2d uv0 = mesh.uvs[tri[0]].cast<double>();
    const Eigen::Vector2d d1 = mesh.uvs[tri[1]].cast<double>() - uv0;
    const Eigen::Vector2d d2 = mesh.uvs[tri[2]].cast<double>() - uv0;
    const double det = d1.x() * d2.y() - d1.y() * d2.x();
    if (!std::isfinite(det) || std::abs(det) < 1e-12) {
      bad_area += area;
      continue;
    }
    const Eigen::Vector3d p0 = mesh.positions[tri[0]].cast<double>();
    const Eigen::Vector3d e1 = mesh.positions[tri[1]].cast<double>() - p0;
    const Eigen::Vector3d e2 = mesh.positions[tri[2]].cast<double>() - p0;
    // [dP/du dP/dv] = [e1 e2] * inverse([d1 d2]).
    const Eigen::Vector3d dp_du = (e1 * d2.y() - e2 * d1.y()) / det;
    const Eigen::Vector3d dp_dv = (e2 * d1.x() - e1 * d2.x()) / det;
    sum += area * Eigen::Vector2d(dp_du.norm(), dp_dv.norm());
    good_area += area;
  }
  if (!(good_area > 0) || bad_area > (1 - kUsableUvAreaFraction) * (good_area + bad_area)) {
    return false;
  }
  *scale_m = sum / good_area;
  return true;
}

void FillFromMeshUvs(const recon::TriangleMesh& mesh, const Eigen::Vector2d& scale_m,
                     const AtlasOptions& options, RegionAtlas* atlas) {
  const double largest_m = scale_m.maxCoeff();
  atlas->texel_size_m = std::max(options.texel_size_m, largest_m / options.max_size);
  auto texels = [&](double metres) {
    const double n = std::ceil(metres / atlas->texel_size_m - 1e-6);
    return std::clamp(static_cast<int>(n), 1, options.max_size);
  };
  atlas->width = texels(scale_m.x());
  atlas->height = texels(scale_m.y());
  atlas->num_charts = 1;
  for (int t : atlas->triangles) {
    for (int k = 0; k < 3; ++k) atlas->corner_uv[t][k] = mesh.uvs[mesh.triangles[t][k]];
    atlas->triangle_chart[t] = 0;
  }
}

// ---- Chart generation ----------------------------------------------------------------------

// Per local triangle, the local triangles sharing an edge with it (positions welded exactly, so
// meshes with unshared vertices, e.g. flat-shaded ones, still connect).
std::vector<std::vector<int>> Neighbours(const recon::TriangleMesh& mesh,
                                         const std::vector<int>& tris) {
  std::map<std::array<float, 3>, int> weld;
  std::vector<std::pair<uint64_t, int>> edges;  // (edge key, local triangle)
  edges.reserve(tris.size() * 3);
  for (size_t i = 0; i < tris.size(); ++i) {
    int ids[3];
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3f& p = mesh.positions[mesh.triangles[tris[i]][k]];
      ids[k] = weld.try_emplace({p.x(), p.y(), p.z()}, int(weld.size())).first->second;
    }
    for (int k = 0; k < 3; ++k) {
      const uint64_t a = std::min(ids[k], ids[(k + 1) % 3]), b = std::max(ids[k], ids[(k + 1) % 3]);
      if (a != b) edges.emplace_back((a << 32) | b, int(i));
    }
  }
  std::sort(edges.begin(), edges.end());
  std::vector<std::vector<int>> out(tris.size());
  for (size_t begin = 0; begin < edges.size();) {
    size_t end = begin + 1;
    while (end < edges.size() && edges[end].first == edges[begin].first) ++end;
    for (size_t i = begin; i < end; ++i) {
      for (size_t j = begin; j < end; ++j) {
        if (edges[i].second != edges[j].second) out[edges[i].second].push_back(edges[j].second);
      }
    }
    begin = end;
  }
  return out;
}

// Grows one chart from `seed` over unassigned neighbours whose normal is within the angle of the
// chart's running (area-weighted) mean normal; degenerate faces join any chart that reaches them.
std::vector<int> GrowChart(int seed, const std::vector<Face>& faces,
                           const std::vector<std::vector<int>>& neighbours, double cos_angle,
                           std::vector<int>* chart_of, int chart) {
  std::vector<int> members = {seed};
  (*chart_of)[seed] = chart;
  Eigen::Vector3d normal_sum = faces[seed].normal * std::max(faces[seed].area_m2, 1e-30);
  for (size_t next = 0; next < members.size(); ++next) {
    for (int nb : neighbours[members[next]]) {
      if ((*chart_of)[nb] >= 0) continue;
      const Face& face = faces[nb];
      const bool degenerate = face.normal.isZero();
      if (!degenerate && face.normal.dot(normal_sum.normalized()) < cos_angle) continue;
      (*chart_of)[nb] = chart;
      members.push_back(nb);
      normal_sum += face.normal * face.area_m2;
    }
  }
  // Members that drifted too far from the final mean would fold in projection: give them back.
  const Eigen::Vector3d mean = normal_sum.normalized();
  std::vector<int> kept;
  for (int m : members) {
    if (m == seed || faces[m].normal.isZero() || faces[m].normal.dot(mean) >= kMinProjectedCos) {
      kept.push_back(m);
    } else {
      (*chart_of)[m] = -1;
    }
  }
  return kept;
}

// Charts as lists of local triangle indices; seeds are taken largest face first.
std::vector<std::vector<int>> MakeCharts(const std::vector<Face>& faces,
                                         const std::vector<std::vector<int>>& neighbours,
                                         double chart_angle_deg) {
  const double cos_angle = std::cos(chart_angle_deg * M_PI / 180.0);
  std::vector<int> order(faces.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return faces[a].area_m2 > faces[b].area_m2; });
  std::vector<int> chart_of(faces.size(), -1);
  std::vector<std::vector<int>> charts;
  bool all_assigned = false;
  while (!all_assigned) {  // more than one pass only when members were given back
    all_assigned = true;
    for (int seed : order) {
      if (chart_of[seed] >= 0) continue;
      charts.push_back(
          GrowChart(seed, faces, neighbours, cos_angle, &chart_of, int(charts.size())));
    }
    for (int c : chart_of) all_assigned = all_assigned && c >= 0;
  }
  return charts;
}

// A chart projected onto its plane: per member, the corners in metres (a right, b up), with the
// chart's bounding rectangle [0, extent_m].
struct ProjectedChart {
  std::vector<int> local_triangles;
  std::vector<std::array<Eigen::Vector2d, 3>> corners_m;
  Eigen::Vector2d extent_m = Eigen::Vector2d::Zero();
};

// Convex hull (Andrew's monotone chain), counter-clockwise, without repeated points.
std::vector<Eigen::Vector2d> ConvexHull(std::vector<Eigen::Vector2d> points) {
  std::sort(points.begin(), points.end(), [](const auto& a, const auto& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  if (points.size() < 3) return points;
  std::vector<Eigen::Vector2d> hull(2 * points.size());
  auto cross = [](const Eigen::Vector2d& o, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
  };
  size_t k = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    while (k >= 2 && cross(hull[k - 2], hull[k - 1], points[i]) <= 0) --k;
    hull[k++] = points[i];
  }
  for (size_t i = points.size() - 1, lower = k + 1; i-- > 0;) {
    while (k >= lower && cross(hull[k - 2], hull[k - 1], points[i]) <= 0) --k;
    hull[k++] = points[i];
  }
  hull.resize(k - 1);
  return hull;
}

// The length of the points' projections onto `d`.
double Extent(const std::vector<Eigen::Vector2d>& points, const Eigen::Vector2d& d) {
  double lo = INFINITY, hi = -INFINITY;
  for (const Eigen::Vector2d& p : points) {
    lo = std::min(lo, p.dot(d));
    hi = std::max(hi, p.dot(d));
  }
  return hi - lo;
}

// The direction whose bounding rectangle (along it and its left perpendicular) has the least
// area: the best is always along an edge of the convex hull.
Eigen::Vector2d BestDirection(const std::vector<Eigen::Vector2d>& points) {
  const std::vector<Eigen::Vector2d> hull = ConvexHull(points);
  Eigen::Vector2d best = Eigen::Vector2d::UnitX();
  double best_area = INFINITY;
  for (size_t i = 0; i <= hull.size(); ++i) {
    Eigen::Vector2d d = Eigen::Vector2d::UnitX();
    if (i < hull.size()) {
      d = hull[(i + 1) % hull.size()] - hull[i];
      if (!(d.norm() > 0)) continue;
      d.normalize();
    }
    const Eigen::Vector2d perp(-d.y(), d.x());
    Eigen::Vector2d lo(INFINITY, INFINITY), hi(-INFINITY, -INFINITY);
    for (const Eigen::Vector2d& p : hull) {
      const Eigen::Vector2d q(p.dot(d), p.dot(perp));
      lo = lo.cwiseMin(q);
      hi = hi.cwiseMax(q);
    }
    const double area = (hi - lo).prod();
    if (area < best_area - 1e-12 * std::abs(best_area)) {
      best_area = area;
      best = d;
    }
  }
  return best;
}

ProjectedChart ProjectChart(const recon::TriangleMesh& mesh, const std::vector<int>& tris,
                            const std::vector<Face>& faces, const std::vector<int>& members) {
  Eigen::Vector3d normal_sum = Eigen::Vector3d::Zero();
  for (int m : members) normal_sum += faces[m].normal * faces[m].area_m2;
  if (!(normal_sum.norm() > 0)) normal_sum = faces[members[0]].normal;
  if (!(normal_sum.norm() > 0)) normal_sum = Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d n = normal_sum.normalized();
  const Eigen::Vector3d helper =
      std::abs(n.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  const Eigen::Vector3d t1 = helper.cross(n).normalized(), t2 = n.cross(t1);  // t1 x t2 = n
  ProjectedChart chart;
  chart.local_triangles = members;
  std::vector<Eigen::Vector2d> points;
  for (int m : members) {
    std::array<Eigen::Vector2d, 3> corners;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d p = mesh.positions[mesh.triangles[tris[m]][k]].cast<double>();
      corners[k] = Eigen::Vector2d(p.dot(t1), p.dot(t2));
      points.push_back(corners[k]);
    }
    chart.corners_m.push_back(corners);
  }
  // Landscape (the wider side along u), so equal inputs give equal layouts.
  Eigen::Vector2d d = BestDirection(points);
  if (Extent(points, Eigen::Vector2d(-d.y(), d.x())) > Extent(points, d) * (1 + 1e-9)) {
    d = Eigen::Vector2d(-d.y(), d.x());
  }
  const Eigen::Vector2d perp(-d.y(), d.x());
  Eigen::Vector2d lo(INFINITY, INFINITY), hi(-INFINITY, -INFINITY);
  for (auto& corners : chart.corners_m) {
    for (Eigen::Vector2d& c : corners) {
      c = Eigen::Vector2d(c.dot(d), c.dot(perp));
      lo = lo.cwiseMin(c);
      hi = hi.cwiseMax(c);
    }
  }
  for (auto& corners : chart.corners_m) {
    for (Eigen::Vector2d& c : corners) c -= lo;
  }
  chart.extent_m = hi - lo;
  return chart;
}

// ---- Packing -------------------------------------------------------------------------------

struct Packing {
  std::vector<Eigen::Vector2i> origin;  // per rectangle, its lower-left texel (x right, y up)
  int width = 0, height = 0;
};

// Shelf packing, tallest first, for one shelf width.
Packing PackShelves(const std::vector<Eigen::Vector2i>& sizes, const std::vector<int>& order,
                    int shelf_width) {
  Packing packing;
  packing.origin.resize(sizes.size());
  int x = 0, y = 0, shelf_height = 0;
  for (int i : order) {
    if (x > 0 && x + sizes[i].x() > shelf_width) {
      y += shelf_height;
      x = 0;
      shelf_height = 0;
    }
    packing.origin[i] = Eigen::Vector2i(x, y);
    x += sizes[i].x();
    shelf_height = std::max(shelf_height, sizes[i].y());
    packing.width = std::max(packing.width, x);
  }
  packing.height = y + shelf_height;
  return packing;
}

// Tries shelf widths from sqrt(area) to twice that; keeps the packing with the smallest larger
// side, then the smallest area.
Packing Pack(const std::vector<Eigen::Vector2i>& sizes) {
  std::vector<int> order(sizes.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    return sizes[a].y() > sizes[b].y() ||
           (sizes[a].y() == sizes[b].y() && sizes[a].x() > sizes[b].x());
  });
  double area = 0;
  int widest = 1;
  for (const Eigen::Vector2i& s : sizes) {
    area += double(s.x()) * s.y();
    widest = std::max(widest, s.x());
  }
  Packing best;
  for (int step = 0; step <= 10; ++step) {
    const double target = std::sqrt(area) * (1.0 + 0.1 * step);
    const int shelf_width = std::max(widest, static_cast<int>(std::ceil(target)));
    Packing p = PackShelves(sizes, order, shelf_width);
    const auto key = [](const Packing& q) {
      return std::make_pair(std::max(q.width, q.height), double(q.width) * q.height);
    };
    if (step == 0 || key(p) < key(best)) best = std::move(p);
  }
  return best;
}

std::vector<Eigen::Vector2i> ChartSizes(const std::vector<ProjectedChart>& charts,
                                        double texel_size_m, int gutter) {
  std::vector<Eigen::Vector2i> sizes;
  for (const ProjectedChart& chart : charts) {
    const Eigen::Vector2d texels = chart.extent_m / texel_size_m;
    // (A chart overhanging its ceil by 1e-6 texel stays well inside its gutter.)
    sizes.emplace_back(static_cast<int>(std::ceil(texels.x() - 1e-6)) + 2 * gutter,
                       static_cast<int>(std::ceil(texels.y() - 1e-6)) + 2 * gutter);
  }
  return sizes;
}

// The texel size (> options.texel_size_m) at which the charts pack into max_size, within 1% of
// the smallest such; sets *packing. 0 when none does (too many charts for the gutters).
double FittingTexelSize(const std::vector<ProjectedChart>& charts, const AtlasOptions& options,
                        Packing* packing) {
  auto pack = [&](double texel) { return Pack(ChartSizes(charts, texel, options.gutter_texels)); };
  auto fits = [&](const Packing& p) { return std::max(p.width, p.height) <= options.max_size; };
  double too_small = options.texel_size_m, big = too_small;
  Packing fitting;
  for (int attempt = 0;; ++attempt) {  // grow until it fits
    if (attempt >= kMaxGrowAttempts) return 0;
    big *= 2;
    fitting = pack(big);
    if (fits(fitting)) break;
    too_small = big;
  }
  while (big > too_small * 1.01) {  // then bisect
    const double mid = std::sqrt(big * too_small);
    Packing p = pack(mid);
    if (fits(p)) {
      big = mid;
      fitting = std::move(p);
    } else {
      too_small = mid;
    }
  }
  *packing = std::move(fitting);
  return big;
}

void GenerateCharts(const recon::TriangleMesh& mesh, const AtlasOptions& options,
                    RegionAtlas* atlas) {
  const std::vector<int>& tris = atlas->triangles;
  std::vector<Face> faces;
  for (int t : tris) faces.push_back(MakeFace(mesh, t));
  std::vector<ProjectedChart> charts;
  for (const auto& members : MakeCharts(faces, Neighbours(mesh, tris), options.chart_angle_deg)) {
    charts.push_back(ProjectChart(mesh, tris, faces, members));
  }
  double texel = options.texel_size_m;
  Packing packing = Pack(ChartSizes(charts, texel, options.gutter_texels));
  if (std::max(packing.width, packing.height) > options.max_size) {
    texel = FittingTexelSize(charts, options, &packing);
    if (texel <= 0) {
      throw Error("region " + mesh.region_names.at(atlas->region) + ": " +
                  std::to_string(charts.size()) + " charts do not fit into " +
                  std::to_string(options.max_size) + " texels at any texel size");
    }
  }
  atlas->texel_size_m = texel;
  atlas->width = packing.width;
  atlas->height = packing.height;
  atlas->num_charts = static_cast<int>(charts.size());
  const Eigen::Vector2d atlas_size(packing.width, packing.height);
  for (size_t c = 0; c < charts.size(); ++c) {
    const Eigen::Vector2d origin =
        packing.origin[c].cast<double>() + Eigen::Vector2d::Constant(options.gutter_texels);
    for (size_t i = 0; i < charts[c].local_triangles.size(); ++i) {
      const int t = tris[charts[c].local_triangles[i]];
      atlas->triangle_chart[t] = int(c);
      for (int k = 0; k < 3; ++k) {
        const Eigen::Vector2d texel_xy = origin + charts[c].corners_m[i][k] / texel;
        atlas->corner_uv[t][k] = texel_xy.cwiseQuotient(atlas_size).cast<float>();
      }
    }
  }
}

}  // namespace

void AtlasOptions::Validate() const {
  auto fail = [](const std::string& key, double value, const std::string& rule) {
    throw InputError(DescribeProblem("", key, ShortestText(value), rule));
  };
  if (!(texel_size_m > 0) || !std::isfinite(texel_size_m)) {
    fail("texel_size_m", texel_size_m, "must be a finite number > 0");
  }
  if (gutter_texels < 1) fail("gutter_texels", double(gutter_texels), "must be >= 1");
  if (max_size < 8) fail("max_size", double(max_size), "must be >= 8");
  if (!(chart_angle_deg > 0 && chart_angle_deg < 90)) {
    fail("chart_angle_deg", chart_angle_deg, "must be in (0, 90)");
  }
}

Eigen::Vector2d RegionAtlas::UvAt(int triangle, double b1, double b2) const {
  const auto& uv = corner_uv[triangle];
  return (1 - b1 - b2) * uv[0].cast<double>() + b1 * uv[1].cast<double>() +
         b2 * uv[2].cast<double>();
}

RegionAtlas BuildRegionAtlas(const recon::TriangleMesh& mesh, int region,
                             const AtlasOptions& options) {
  options.Validate();
  if (region < 0 || region >= static_cast<int>(mesh.region_names.size())) {
    throw Error("BuildRegionAtlas: region " + std::to_string(region) + " is not in the mesh");
  }
  RegionAtlas atlas;
  atlas.region = region;
  for (size_t t = 0; t < mesh.num_triangles(); ++t) {
    if (mesh.triangle_region[t] == region) atlas.triangles.push_back(static_cast<int>(t));
  }
  if (atlas.triangles.empty()) {
    throw InputError(DescribeProblem("", "region", mesh.region_names[region],
                                     "has no triangles: no albedo map can be made"));
  }
  atlas.corner_uv.assign(mesh.num_triangles(), {Eigen::Vector2f::Zero(), Eigen::Vector2f::Zero(),
                                                Eigen::Vector2f::Zero()});
  atlas.triangle_chart.assign(mesh.num_triangles(), -1);
  Eigen::Vector2d scale_m;
  if (MeshUvScale(mesh, atlas.triangles, &scale_m)) {
    FillFromMeshUvs(mesh, scale_m, options, &atlas);
  } else {
    atlas.generated = true;
    GenerateCharts(mesh, options, &atlas);
  }
  if (atlas.texel_size_m > options.texel_size_m * (1 + 1e-9)) {
    spdlog::warn("region {}: albedo map limited to {} texels: texel size grown from {} m to {} m",
                 mesh.region_names[region], options.max_size, options.texel_size_m,
                 atlas.texel_size_m);
  }
  spdlog::debug("region {}: albedo atlas {}x{} texels of {} m, {}", mesh.region_names[region],
                atlas.width, atlas.height, atlas.texel_size_m,
                atlas.generated ? std::to_string(atlas.num_charts) + " generated charts"
                                : std::string("mesh UVs"));
  return atlas;
}

void WriteObjWithAtlases(const recon::TriangleMesh& mesh, const std::vector<RegionAtlas>& atlases,
                         const std::filesystem::path& path) {
  std::vector<const RegionAtlas*> atlas_of(mesh.region_names.size(), nullptr);
  for (const RegionAtlas& atlas : atlases) {
    if (atlas.region < 0 || atlas.region >= int(atlas_of.size()) ||
        atlas.corner_uv.size() != mesh.num_triangles()) {
      throw Error(path.string() + ": an albedo atlas (region " + std::to_string(atlas.region) +
                  ") does not belong to this mesh");
    }
    atlas_of[atlas.region] = &atlas;
  }
  const bool normals = mesh.has_normals() && mesh.normals.size() == mesh.positions.size();
  const bool uvs = mesh.has_uvs() && mesh.uvs.size() == mesh.positions.size();
  std::string text = "# igi: mesh with albedo-map UVs (v, vt per corner, vn, usemtl regions)\n";
  for (const Eigen::Vector3f& p : mesh.positions) {
    text += "v " + Num(p.x()) + ' ' + Num(p.y()) + ' ' + Num(p.z()) + '\n';
  }
  if (normals) {
    for (const Eigen::Vector3f& n : mesh.normals) {
      text += "vn " + Num(n.x()) + ' ' + Num(n.y()) + ' ' + Num(n.z()) + '\n';
    }
  }
  size_t corner = 0;
  for (size_t r = 0; r < mesh.region_names.size(); ++r) {
    std::string faces;
    for (size_t t = 0; t < mesh.num_triangles(); ++t) {
      if (mesh.triangle_region[t] != int(r)) continue;
      faces += 'f';
      for (int k = 0; k < 3; ++k) {
        const int v = mesh.triangles[t][k];
        Eigen::Vector2f uv = Eigen::Vector2f::Zero();
        if (atlas_of[r] != nullptr) {
          uv = atlas_of[r]->corner_uv[t][k];
        } else if (uvs) {
          uv = mesh.uvs[v];
        }
        text += "vt " + Num(uv.x()) + ' ' + Num(uv.y()) + '\n';
        const std::string vi = std::to_string(v + 1);
        faces += ' ' + vi + '/' + std::to_string(++corner) + (normals ? '/' + vi : "");
      }
      faces += '\n';
    }
    if (!faces.empty()) text += "usemtl " + mesh.region_names[r] + '\n' + faces;
  }
  WriteFileAtomic(path, text);
}

}  // namespace igi::solver
