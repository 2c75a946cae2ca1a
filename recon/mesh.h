#pragma once
// Triangle meshes of a scene (docs/scene-format.md): any format Assimp reads. Each triangle's
// material name (OBJ `usemtl`, glTF material name) is its region. UVs (u right, v up: v = 0 is a
// texture's bottom row) and vertex normals are kept where the file has them; without normals
// faces are shaded flat. Positions are in the scene's world frame, metres.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <filesystem>
#include <string>
#include <vector>

#include "tools/common/error.h"

namespace igi::recon {

struct TriangleMesh {
  std::vector<Eigen::Vector3f> positions;
  // Per vertex, unit length. A file without normals is shaded flat: its vertices are unshared
  // and each carries its face's normal, so `normals` is always filled after LoadMesh.
  std::vector<Eigen::Vector3f> normals;
  std::vector<Eigen::Vector2f> uvs;  // per vertex; empty = no file had texture coordinates
  std::vector<Eigen::Vector3i> triangles;
  std::vector<int> triangle_region;       // per triangle, index into region_names
  std::vector<std::string> region_names;  // material names, in order of first appearance

  size_t num_triangles() const { return triangles.size(); }
  bool has_normals() const { return !normals.empty(); }
  bool has_uvs() const { return !uvs.empty(); }

  // Geometric (face) normal, unit length, counter-clockwise winding = front.
  Eigen::Vector3f FaceNormal(size_t triangle) const;
  double TriangleArea(size_t triangle) const;
  // Appends `other`, merging regions by name. When only one side has UVs, the other side's
  // vertices get (0, 0).
  void Append(const TriangleMesh& other);
};

struct MeshLoadSummary {
  size_t num_vertices = 0;
  size_t num_triangles = 0;
  size_t num_degenerate_dropped = 0;  // zero-area triangles removed on load
  bool has_normals = false;  // the file had vertex normals (else: flat shading)
  bool has_uvs = false;      // the file had texture coordinates
};

// Loads `path` with Assimp into one triangle mesh (node transforms applied, polygons
// triangulated, identical vertices joined, points and lines dropped). Problems — unreadable file, no triangles, non-finite
// positions — are added to `problems` naming `path` (and the vertex); returns what was read.
TriangleMesh LoadMesh(const std::filesystem::path& path, ProblemList* problems,
                      MeshLoadSummary* summary = nullptr);

}  // namespace igi::recon
