#include "solver/sampling.h"

#include <algorithm>
#include <cmath>

namespace igi {
namespace {

double SafeSqrt(double v) { return std::sqrt(std::max(0.0, v)); }

// Unit direction around +z with 1 - cosθ = one_minus_cos and azimuth 2π u.
Eigen::Vector3d DirectionFromOneMinusCos(double one_minus_cos, double u) {
  const double cos_theta = 1.0 - one_minus_cos;
  const double sin_theta = SafeSqrt(one_minus_cos * (2.0 - one_minus_cos));
  const double phi = 2.0 * kPi * u;
  return {sin_theta * std::cos(phi), sin_theta * std::sin(phi), cos_theta};
}

}  // namespace

Frame Frame::FromNormal(const Eigen::Vector3d& n) {
  const double sign = std::copysign(1.0, n.z());
  const double a = -1.0 / (sign + n.z());
  const double bxy = n.x() * n.y() * a;
  Frame frame;
  frame.n = n;
  frame.t = Eigen::Vector3d(1.0 + sign * n.x() * n.x() * a, sign * bxy, -sign * n.x());
  frame.b = n.cross(frame.t);
  return frame;
}

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

Eigen::Vector2d SampleUniformDiskConcentric(const Eigen::Vector2d& u) {
  const double x = 2.0 * u.x() - 1.0;
  const double y = 2.0 * u.y() - 1.0;
  if (x == 0.0 && y == 0.0) return Eigen::Vector2d::Zero();
  double r;
  double phi;
  if (std::abs(x) > std::abs(y)) {
    r = x;
    phi = 0.25 * kPi * (y / x);
  } else {
    r = y;
    phi = 0.5 * kPi - 0.25 * kPi * (x / y);
  }
  return {r * std::cos(phi), r * std::sin(phi)};
}

Eigen::Vector3d SampleCosineHemisphere(const Eigen::Vector2d& u) {
  const Eigen::Vector2d d = SampleUniformDiskConcentric(u);
  return {d.x(), d.y(), SafeSqrt(1.0 - d.squaredNorm())};
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

SphereSample SampleSphereFromPoint(const Eigen::Vector3d& point, const Eigen::Vector3d& center,
                                   double radius, const Eigen::Vector2d& u) {
  const Eigen::Vector3d to_center = center - point;
  const double dist2 = to_center.squaredNorm();
  const double radius2 = radius * radius;
  SphereSample sample;
  if (dist2 <= radius2) {
    sample.direction = SampleUniformSphere(u);
    const double along = sample.direction.dot(to_center);
    const double perp2 = (to_center - along * sample.direction).squaredNorm();
    sample.distance = along + SafeSqrt(radius2 - perp2);
    sample.pdf = UniformSpherePdf();
    return sample;
  }
  // Cone of half-angle θmax with sin²θmax = r²/d²; 1 - cosθmax = sin²/(1 + cos) keeps precision
  // for small or distant spheres.
  const double sin2_max = radius2 / dist2;
  const double cos_max = SafeSqrt(1.0 - sin2_max);
  const double one_minus_cos_max = sin2_max / (1.0 + cos_max);
  const Eigen::Vector3d local = DirectionFromOneMinusCos(u.x() * one_minus_cos_max, u.y());
  const Frame frame = Frame::FromNormal(to_center / std::sqrt(dist2));
  sample.direction = frame.ToWorld(local);  // unit: an orthonormal frame and a unit local
  const double along = sample.direction.dot(to_center);
  const double perp2 = (to_center - along * sample.direction).squaredNorm();
  sample.distance = std::max(0.0, along - SafeSqrt(radius2 - perp2));
  sample.pdf = 1.0 / (2.0 * kPi * one_minus_cos_max);
  return sample;
}

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

}  // namespace igi
