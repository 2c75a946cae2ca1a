#pragma once
// A small triangle-mesh builder for synthetic scenes: quads, boxes and spheres with a region
// (material name) per triangle, per-vertex normals and UVs, written as Wavefront OBJ with
// `usemtl` regions (docs/scene-format.md). Also a brute-force ray caster, enough for the few
// thousand triangles of a synthetic room (camera placement and visibility checks).
//
// Units: metres, world frame. Counter-clockwise winding seen from the front = front face.

#include <Eigen/Core>
#include <array>
#include <optional>
#include <string>
#include <vector>

namespace igi::synth {

struct SynthMesh {
  std::vector<Eigen::Vector3d> positions;
  std::vector<Eigen::Vector3d> normals;  // per vertex, unit
  std::vector<Eigen::Vector2d> uvs;      // per vertex
  std::vector<Eigen::Vector3i> triangles;
  std::vector<int> triangle_region;  // index into region_names
  std::vector<std::string> region_names;

  int RegionIndex(const std::string& name);       // adds the region when new
  int FindRegion(const std::string& name) const;  // -1 when absent

  // A planar quad p0 p1 p2 p3 (counter-clockwise seen from the front), flat normal; the UVs of
  // the corners are given (u right, v up).
  void AddQuad(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, const Eigen::Vector3d& p2,
               const Eigen::Vector3d& p3, const std::string& region,
               const std::array<Eigen::Vector2d, 4>& uv = {});
  // A closed box standing on z = `base_z`, centre (x, y), size (sx, sy, sz), rotated `yaw_deg`
  // about z, faces outward.
  void AddBox(const Eigen::Vector2d& center_xy, double base_z, const Eigen::Vector3d& size,
              double yaw_deg, const std::string& region);
  // A UV sphere with smooth normals, `rings` x `segments` quads.
  void AddSphere(const Eigen::Vector3d& center, double radius, int rings, int segments,
                 const std::string& region);

  Eigen::Vector3d FaceNormal(int triangle) const;  // unit, from the winding
  double TriangleArea(int triangle) const;

  // The OBJ text (v, vt, vn, usemtl, f), with `header` as a comment.
  std::string ToObj(const std::string& header) const;
};

struct MeshHit {
  double distance = 0;
  int triangle = -1;
};
// The nearest hit of the ray origin + t·direction (direction unit) with t in (t_min, t_max);
// both faces count.
std::optional<MeshHit> IntersectRay(const SynthMesh& mesh, const Eigen::Vector3d& origin,
                                    const Eigen::Vector3d& direction, double t_min = 1e-6,
                                    double t_max = 1e30);
// Whether nothing blocks the open segment between a and b (ends excluded by `epsilon` metres).
bool SegmentVisible(const SynthMesh& mesh, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                    double epsilon = 1e-4);

}  // namespace igi::synth
