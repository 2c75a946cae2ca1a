#pragma once
// The texture parameterisation of one region, for its albedo map: the mesh's own UVs
// where it has usable ones, else charts generated from the geometry and packed into one atlas.
//
// UV convention (the renderer's, solver/render/render.cpp SampleTexture): u right, v up, in [0, 1];
// v = 0 is the image's bottom row; texel (i, j) (column i, row j, row 0 = top) has its centre at
// ((i + 0.5) / W, 1 - (j + 0.5) / H), and lookups are bilinear between texel centres.
//
// Units: world metres.

#include <Eigen/Core>
#include <array>
#include <filesystem>
#include <vector>

#include "recon/mesh.h"

namespace igi::solver {

struct AtlasOptions {
  double texel_size_m = 0.01;  // world size of one texel (metres), > 0
  // Padding around each generated chart (texels), >= 1: bilinear lookups and splats inside one
  // chart never touch another chart's texels.
  int gutter_texels = 2;
  // Largest width/height (texels), >= 8; when exceeded the texel size grows (RegionAtlas::
  // texel_size_m says by how much, and a warning is logged).
  int max_size = 4096;
  // Generated charts: a triangle joins a chart while its normal is within this angle (degrees) of
  // the chart's (area-weighted mean) normal. In (0, 90).
  double chart_angle_deg = 30;

  // Throws InputError "KEY: VALUE: RULE" naming the first bad field.
  void Validate() const;
};

struct RegionAtlas {
  int region = -1;
  int width = 0, height = 0;   // texels
  double texel_size_m = 0;     // actually used (>= AtlasOptions::texel_size_m)
  bool generated = false;      // true: charts generated (the mesh had no usable UVs for the region)
  int num_charts = 0;          // generated charts (1 when the mesh's UVs are used)
  std::vector<int> triangles;  // the region's triangles (indices into the mesh), ascending
  // Per mesh triangle (size = mesh.num_triangles(); only this region's triangles meaningful):
  // UV of each corner, u right and v up in [0,1] (v = 0 is the image's bottom row).
  std::vector<std::array<Eigen::Vector2f, 3>> corner_uv;
  // Per mesh triangle: its chart in [0, num_charts), -1 for other regions' triangles.
  std::vector<int> triangle_chart;

  // The UV at barycentrics (b1, b2) of corners 1 and 2 (corner 0 has 1 - b1 - b2).
  Eigen::Vector2d UvAt(int triangle, double b1, double b2) const;
};

// The region's atlas. Uses the mesh's UVs when it has UVs and the region's triangles carrying
// non-degenerate UVs cover at least 99% of its world area; the map's size then follows from the
// area-weighted world length of a unit step in u and in v (so W/H match the surface's aspect),
// divided by the texel size. Otherwise generates charts (region growing over shared edges, vertex
// positions welded exactly), projects each onto its plane in the orientation of its smallest
// bounding rectangle, at exactly the texel size, and shelf-packs the chart rectangles with
// gutters. Throws InputError when the region has no triangles, igi::Error when even the largest
// texel size tried cannot fit the charts into max_size.
RegionAtlas BuildRegionAtlas(const recon::TriangleMesh& mesh, int region,
                             const AtlasOptions& options);

// Writes every triangle of `mesh` as OBJ: `v` per vertex, `vt` per triangle corner, `vn` per
// vertex (when the mesh has normals), faces grouped by region in region order (`usemtl NAME`),
// each group's triangles in mesh order. Corner UVs come from the atlas of the triangle's region in
// `atlases` when there is one, else from the mesh's UVs, else (0, 0). Atomic. Throws igi::Error
// when an atlas does not belong to this mesh (size mismatch) or the write fails.
void WriteObjWithAtlases(const recon::TriangleMesh& mesh, const std::vector<RegionAtlas>& atlases,
                         const std::filesystem::path& path);

}  // namespace igi::solver
