// Region atlases (solver/inverse/uv_charts.h): the mesh's UVs where usable, generated charts
// otherwise, and the OBJ written with them.
#include "solver/inverse/uv_charts.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>

#include "tests/temp_dir.h"

namespace igi::solver {
namespace {

// A w×h rectangle in z = 0 facing +z, UVs [0,1]² (u along x, v along y), region "floor".
recon::TriangleMesh Quad(float w, float h, bool with_uvs) {
  recon::TriangleMesh mesh;
  mesh.positions = {{0, 0, 0}, {w, 0, 0}, {w, h, 0}, {0, h, 0}};
  mesh.normals.assign(4, Eigen::Vector3f::UnitZ());
  if (with_uvs) mesh.uvs = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  mesh.triangle_region = {0, 0};
  mesh.region_names = {"floor"};
  return mesh;
}

// A 1 × 0.6 × 0.4 m box, 8 shared vertices, 12 outward triangles; the +z face is region "lid",
// the other five "box". No UVs.
recon::TriangleMesh Box() {
  recon::TriangleMesh mesh;
  const Eigen::Vector3f size(1.0f, 0.6f, 0.4f);
  for (int i = 0; i < 8; ++i) {
    const Eigen::Vector3f corner((i & 1) ? size.x() : 0, (i & 2) ? size.y() : 0,
                                 (i & 4) ? size.z() : 0);
    mesh.positions.push_back(corner);
    mesh.normals.push_back((corner - size / 2).normalized());
  }
  // Each face as a quad (counter-clockwise seen from outside).
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  mesh.region_names = {"box", "lid"};
  for (int f = 0; f < 6; ++f) {
    const int* q = quads[f];
    mesh.triangles.emplace_back(q[0], q[1], q[2]);
    mesh.triangles.emplace_back(q[0], q[2], q[3]);
    mesh.triangle_region.insert(mesh.triangle_region.end(), 2, f == 1 ? 1 : 0);
  }
  return mesh;
}

// Unshared vertices, one per corner (as LoadMesh makes a file without normals).
recon::TriangleMesh Unshared(const recon::TriangleMesh& mesh) {
  recon::TriangleMesh out = mesh;
  out.positions.clear();
  out.normals.clear();
  for (size_t t = 0; t < mesh.num_triangles(); ++t) {
    for (int k = 0; k < 3; ++k) {
      out.positions.push_back(mesh.positions[mesh.triangles[t][k]]);
      out.normals.push_back(mesh.FaceNormal(t));
    }
    out.triangles[t] = Eigen::Vector3i(3 * t, 3 * t + 1, 3 * t + 2);
  }
  return out;
}

// An icosahedron subdivided `levels` times onto a sphere of `radius`, region "ball".
recon::TriangleMesh Icosphere(int levels, float radius) {
  const float g = (1 + std::sqrt(5.0f)) / 2;
  std::vector<Eigen::Vector3f> p = {{-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0},
                                    {0, -1, g}, {0, 1, g}, {0, -1, -g}, {0, 1, -g},
                                    {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}};
  std::vector<Eigen::Vector3i> tris = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                       {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                       {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                       {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (Eigen::Vector3f& v : p) v.normalize();
  for (int l = 0; l < levels; ++l) {
    std::map<std::pair<int, int>, int> mid;
    auto midpoint = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      auto [it, inserted] = mid.try_emplace({key.first, key.second}, int(p.size()));
      if (inserted) p.push_back((p[a] + p[b]).normalized());
      return it->second;
    };
    std::vector<Eigen::Vector3i> next;
    for (const Eigen::Vector3i& t : tris) {
      const int a = midpoint(t[0], t[1]), b = midpoint(t[1], t[2]), c = midpoint(t[2], t[0]);
      next.insert(next.end(), {{t[0], a, c}, {t[1], b, a}, {t[2], c, b}, {a, b, c}});
    }
    tris = next;
  }
  recon::TriangleMesh mesh;
  for (const Eigen::Vector3f& v : p) {
    mesh.positions.push_back(v * radius);
    mesh.normals.push_back(v);
  }
  mesh.triangles = tris;
  mesh.triangle_region.assign(tris.size(), 0);
  mesh.region_names = {"ball"};
  return mesh;
}

struct AtlasCheck {
  double min_scale = INFINITY, max_scale = 0;  // texel-space edge length / (world length / texel)
  int64_t footprint_conflicts = 0;  // texels read by bilinear lookups of two different charts
  int64_t raster_conflicts = 0;     // texel centres inside triangles of two different charts
  int64_t mirrored = 0;             // triangles with clockwise UVs (a fold)
  double fill = 0;                  // UV area of the triangles / atlas area
};

// Checks a generated atlas: UVs in [0,1]², scale, disjoint chart footprints (each chart's
// bilinear footprint bounding box, so gutters included) and rasterised overlap.
AtlasCheck CheckAtlas(const recon::TriangleMesh& mesh, const RegionAtlas& atlas) {
  AtlasCheck check;
  const int w = atlas.width, h = atlas.height;
  std::vector<int> footprint(size_t(w) * h, -1), raster(size_t(w) * h, -1);
  std::map<int, Eigen::Array4d> chart_box;  // x_lo, y_lo, x_hi, y_hi in lookup coordinates
  for (int t : atlas.triangles) {
    const int chart = atlas.triangle_chart[t];
    EXPECT_GE(chart, 0);
    EXPECT_LT(chart, atlas.num_charts);
    std::array<Eigen::Vector2d, 3> px;  // pixel coordinates (x right, y down)
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector2f uv = atlas.corner_uv[t][k];
      EXPECT_TRUE(uv.x() >= 0 && uv.x() <= 1 && uv.y() >= 0 && uv.y() <= 1) << uv.transpose();
      px[k] = Eigen::Vector2d(uv.x() * w, (1 - uv.y()) * h);
    }
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector2d e = px[(k + 1) % 3] - px[k];
      const double world =
          (mesh.positions[mesh.triangles[t][(k + 1) % 3]] - mesh.positions[mesh.triangles[t][k]])
              .cast<double>()
              .norm();
      const double scale = e.norm() / (world / atlas.texel_size_m);
      check.min_scale = std::min(check.min_scale, scale);
      check.max_scale = std::max(check.max_scale, scale);
    }
    const Eigen::Vector2d e1 = px[1] - px[0], e2 = px[2] - px[0];
    const double cross = e1.x() * e2.y() - e1.y() * e2.x();  // y down: CCW in UV is negative
    if (cross > 0) ++check.mirrored;
    check.fill += std::abs(cross) / 2 / (double(w) * h);
    auto [it, inserted] =
        chart_box.try_emplace(chart, Eigen::Array4d(INFINITY, INFINITY, -INFINITY, -INFINITY));
    for (const auto& p : px) {
      it->second = it->second.min(Eigen::Array4d(p.x() - 0.5, p.y() - 0.5, INFINITY, INFINITY))
                       .max(Eigen::Array4d(-INFINITY, -INFINITY, p.x() - 0.5, p.y() - 0.5));
    }
    const Eigen::Vector2d lo = px[0].cwiseMin(px[1]).cwiseMin(px[2]);
    const Eigen::Vector2d hi = px[0].cwiseMax(px[1]).cwiseMax(px[2]);
    for (int y = std::max(0, int(lo.y()) - 1); y < std::min(h, int(hi.y()) + 1); ++y) {
      for (int x = std::max(0, int(lo.x()) - 1); x < std::min(w, int(hi.x()) + 1); ++x) {
        double sign = 0;
        bool inside = true;
        for (int k = 0; k < 3 && inside; ++k) {
          const Eigen::Vector2d a = px[k], b = px[(k + 1) % 3];
          const double e =
              (b.x() - a.x()) * (y + 0.5 - a.y()) - (b.y() - a.y()) * (x + 0.5 - a.x());
          if (e != 0 && sign == 0) sign = e;
          if (e != 0 && (e > 0) != (sign > 0)) inside = false;
        }
        if (!inside) continue;
        int& cell = raster[size_t(y) * w + x];
        if (cell >= 0 && cell != chart) ++check.raster_conflicts;
        cell = chart;
      }
    }
  }
  for (const auto& [chart, box] : chart_box) {
    // Lookups at x read texels floor(x) and floor(x) + 1.
    const int x0 = int(std::floor(box[0])), y0 = int(std::floor(box[1]));
    const int x1 = int(std::floor(box[2])) + 1, y1 = int(std::floor(box[3])) + 1;
    EXPECT_GE(x0, 0) << "chart " << chart << " reads left of the atlas";
    EXPECT_GE(y0, 0);
    EXPECT_LT(x1, w);
    EXPECT_LT(y1, h);
    for (int y = std::max(0, y0); y <= std::min(h - 1, y1); ++y) {
      for (int x = std::max(0, x0); x <= std::min(w - 1, x1); ++x) {
        int& cell = footprint[size_t(y) * w + x];
        if (cell >= 0 && cell != chart) ++check.footprint_conflicts;
        cell = chart;
      }
    }
  }
  return check;
}

TEST(AtlasOptions, ValidateRejectsBadValues) {
  EXPECT_NO_THROW(AtlasOptions().Validate());
  auto expect_bad = [](AtlasOptions o, const std::string& key) {
    try {
      o.Validate();
      ADD_FAILURE() << key << " accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
    }
  };
  AtlasOptions o;
  o.texel_size_m = 0;
  expect_bad(o, "texel_size_m");
  o.texel_size_m = NAN;
  expect_bad(o, "texel_size_m");
  o = {};
  o.gutter_texels = 0;
  expect_bad(o, "gutter_texels");
  o = {};
  o.max_size = 4;
  expect_bad(o, "max_size");
  o = {};
  o.chart_angle_deg = 90;
  expect_bad(o, "chart_angle_deg");
  o.chart_angle_deg = 0;
  expect_bad(o, "chart_angle_deg");
  // BuildRegionAtlas validates first.
  EXPECT_THROW(BuildRegionAtlas(Quad(1, 1, true), 0, o), InputError);
}

TEST(BuildRegionAtlas, RejectsMissingAndEmptyRegions) {
  recon::TriangleMesh mesh = Quad(1, 1, true);
  EXPECT_THROW(BuildRegionAtlas(mesh, 1, {}), Error);
  mesh.region_names.push_back("empty");
  EXPECT_THROW(BuildRegionAtlas(mesh, 1, {}), InputError);
}

TEST(BuildRegionAtlas, UsesMeshUvsWithSizeFromTexelSize) {
  const recon::TriangleMesh mesh = Quad(1.0f, 0.5f, true);
  AtlasOptions options;
  options.texel_size_m = 0.01;
  const RegionAtlas atlas = BuildRegionAtlas(mesh, 0, options);
  EXPECT_FALSE(atlas.generated);
  EXPECT_EQ(atlas.num_charts, 1);
  // A unit step in u is 1 m and in v 0.5 m: 100 × 50 texels of 1 cm.
  EXPECT_EQ(atlas.width, 100);
  EXPECT_EQ(atlas.height, 50);
  EXPECT_DOUBLE_EQ(atlas.texel_size_m, 0.01);
  EXPECT_EQ(atlas.triangles, (std::vector<int>{0, 1}));
  for (int t = 0; t < 2; ++t) {
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(atlas.corner_uv[t][k], mesh.uvs[mesh.triangles[t][k]]);
    }
  }
  // UvAt interpolates the corners: barycentrics (b1, b2) of triangle 0 = (0,0),(1,0),(1,1).
  EXPECT_TRUE(atlas.UvAt(0, 0.25, 0.5).isApprox(Eigen::Vector2d(0.75, 0.5)));

