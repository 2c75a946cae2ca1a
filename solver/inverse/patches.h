#pragma once
// The scene's surface split into patches (Yu et al. 1999 §4: "the scene is partitioned
// hierarchically into patches"): region → triangle → patch. Each triangle is cut into k×k
// congruent sub-triangles (a barycentric grid), k chosen so that no patch edge exceeds the patch
// size. Patches carry the image-based radiance the solver gathers to compute irradiance.
//
// World frame, metres.

#include <Eigen/Core>
#include <vector>

#include "recon/mesh.h"

namespace igi::solver {

struct PatchSet {
  std::vector<int> triangle_first;  // first patch of each triangle; size = triangles + 1
  std::vector<int> triangle_k;      // grid resolution of each triangle (k² patches)
  std::vector<int> patch_triangle;  // per patch
  std::vector<int> patch_region;    // per patch, index into Scene::materials
  std::vector<Eigen::Vector3f> center;  // per patch, world
  std::vector<Eigen::Vector3f> normal;  // per patch: shading normal at the centre, front side
  std::vector<Eigen::Vector2f> center_bary;  // per patch: barycentrics (b1, b2) of the centre
  std::vector<float> area;                   // per patch, m²

  int size() const { return static_cast<int>(patch_triangle.size()); }
  // The patch holding the point with barycentrics (b1, b2) of vertices 1 and 2 of `triangle`.
  int PatchOf(int triangle, double b1, double b2) const;
};

// Splits every triangle of `mesh` so that patch edges are at most `patch_size_m` (k at most 64
// per triangle edge). patch_size_m must be > 0.
PatchSet BuildPatches(const recon::TriangleMesh& mesh, double patch_size_m);

}  // namespace igi::solver
