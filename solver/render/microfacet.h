#pragma once
// The microfacet lobes of the ggx and beckmann models and their anisotropic forms
// (docs/scene-format.md), in the local shading frame of solver/render/brdf.h (z the normal, x the
// tangent, the direction of αx):
//
//   f = ρd/π + D(ĥ)·G2(wo, wi)·F(wo·ĥ) / (4 cosθo cosθi),   ĥ = (wo + wi)/|wo + wi|
//   Q = (ĥx/ĥz)²/αx² + (ĥy/ĥz)²/αy²   (tan²θh weighted by the roughness along φh)
//   GGX (Trowbridge–Reitz)   D = 1 / (π αx αy ĥz⁴ (1 + Q)²)
//   Beckmann                 D = exp(−Q) / (π αx αy ĥz⁴)
//   Smith's height-correlated masking-shadowing G2 = 1 / (1 + Λ(wo) + Λ(wi)), with
//   a² = (αx² wx² + αy² wy²)/wz² for a direction w:
//     GGX        Λ = (√(1 + a²) − 1)/2
//     Beckmann   Λ = (exp(−ν²)/(ν√π) − erfc(ν))/2,  ν = 1/a
//   Schlick's Fresnel factor with F0 = ρs per channel: F = ρs + (1 − ρs)·m, m = (1 − wo·ĥ)⁵.
//
// So with the colourless S = D·G2/(4 cosθo cosθi), the lobe is S·(ρs·(1 − m) + m): affine in ρs
// (LobeWeights in brdf.h). Both D are normalised (∫ D cosθh dω = 1) and G1 = 1/(1 + Λ) makes
// the visible normals' distribution a density (∫ G1(wo) D max(0, wo·ĥ)/cosθo dω = 1), the "weak
// white furnace" the tests check. f is symmetric in wo and wi (reciprocal).
//
// Templates so that Ceres Jets flow through α (and the directions); branches compare values only.

#include <Eigen/Core>
#include <cmath>

#include "recon/brdf_model.h"
#include "solver/render/sampling.h"

namespace igi::render::microfacet {

// Smith's Λ of `shape` as a function of a² = (αx² wx² + αy² wy²)/wz² (the solver's lobe table
// keeps a direction's squared tangents and forms a² at each roughness it tries).
template <typename T>
T LambdaOfA2(recon::LobeShape shape, const T& a2) {
  using std::exp;
  using std::sqrt;
  if (shape == recon::LobeShape::kGgx) return (sqrt(T(1.0) + a2) - T(1.0)) * T(0.5);
  // Beckmann: Λ is below 1e-17 once ν > 6 (a² < 1/36), and ν = 1/a is singular at the normal.
  if (!(a2 > 1.0 / 36.0)) return T(0.0);
  using std::erfc;
  const T nu = T(1.0) / sqrt(a2);
  return (exp(-nu * nu) / (nu * T(std::sqrt(kPi))) - erfc(nu)) * T(0.5);
}

// Smith's Λ(w) of `shape` for a direction w (w.z > 0) at roughness (αx, αy).
template <typename T>
T Lambda(recon::LobeShape shape, const T& alpha_x, const T& alpha_y,
         const Eigen::Matrix<T, 3, 1>& w) {
  const T ax = alpha_x * w.x(), ay = alpha_y * w.y();
  return LambdaOfA2<T>(shape, (ax * ax + ay * ay) / (w.z() * w.z()));
}

// G1(w) = 1/(1 + Λ(w)): the share of microfacets of the visible projected area that w sees.
template <typename T>
T SmithG1(recon::LobeShape shape, const T& alpha_x, const T& alpha_y,
          const Eigen::Matrix<T, 3, 1>& w) {
  return T(1.0) / (T(1.0) + Lambda<T>(shape, alpha_x, alpha_y, w));
}

// D of the unnormalised half vector h = wo + wi, per steradian of ĥ; 0 unless h.z > 0.
template <typename T>
T Distribution(recon::LobeShape shape, const T& alpha_x, const T& alpha_y,
               const Eigen::Matrix<T, 3, 1>& h) {
  using std::exp;
  if (!(h.z() > 0.0)) return T(0.0);
  const T sx = h.x() / (h.z() * alpha_x), sy = h.y() / (h.z() * alpha_y);
  const T q = sx * sx + sy * sy;
  const T h2 = h.squaredNorm(), hz2 = h.z() * h.z();
  const T cos4 = hz2 * hz2 / (h2 * h2);  // ĥz⁴
  const T base = T(kPi) * alpha_x * alpha_y * cos4;
  if (shape == recon::LobeShape::kGgx) {
    const T d = T(1.0) + q;
    return T(1.0) / (base * d * d);
  }
  return exp(-q) / base;
}

// S = D·G2/(4 cosθo cosθi) (the lobe without its Fresnel factor); 0 when wo or wi is at or below
// the surface.
template <typename T>
T Factor(recon::LobeShape shape, const T& alpha_x, const T& alpha_y,
         const Eigen::Matrix<T, 3, 1>& wo, const Eigen::Matrix<T, 3, 1>& wi) {
  if (!(wo.z() > 0.0) || !(wi.z() > 0.0)) return T(0.0);
  const Eigen::Matrix<T, 3, 1> h = wo + wi;
  const T g2 = T(1.0) / (T(1.0) + Lambda<T>(shape, alpha_x, alpha_y, wo) +
                         Lambda<T>(shape, alpha_x, alpha_y, wi));
  return Distribution<T>(shape, alpha_x, alpha_y, h) * g2 / (T(4.0) * wo.z() * wi.z());
}

// m = (1 − wo·ĥ)⁵ of Schlick's factor F = F0 + (1 − F0)·m; wo·ĥ = |wo + wi|/2.
template <typename T>
T SchlickWeight(const Eigen::Matrix<T, 3, 1>& wo, const Eigen::Matrix<T, 3, 1>& wi) {
  using std::sqrt;
  const T c = T(0.5) * sqrt((wo + wi).squaredNorm());
  const T m = T(1.0) - c;
  const T m2 = m * m;
  return m2 * m2 * m;
}

// Draws a microfacet normal ĥ (local, unit) for wo (wo.z > 0) from u in [0,1)²:
// GGX's distribution of visible normals, density G1(wo)·D(ĥ)·max(0, wo·ĥ)/cosθo (Heitz 2018);
// Beckmann's D(ĥ)·cosθh (its slopes Gaussian, as Ward's). HalfVectorPdf gives the density.
Eigen::Vector3d SampleHalfVector(recon::LobeShape shape, double alpha_x, double alpha_y,
                                 const Eigen::Vector3d& wo, const Eigen::Vector2d& u);

// The density per steradian of wi = wo mirrored about the sampled ĥ, for the unnormalised
// h = wo + wi (the Jacobian 1/(4 wo·ĥ) included); 0 when h.z <= 0.
double ReflectedPdf(recon::LobeShape shape, double alpha_x, double alpha_y,
                    const Eigen::Vector3d& wo, const Eigen::Vector3d& h);

}  // namespace igi::render::microfacet
