#pragma once
// Closest points on a triangle mesh (Embree's BVH point queries; exact point-triangle distance
// in double precision), and rays against it (Embree's ray queries). Used to fit reconstructed
// points to a scene mesh, and for visibility on a mesh outside the renderer.

#include <Eigen/Core>
#include <memory>
#include <optional>

#include "recon/mesh.h"

namespace igi::recon {

struct ClosestPoint {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();    // on the mesh, metres
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // the triangle's face normal (unit)
  double distance_m = 0;
  int triangle = -1;
};

// Closest point to `p` on the triangle (a, b, c) (Ericson, Real-Time Collision Detection 5.1.5).
Eigen::Vector3d ClosestPointOnTriangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                       const Eigen::Vector3d& b, const Eigen::Vector3d& c);

struct MeshRayHit {
  int triangle = -1;
  double t = 0;           // origin + t·direction is the hit (direction as given, not normalised)
  double b1 = 0, b2 = 0;  // barycentrics of the triangle's vertices 1 and 2
};

// An acceleration structure over a mesh's triangles. Queries are thread-safe. The mesh must
// outlive the object.
class MeshClosestPoint {
 public:
  explicit MeshClosestPoint(const TriangleMesh& mesh);
  ~MeshClosestPoint();
  MeshClosestPoint(const MeshClosestPoint&) = delete;
  MeshClosestPoint& operator=(const MeshClosestPoint&) = delete;

  // The closest mesh point within `max_distance_m` of `p` (nullopt when none is).
  std::optional<ClosestPoint> Query(const Eigen::Vector3d& p, double max_distance_m = 1e30) const;

  // The first triangle (either side) along origin + t·direction with t_min < t < t_max (nullopt
  // when none is).
  std::optional<MeshRayHit> Intersect(const Eigen::Vector3d& origin,
                                      const Eigen::Vector3d& direction, double t_min = 0,
                                      double t_max = 1e30) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace igi::recon
