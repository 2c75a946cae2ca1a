#include "solver/render/microfacet.h"

#include <algorithm>
#include <cmath>

namespace igi::render::microfacet {

Eigen::Vector3d SampleHalfVector(recon::LobeShape shape, double alpha_x, double alpha_y,
                                 const Eigen::Vector3d& wo, const Eigen::Vector2d& u) {
  double sin_phi, cos_phi;
  SinCos2Pi(u.y(), &sin_phi, &cos_phi);
  if (shape == recon::LobeShape::kGgx) {
    // Visible normals: wo in the frame where the roughness is 1 (the ellipsoid of microfacets
    // stretched to a hemisphere), a point of the unit disk projected onto the hemisphere seen
    // from there, and back.
    const Eigen::Vector3d v =
        Eigen::Vector3d(alpha_x * wo.x(), alpha_y * wo.y(), wo.z()).normalized();
    const double len2 = v.x() * v.x() + v.y() * v.y();
    const Eigen::Vector3d t1 =
        len2 > 0.0 ? Eigen::Vector3d(Eigen::Vector3d(-v.y(), v.x(), 0.0) / std::sqrt(len2))
                   : Eigen::Vector3d(Eigen::Vector3d::UnitX());
    const Eigen::Vector3d t2 = v.cross(t1);
    const double r = std::sqrt(u.x());
    const double p1 = r * cos_phi;
    const double blend = 0.5 * (1.0 + v.z());
    const double p2 = (1.0 - blend) * std::sqrt(std::max(0.0, 1.0 - p1 * p1)) + blend * r * sin_phi;
    const Eigen::Vector3d n =
        p1 * t1 + p2 * t2 + std::sqrt(std::max(0.0, 1.0 - p1 * p1 - p2 * p2)) * v;
    return Eigen::Vector3d(alpha_x * n.x(), alpha_y * n.y(), std::max(0.0, n.z())).normalized();
  }
  // Beckmann's D·cosθh: the slopes (h.x/h.z, h.y/h.z) are Gaussian with deviations αx/√2, αy/√2
  // (Box-Muller radius; 1 − u.x is in (0, 1], so the log is finite).
  const double radius = std::sqrt(-std::log(1.0 - u.x()));
  return Eigen::Vector3d(alpha_x * radius * cos_phi, alpha_y * radius * sin_phi, 1.0).normalized();
}

double ReflectedPdf(recon::LobeShape shape, double alpha_x, double alpha_y,
                    const Eigen::Vector3d& wo, const Eigen::Vector3d& h) {
  if (!(h.z() > 0.0) || !(wo.z() > 0.0)) return 0.0;
  const double d = Distribution<double>(shape, alpha_x, alpha_y, h);
  // With wo·ĥ = |h|/2: GGX's G1(wo)·D·(wo·ĥ)/cosθo/(4 wo·ĥ); Beckmann's D·cosθh/(4 wo·ĥ).
  if (shape == recon::LobeShape::kGgx)
    return SmithG1<double>(shape, alpha_x, alpha_y, wo) * d / (4.0 * wo.z());
  const double norm = h.norm();
  return d * (h.z() / norm) / (2.0 * norm);
}

}  // namespace igi::render::microfacet