  // Too large for max_size: the texel grows to 1 m / 40 = 2.5 cm.
  options.max_size = 40;
  const RegionAtlas small = BuildRegionAtlas(mesh, 0, options);
  EXPECT_EQ(small.width, 40);
  EXPECT_EQ(small.height, 20);
  EXPECT_NEAR(small.texel_size_m, 0.025, 1e-12);
}

TEST(BuildRegionAtlas, DegenerateMeshUvsAreReplacedByCharts) {
  recon::TriangleMesh mesh = Quad(1.0f, 0.5f, true);
  mesh.uvs.assign(4, Eigen::Vector2f::Zero());  // as TriangleMesh::Append pads a mesh without UVs
  const RegionAtlas atlas = BuildRegionAtlas(mesh, 0, {});
  EXPECT_TRUE(atlas.generated);
  EXPECT_EQ(atlas.num_charts, 1);
  // One chart of 100 × 50 texels plus 2 gutter texels on each side.
  EXPECT_EQ(atlas.width, 104);
  EXPECT_EQ(atlas.height, 54);
}

TEST(BuildRegionAtlas, BoxGetsOneChartPerFace) {
  for (bool unshared : {false, true}) {
    const recon::TriangleMesh mesh = unshared ? Unshared(Box()) : Box();
    AtlasOptions options;
    options.texel_size_m = 0.01;
    const RegionAtlas atlas = BuildRegionAtlas(mesh, 0, options);
    EXPECT_TRUE(atlas.generated);
    EXPECT_EQ(atlas.num_charts, 5) << "unshared " << unshared;
    EXPECT_EQ(atlas.triangles.size(), 10u);
    EXPECT_DOUBLE_EQ(atlas.texel_size_m, 0.01);
    const AtlasCheck check = CheckAtlas(mesh, atlas);
    // Planar faces projected onto their own plane: the scale is exact up to float UVs (1e-7
    // relative × a few hundred texels), so 1e-4.
    EXPECT_NEAR(check.min_scale, 1.0, 1e-4);
    EXPECT_NEAR(check.max_scale, 1.0, 1e-4);
    EXPECT_EQ(check.footprint_conflicts, 0);
    EXPECT_EQ(check.raster_conflicts, 0);
    EXPECT_EQ(check.mirrored, 0);
    // Shelf packing of 5 rectangles of 104×64, 104×44, 64×44 texels: no worse than half empty.
    EXPECT_GT(check.fill, 0.5) << atlas.width << "x" << atlas.height;
    // The triangles of the other region are not part of this atlas.
    EXPECT_EQ(atlas.triangle_chart[2], -1);
  }
}

TEST(BuildRegionAtlas, GrowsTexelToFitMaxSize) {
  const recon::TriangleMesh mesh = Box();
  AtlasOptions options;
  options.texel_size_m = 0.01;
  options.max_size = 64;
  const RegionAtlas atlas = BuildRegionAtlas(mesh, 0, options);
  EXPECT_LE(atlas.width, 64);
  EXPECT_LE(atlas.height, 64);
  EXPECT_GT(atlas.texel_size_m, 0.01);
  const AtlasCheck check = CheckAtlas(mesh, atlas);
  EXPECT_NEAR(check.min_scale, 1.0, 1e-4);
  EXPECT_NEAR(check.max_scale, 1.0, 1e-4);
  EXPECT_EQ(check.footprint_conflicts, 0);
}

TEST(BuildRegionAtlas, SphereChartsAreDisjointAndNearlyIsometric) {
  const recon::TriangleMesh mesh = Icosphere(3, 0.5f);  // 1280 triangles
  AtlasOptions options;
  options.texel_size_m = 0.01;
  options.chart_angle_deg = 15;
  const RegionAtlas atlas = BuildRegionAtlas(mesh, 0, options);
  EXPECT_TRUE(atlas.generated);
  EXPECT_GT(atlas.num_charts, 10);
  const AtlasCheck check = CheckAtlas(mesh, atlas);
  // An orthogonal projection never lengthens (max 1, up to float UVs) and shortens an edge by
  // cos(its tilt to the chart's plane): triangles join within 15 degrees of the running mean
  // normal, which drifts a little, so >= cos(20°) = 0.94.
  EXPECT_LE(check.max_scale, 1.0001);
  EXPECT_GE(check.min_scale, 0.94);
  EXPECT_EQ(check.footprint_conflicts, 0);
  EXPECT_EQ(check.raster_conflicts, 0);
  EXPECT_EQ(check.mirrored, 0);
  EXPECT_GT(check.fill, 0.3);
  RecordProperty("charts", atlas.num_charts);
  std::printf("sphere: %d charts, %dx%d, scale [%.4f, %.4f], fill %.3f\n", atlas.num_charts,
              atlas.width, atlas.height, check.min_scale, check.max_scale, check.fill);

  options.chart_angle_deg = 30;  // the default: fewer, larger charts, more shortening
  const RegionAtlas coarse = BuildRegionAtlas(mesh, 0, options);
  const AtlasCheck coarse_check = CheckAtlas(mesh, coarse);
  EXPECT_LT(coarse.num_charts, atlas.num_charts);
  EXPECT_GE(coarse_check.min_scale, std::cos(40 * M_PI / 180));
  EXPECT_EQ(coarse_check.footprint_conflicts, 0);
  EXPECT_EQ(coarse_check.mirrored, 0);
  std::printf("sphere 30deg: %d charts, %dx%d, scale [%.4f, %.4f], fill %.3f\n", coarse.num_charts,
              coarse.width, coarse.height, coarse_check.min_scale, coarse_check.max_scale,
              coarse_check.fill);
}

// Emission order of WriteObjWithAtlases: by region, then mesh order.
std::vector<int> ObjOrder(const recon::TriangleMesh& mesh) {
  std::vector<int> order;
  for (size_t r = 0; r < mesh.region_names.size(); ++r) {
    for (size_t t = 0; t < mesh.num_triangles(); ++t) {
      if (mesh.triangle_region[t] == int(r)) order.push_back(int(t));
    }
  }
  return order;
}

TEST(WriteObjWithAtlases, RoundTripsThroughLoadMesh) {
  // floor (mesh UVs, no atlas), box + lid (generated atlases), ball (no atlas: mesh UVs, which
  // Append padded with (0, 0)).
  recon::TriangleMesh mesh = Quad(1.0f, 0.5f, true);
  mesh.Append(Box());
  mesh.Append(Icosphere(1, 0.3f));
  ASSERT_EQ(mesh.region_names, (std::vector<std::string>{"floor", "box", "lid", "ball"}));
  std::vector<RegionAtlas> atlases = {BuildRegionAtlas(mesh, 1, {}), BuildRegionAtlas(mesh, 2, {})};
  ASSERT_TRUE(atlases[0].generated);
  const auto dir = test::UniqueTempDir("igi_uv_charts");
  WriteObjWithAtlases(mesh, atlases, dir / "mesh.obj");
  ProblemList problems;
  recon::MeshLoadSummary summary;
  const recon::TriangleMesh loaded = recon::LoadMesh(dir / "mesh.obj", &problems, &summary);
  ASSERT_TRUE(problems.empty()) << problems.problems().front();
  EXPECT_TRUE(summary.has_uvs);
  EXPECT_TRUE(summary.has_normals);
  ASSERT_EQ(loaded.num_triangles(), mesh.num_triangles());
  EXPECT_EQ(loaded.region_names, mesh.region_names);
  const std::vector<int> order = ObjOrder(mesh);
  // Text round trip of floats (shortest representation; Assimp's parser may be off by an ulp).
  constexpr float kTol = 1e-6f;
  for (size_t i = 0; i < order.size(); ++i) {
    const int t = order[i];
    const int r = mesh.triangle_region[t];
    ASSERT_EQ(loaded.triangle_region[i], r);
    for (int k = 0; k < 3; ++k) {
      const int v = mesh.triangles[t][k], lv = loaded.triangles[i][k];
      EXPECT_TRUE(loaded.positions[lv].isApprox(mesh.positions[v], kTol)) << i << " " << k;
      EXPECT_TRUE(loaded.normals[lv].isApprox(mesh.normals[v], kTol));
      Eigen::Vector2f uv = mesh.uvs[v];
      if (r == 1 || r == 2) uv = atlases[r - 1].corner_uv[t][k];
      EXPECT_NEAR((loaded.uvs[lv] - uv).norm(), 0, kTol) << "triangle " << t << " region " << r;
    }
  }
  // An atlas of another mesh is refused before anything is written.
  RegionAtlas foreign = atlases[0];
  foreign.corner_uv.pop_back();
  EXPECT_THROW(WriteObjWithAtlases(mesh, {foreign}, dir / "other.obj"), Error);
  EXPECT_FALSE(std::filesystem::exists(dir / "other.obj"));
}

}  // namespace
}  // namespace igi::solver
