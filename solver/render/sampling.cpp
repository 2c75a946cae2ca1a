#include "solver/render/sampling.h"

#include <algorithm>
#include <cmath>

namespace igi::render {
namespace {

double SafeSqrt(double v) { return std::sqrt(std::max(0.0, v)); }

// Unit direction around +z with 1 - cosθ = one_minus_cos and azimuth 2π u.
Eigen::Vector3d DirectionFromOneMinusCos(double one_minus_cos, double u) {
  const double cos_theta = 1.0 - one_minus_cos;
  const double sin_theta = SafeSqrt(one_minus_cos * (2.0 - one_minus_cos));
  double sin_phi, cos_phi;
  SinCos2Pi(u, &sin_phi, &cos_phi);
  return {sin_theta * cos_phi, sin_theta * sin_phi, cos_theta};
}

}  // namespace

Frame Frame::FromNormalTangent(const Eigen::Vector3d& n, const Eigen::Vector3d& tangent) {
  const Eigen::Vector3d t = tangent - n * n.dot(tangent);
  const double length = t.norm();
  // Below this the tangent is parallel to n (or zero) to within rounding: no direction left.
  constexpr double kMinLength = 1e-9;
  if (!(length > kMinLength * tangent.norm()) || !(length > 0.0)) return FromNormal(n);
  Frame frame;
  frame.n = n;
  frame.t = t / length;
  frame.b = n.cross(frame.t);
  return frame;
}

Eigen::Vector3d SampleUniformHemisphere(const Eigen::Vector2d& u) {
  return DirectionFromOneMinusCos(u.x(), u.y());
}

Eigen::Vector3d SampleUniformSphere(const Eigen::Vector2d& u) {
  return DirectionFromOneMinusCos(2.0 * u.x(), u.y());
}

Eigen::Vector3d SampleUniformCone(const Eigen::Vector2d& u, double cos_theta_max) {
  return DirectionFromOneMinusCos(u.x() * (1.0 - cos_theta_max), u.y());
}

Eigen::Vector3d SampleUniformTriangle(const Eigen::Vector2d& u) {
  const double s = std::sqrt(u.x());
  const double w1 = s * (1.0 - u.y());
  const double w2 = s * u.y();
  return {1.0 - w1 - w2, w1, w2};
}

namespace sampling_internal {

SphereSample SampleSphereFromInside(const Eigen::Vector3d& point, const Eigen::Vector3d& center,
                                    double radius, const Eigen::Vector2d& u) {
  const Eigen::Vector3d to_center = center - point;
  SphereSample sample;
  sample.direction = SampleUniformSphere(u);
  const double along = sample.direction.dot(to_center);
  const double perp2 = (to_center - along * sample.direction).squaredNorm();
  sample.distance = along + SafeSqrt(radius * radius - perp2);
  sample.pdf = UniformSpherePdf();
  return sample;
}

}  // namespace sampling_internal

double SphereFromPointPdf(const Eigen::Vector3d& point, const Eigen::Vector3d& center,
                          double radius, const Eigen::Vector3d& direction) {
  const Eigen::Vector3d to_center = center - point;
  const double dist2 = to_center.squaredNorm();
  const double radius2 = radius * radius;
  if (dist2 <= radius2) return UniformSpherePdf();
  const double along = direction.dot(to_center);
  if (along <= 0.0) return 0.0;
  // Inside the cone iff the ray passes within `radius` of the centre.
  const double perp2 = (to_center - along * direction).squaredNorm();
  if (perp2 > radius2) return 0.0;
  const double sin2_max = radius2 / dist2;
  const double cos_max = SafeSqrt(1.0 - sin2_max);
  return 1.0 / (2.0 * kPi * (sin2_max / (1.0 + cos_max)));
}

}  // namespace igi::render
