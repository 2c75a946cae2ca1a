#pragma once
// Small geometry types shared by every module. Poses are named by the frames they map between,
// COLMAP-style: `cam_from_world` maps world points into the camera frame
// (X_cam = rotation * X_world + translation).

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace igi {

struct Rigid3d {
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  Rigid3d() = default;
  Rigid3d(const Eigen::Quaterniond& r, const Eigen::Vector3d& t) : rotation(r), translation(t) {}

  Eigen::Vector3d operator*(const Eigen::Vector3d& x) const { return rotation * x + translation; }
  Rigid3d Inverse() const {
    const Eigen::Quaterniond inv = rotation.conjugate();
    return {inv, -(inv * translation)};
  }
  Eigen::Matrix<double, 3, 4> ToMatrix() const {
    Eigen::Matrix<double, 3, 4> m;
    m.leftCols<3>() = rotation.toRotationMatrix();
    m.col(3) = translation;
    return m;
  }
};

// COLMAP's qvec order [w, x, y, z] <-> Eigen quaternion.
inline Eigen::Quaterniond QuaternionFromQvec(const Eigen::Vector4d& qvec) {
  return Eigen::Quaterniond(qvec[0], qvec[1], qvec[2], qvec[3]);
}
inline Eigen::Vector4d QvecFromQuaternion(const Eigen::Quaterniond& q) {
  return Eigen::Vector4d(q.w(), q.x(), q.y(), q.z());
}

}  // namespace igi

namespace igi {

// A right-handed orthonormal frame whose third column is `axis` (unit). The first column is a
// fixed function of the axis: world x projected off the axis, or world y when the axis is
// (nearly) parallel to world x. Used as the azimuth reference of spot profiles.
inline Eigen::Matrix3d FrameFromAxis(const Eigen::Vector3d& axis) {
  const Eigen::Vector3d z = axis.normalized();
  const Eigen::Vector3d ref =
      std::abs(z.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  const Eigen::Vector3d x = (ref - z * z.dot(ref)).normalized();
  Eigen::Matrix3d frame;
  frame.col(0) = x;
  frame.col(1) = z.cross(x);
  frame.col(2) = z;
  return frame;
}

}  // namespace igi
