#include "solver/synth/synth_mesh.h"

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <sstream>

namespace igi::synth {

int SynthMesh::FindRegion(const std::string& name) const {
  for (size_t i = 0; i < region_names.size(); ++i) {
    if (region_names[i] == name) return int(i);
  }
  return -1;
}

int SynthMesh::RegionIndex(const std::string& name) {
  if (const int found = FindRegion(name); found >= 0) return found;
  region_names.push_back(name);
  return int(region_names.size()) - 1;
}

void SynthMesh::AddQuad(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1,
                        const Eigen::Vector3d& p2, const Eigen::Vector3d& p3,
                        const std::string& region, const std::array<Eigen::Vector2d, 4>& uv) {
  const int region_index = RegionIndex(region);
  const Eigen::Vector3d n = (p1 - p0).cross(p2 - p0).normalized();
  const int base = int(positions.size());
  const Eigen::Vector3d corners[4] = {p0, p1, p2, p3};
  for (int i = 0; i < 4; ++i) {
    positions.push_back(corners[i]);
    normals.push_back(n);
    uvs.push_back(uv[i]);
  }
  triangles.emplace_back(base, base + 1, base + 2);
  triangles.emplace_back(base, base + 2, base + 3);
  triangle_region.push_back(region_index);
  triangle_region.push_back(region_index);
}

void SynthMesh::AddBox(const Eigen::Vector2d& center_xy, double base_z, const Eigen::Vector3d& size,
                       double yaw_deg, const std::string& region) {
  const double yaw = yaw_deg * std::numbers::pi / 180.0;
  const Eigen::Matrix3d rot = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Vector3d c(center_xy.x(), center_xy.y(), base_z + 0.5 * size.z());
  auto corner = [&](int sx, int sy, int sz) {
    return Eigen::Vector3d(
        c + rot * Eigen::Vector3d(0.5 * sx * size.x(), 0.5 * sy * size.y(), 0.5 * sz * size.z()));
  };
  const std::array<Eigen::Vector2d, 4> uv = {Eigen::Vector2d(0, 0), Eigen::Vector2d(1, 0),
                                             Eigen::Vector2d(1, 1), Eigen::Vector2d(0, 1)};
  // Each face counter-clockwise seen from outside.
  AddQuad(corner(-1, -1, 1), corner(1, -1, 1), corner(1, 1, 1), corner(-1, 1, 1), region, uv);
  AddQuad(corner(-1, -1, -1), corner(-1, 1, -1), corner(1, 1, -1), corner(1, -1, -1), region, uv);
  AddQuad(corner(-1, -1, -1), corner(1, -1, -1), corner(1, -1, 1), corner(-1, -1, 1), region, uv);
  AddQuad(corner(1, 1, -1), corner(-1, 1, -1), corner(-1, 1, 1), corner(1, 1, 1), region, uv);
  AddQuad(corner(1, -1, -1), corner(1, 1, -1), corner(1, 1, 1), corner(1, -1, 1), region, uv);
  AddQuad(corner(-1, 1, -1), corner(-1, -1, -1), corner(-1, -1, 1), corner(-1, 1, 1), region, uv);
}

void SynthMesh::AddSphere(const Eigen::Vector3d& center, double radius, int rings, int segments,
                          const std::string& region) {
  const int region_index = RegionIndex(region);
  const int base = int(positions.size());
  for (int i = 0; i <= rings; ++i) {
    const double theta = std::numbers::pi * i / rings;
    for (int j = 0; j <= segments; ++j) {
      const double phi = 2 * std::numbers::pi * j / segments;
      const Eigen::Vector3d n(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                              std::cos(theta));
      positions.push_back(center + radius * n);
      normals.push_back(n);
      uvs.emplace_back(double(j) / segments, 1.0 - double(i) / rings);
    }
  }
  auto index = [&](int i, int j) { return base + i * (segments + 1) + j; };
  for (int i = 0; i < rings; ++i) {
    for (int j = 0; j < segments; ++j) {
      const int a = index(i, j), b = index(i + 1, j), c = index(i + 1, j + 1), d = index(i, j + 1);
      // Outward: seen from outside, (a, b, c) runs counter-clockwise (theta grows downward).
      if (i != 0) {
        triangles.emplace_back(a, b, d);
        triangle_region.push_back(region_index);
      }
      if (i != rings - 1) {
        triangles.emplace_back(d, b, c);
        triangle_region.push_back(region_index);
      }
    }
  }
}

Eigen::Vector3d SynthMesh::FaceNormal(int triangle) const {
  const Eigen::Vector3i& t = triangles[triangle];
  return (positions[t[1]] - positions[t[0]]).cross(positions[t[2]] - positions[t[0]]).normalized();
}

double SynthMesh::TriangleArea(int triangle) const {
  const Eigen::Vector3i& t = triangles[triangle];
  return 0.5 * (positions[t[1]] - positions[t[0]]).cross(positions[t[2]] - positions[t[0]]).norm();
}

std::string SynthMesh::ToObj(const std::string& header) const {
  std::ostringstream os;
  os.precision(9);
  os << "# " << header << "\n";
  for (const auto& p : positions) os << "v " << p.x() << ' ' << p.y() << ' ' << p.z() << '\n';
  for (const auto& t : uvs) os << "vt " << t.x() << ' ' << t.y() << '\n';
  for (const auto& n : normals) os << "vn " << n.x() << ' ' << n.y() << ' ' << n.z() << '\n';
  int current = -1;
  for (size_t i = 0; i < triangles.size(); ++i) {
    if (triangle_region[i] != current) {
      current = triangle_region[i];
      os << "usemtl " << region_names[current] << '\n';
    }
    os << 'f';
    for (int k = 0; k < 3; ++k) {
      const int v = triangles[i][k] + 1;
      os << ' ' << v << '/' << v << '/' << v;
    }
    os << '\n';
  }
  return os.str();
}

std::optional<MeshHit> IntersectRay(const SynthMesh& mesh, const Eigen::Vector3d& origin,
                                    const Eigen::Vector3d& direction, double t_min, double t_max) {
  std::optional<MeshHit> best;
  double nearest = t_max;
  for (size_t i = 0; i < mesh.triangles.size(); ++i) {
    // Möller–Trumbore.
    const Eigen::Vector3i& t = mesh.triangles[i];
    const Eigen::Vector3d& p0 = mesh.positions[t[0]];
    const Eigen::Vector3d e1 = mesh.positions[t[1]] - p0;
    const Eigen::Vector3d e2 = mesh.positions[t[2]] - p0;
    const Eigen::Vector3d pv = direction.cross(e2);
    const double det = e1.dot(pv);
    if (std::abs(det) < 1e-14) continue;
    const double inv = 1.0 / det;
    const Eigen::Vector3d tv = origin - p0;
    const double u = tv.dot(pv) * inv;
    if (u < 0 || u > 1) continue;
    const Eigen::Vector3d qv = tv.cross(e1);
    const double v = direction.dot(qv) * inv;
    if (v < 0 || u + v > 1) continue;
    const double dist = e2.dot(qv) * inv;
    if (dist > t_min && dist < nearest) {
      nearest = dist;
      best = MeshHit{dist, int(i)};
    }
  }
  return best;
}

bool SegmentVisible(const SynthMesh& mesh, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                    double epsilon) {
  const Eigen::Vector3d d = b - a;
  const double length = d.norm();
  if (length <= 2 * epsilon) return true;
  return !IntersectRay(mesh, a, d / length, epsilon, length - epsilon).has_value();
}

}  // namespace igi::synth
