#pragma once
// The reflectance models of docs/scene-format.md and their importance sampling.
//
// Frame and directions: every direction is a unit vector in the LOCAL shading frame of a Frame
// (solver/render/sampling.h): x along the tangent t, y along b = n × t, z along the normal n. Build
// the frame with Frame::FromNormalTangent(n, tangent) for the anisotropic models (the tangent is
// the material's "tangent", the x direction of alpha_x) and Frame::FromNormal(n) otherwise. wo
// points from the surface toward the viewer (v in the contract), wi toward the light (l); both
// leave the surface. The BRDFs are one-sided: f = 0 unless wo.z > 0 and wi.z > 0 (a renderer
// shading a two-sided surface flips the frame to wo's side first). All models are reciprocal,
// f(wo, wi) = f(wi, wo). Values are per steradian, RGB.
//
// With h = wi + wo (NOT normalised), tan²θh cos²φh = (h.x/h.z)², tan²θh sin²φh = (h.y/h.z)²:
//   lambert         f = ρd/π
//   ward            f = ρd/π + ρs exp(-tan²θh/α²) / (4π α² √(cosθi cosθo))
//   ward_gmd        f = ρd/π + ρs (h·h) exp(-tan²θh/α²) / (π α² h.z⁴)
//   ward_aniso      f = ρd/π + ρs exp(-((h.x/αx)² + (h.y/αy)²)/h.z²) / (4π αx αy √(cosθi cosθo))
//   ward_gmd_aniso  f = ρd/π + ρs (h·h) exp(-((h.x/αx)² + (h.y/αy)²)/h.z²) / (π αx αy h.z⁴)
// i.e. f = ρd/π + ρs·S(wo, wi) with the colourless specular factor S of SpecularFactor().
//
// The microfacet models ggx, beckmann, ggx_aniso and beckmann_aniso (solver/render/microfacet.h)
// have S = D·G2/(4 cosθo cosθi) and Schlick's Fresnel factor with F0 = ρs:
//   f = ρd/π + S·(ρs·(1 − m) + m),   m = (1 − wo·ĥ)⁵,
// affine in ρs. SpecularWeights() gives every model's lobe as ρs·scale + offset.
//
// The Fresnel-weighted models ward_fresnel, ward_gmd_fresnel, ward_aniso_fresnel and
// ward_gmd_aniso_fresnel (igi's additions) multiply the specular term of the model without the
// suffix by Schlick's Fresnel factor divided by its value at normal incidence:
//   f = ρd/π + ρs·S(wo, wi)·W(c),   W(c) = F(c)/F0 = 1 + (1/F0 − 1)(1 − c)⁵,
//   F0 = ((η − 1)/(η + 1))² with η the material's "ior" (default 1.5: F0 = 0.04),
//   c = ĥ·wi = ĥ·wo = |wi + wo|/2 (ĥ the normalised half vector).
// So ρs is the specular reflectance at normal incidence on the microfacet (c = 1, i.e. wi = wo,
// which includes the mirror configuration at the normal): there f equals the plain model's, and
// W rises toward 1/F0 (25 for η = 1.5) as wi and wo approach opposite grazing directions. As
// η → ∞ (F0 → 1) W → 1 and the model becomes the plain one. W is symmetric in wi and wo, so the
// models stay reciprocal. The diffuse term is not weighted.
//
// The diffuse term ρd/π is Lambert's unless the material's "diffuse" is oren_nayar: then it is
// Oren and Nayar's rough diffuse surface (their qualitative model, 1994) of slope deviation σ,
//   ρd/π·(A + B·max(0, cos(φi − φo))·sin(max(θi, θo))·tan(min(θi, θo))),
//   A = 1 − σ²/(2(σ² + 0.33)),  B = 0.45σ²/(σ² + 0.09),
// in vector form ρd/π·(A + B·max(0, wi.x wo.x + wi.y wo.y)/max(cosθi, cosθo)) (DiffuseFactor);
// σ = 0 is Lambert's. When "diffuse" is coated it is a Lambertian base under a smooth clear coat:
// light reaches the base and leaves it through the coat's surface, each time losing Schlick's
// reflectance F(θ) = F0 + (1 − F0)(1 − cosθ)⁵, so the term is ρd/π·(1 − F(θi))(1 − F(θo)) =
//   ρd/π·(1 − F0)²·T(cosθi)·T(cosθo),  T(c) = 1 − (1 − c)⁵,
// with (1 − F0)² folded into ρd (ρd is the albedo at normal light and view): the shape has no
// parameter, 1 at normal incidence and 0 at grazing, so the coated base darkens toward the
// terminator and the silhouette, where Lambert's stays flat. Both are symmetric in wi and wo and
// sampled cosine-weighted as Lambert's.
//
// Sampling picks the diffuse lobe (cosine-weighted) or the specular lobe with probabilities from
// the lobes' mean RGB albedos (SpecularLobeProbability). Ward's lobes and Beckmann's draw the half
// vector's slopes (h.x/h.z, h.y/h.z) from a Gaussian with deviations αx/√2, αy/√2 (Ward's
// half-vector sampling, which is Beckmann's D·cosθh); GGX draws the visible normals (Heitz 2018);
// wi is wo mirrored about ĥ. The *_fresnel models sample exactly as their plain models do.
// BrdfPdf() is the exact combined density of that procedure over the whole sphere of wi, so it
// serves MIS directly.
//
// EvalBrdf/SpecularFactor are templates so Ceres Jets flow through the parameters (and the
// directions); their branches compare values only, which Jets support.

#include <Eigen/Core>
#include <cmath>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "recon/brdf_model.h"
#include "solver/render/microfacet.h"
#include "solver/render/sampling.h"

namespace igi::render {

// The `"brdf"` names of docs/scene-format.md that are reflectance models ("emitter" and "black" are
// not: the renderer handles them).
// BrdfModel, IsAnisotropic, IsGmd, HasSpecularLobe: recon/brdf_model.h. Only the reflective
// models (IsReflective) are evaluated here.

// One material's parameters, named as its scene.json keys. Isotropic models read `alpha` and
// ignore alpha_x/alpha_y; anisotropic models read alpha_x (along t) and alpha_y (along b) and
// ignore `alpha`; lambert reads rho_d only. Roughnesses are dimensionless (RMS slope), > 0.
template <typename T>
struct BrdfParamsT {
  recon::BrdfModel model = recon::BrdfModel::kLambert;
  Eigen::Matrix<T, 3, 1> rho_d = Eigen::Matrix<T, 3, 1>::Zero();  // diffuse albedo, RGB
  Eigen::Matrix<T, 3, 1> rho_s = Eigen::Matrix<T, 3, 1>::Zero();  // specular reflectance, RGB
  T alpha = T(0.1);
  T alpha_x = T(0.1);
  T alpha_y = T(0.1);
  T ior = T(1.5);  // index of refraction, read by the *_fresnel models only; > 1
  recon::DiffuseShape diffuse = recon::DiffuseShape::kLambert;
  T sigma = T(0.0);  // Oren–Nayar's slope deviation (radians), read with diffuse kOrenNayar

  // The roughness along t and along b that the model uses.
  T AlphaX() const { return recon::IsAnisotropic(model) ? alpha_x : alpha; }
  T AlphaY() const { return recon::IsAnisotropic(model) ? alpha_y : alpha; }
};
using BrdfParams = BrdfParamsT<double>;

// A value the model reads that breaks a rule: key as in scene.json ("rho_d[1]", "alpha_x").
struct BrdfParamProblem {
  std::string key;
  double value = 0.0;
  std::string rule;
};
// Every problem of `params` (ρ finite and >= 0; the α the model reads finite and > 0; for the
// *_fresnel models ior finite and > 1); empty if none. The caller turns them into InputErrors
// naming its file and material.
std::vector<BrdfParamProblem> CheckBrdfParams(const BrdfParams& params);

// S(wo, wi) of the header comment for a model with specular lobe; 0 for lambert or when wo or
// wi is at or below the surface. Isotropic models take alpha_x = alpha_y = alpha. For a
// *_fresnel model it is S of the plain model (without the Fresnel weight W); for a microfacet
// model D·G2/(4 cosθo cosθi), without its Fresnel factor.
template <typename T>
T SpecularFactor(recon::BrdfModel model, const T& alpha_x, const T& alpha_y,
                 const Eigen::Matrix<T, 3, 1>& wo, const Eigen::Matrix<T, 3, 1>& wi) {
  using std::exp;
  using std::sqrt;
  if (!recon::HasSpecularLobe(model) || !(wo.z() > 0.0) || !(wi.z() > 0.0)) return T(0.0);
  if (recon::IsMicrofacet(model))
    return microfacet::Factor<T>(recon::Lobe(model), alpha_x, alpha_y, wo, wi);
  const Eigen::Matrix<T, 3, 1> h = wo + wi;
  const T hz2 = h.z() * h.z();
  const T slope_x = h.x() / alpha_x;
  const T slope_y = h.y() / alpha_y;
  const T lobe = exp(-(slope_x * slope_x + slope_y * slope_y) / hz2);
  if (recon::IsGmd(model)) return h.squaredNorm() * lobe / (T(kPi) * alpha_x * alpha_y * hz2 * hz2);
  return lobe / (T(4.0 * kPi) * alpha_x * alpha_y * sqrt(wo.z() * wi.z()));
}

// SpecularFactor of Ward's lobes split into the parts that do not depend on the roughness, for
// searches over α: S = g·exp(−(q_x/α_x² + q_y/α_y²))/(α_x·α_y). False (parts unset) when the model
// has no Ward lobe or S is 0 at every α (wo or wi at or below the surface).
inline bool SpecularFactorParts(recon::BrdfModel model, const Eigen::Vector3d& wo,
                                const Eigen::Vector3d& wi, double* q_x, double* q_y, double* g) {
  if (!recon::IsWardLobe(model) || !(wo.z() > 0.0) || !(wi.z() > 0.0)) return false;
  const Eigen::Vector3d h = wo + wi;
  const double hz2 = h.z() * h.z();
  *q_x = h.x() * h.x() / hz2;
  *q_y = h.y() * h.y() / hz2;
  *g = recon::IsGmd(model) ? h.squaredNorm() / (kPi * hz2 * hz2)
                           : 1.0 / (4.0 * kPi * std::sqrt(wo.z() * wi.z()));
  return true;
}

// W(c) of the header comment: Schlick's Fresnel factor over its normal-incidence value, with
// F0 = ((ior − 1)/(ior + 1))² and c = |wo + wi|/2 = ĥ·wi.
template <typename T>
T FresnelWeight(const T& ior, const Eigen::Matrix<T, 3, 1>& wo, const Eigen::Matrix<T, 3, 1>& wi) {
  using std::sqrt;
  const T r = (ior - T(1.0)) / (ior + T(1.0));
  const T f0 = r * r;
  const T c = T(0.5) * sqrt((wo + wi).squaredNorm());
  const T m = T(1.0) - c;
  const T m2 = m * m;
  return T(1.0) + (T(1.0) / f0 - T(1.0)) * (m2 * m2 * m);
}

// A lobe's value per unit ρs and its part that ρs does not scale: the lobe is ρs_c·scale + offset
// in each channel c. scale = S·W for Ward's models (W = 1 without Fresnel weight, offset 0);
// S·(1 − m) and S·m for the microfacet models (Schlick's F = ρs + (1 − ρs)·m).
template <typename T>
struct LobeWeightsT {
  T scale = T(0.0);
  T offset = T(0.0);
};
using LobeWeights = LobeWeightsT<double>;

// The lobe of `model` at (αx, αy) for wo, wi (local); zero when it has none or wo or wi is at or
// below the surface. `ior` is read by the *_fresnel models only.
template <typename T>
LobeWeightsT<T> SpecularWeights(recon::BrdfModel model, const T& alpha_x, const T& alpha_y,
                                const T& ior, const Eigen::Matrix<T, 3, 1>& wo,
                                const Eigen::Matrix<T, 3, 1>& wi) {
  LobeWeightsT<T> w;
  const T s = SpecularFactor<T>(model, alpha_x, alpha_y, wo, wi);
  if (!(s > 0.0)) return w;
  switch (recon::Info(model).fresnel) {
    case recon::LobeFresnel::kNone:
      w.scale = s;
      break;
    case recon::LobeFresnel::kIorWeight:
      w.scale = s * FresnelWeight<T>(ior, wo, wi);
      break;
    case recon::LobeFresnel::kRhoS: {
      const T m = microfacet::SchlickWeight<T>(wo, wi);
      w.scale = s * (T(1.0) - m);
      w.offset = s * m;
      break;
    }
  }
  return w;
}

// Oren–Nayar's A and B of σ (the header comment).
template <typename T>
T OrenNayarA(const T& sigma) {
  const T s2 = sigma * sigma;
  return T(1.0) - T(0.5) * s2 / (s2 + T(0.33));
}
template <typename T>
T OrenNayarB(const T& sigma) {
  const T s2 = sigma * sigma;
  return T(0.45) * s2 / (s2 + T(0.09));
}
// The geometric part of Oren–Nayar's B term, max(0, cos(φi − φo))·sin(max θ)·tan(min θ) =
// max(0, wi.x wo.x + wi.y wo.y)/max(cosθi, cosθo); wo and wi above the surface.
template <typename T>
T OrenNayarG(const Eigen::Matrix<T, 3, 1>& wo, const Eigen::Matrix<T, 3, 1>& wi) {
  const T dot = wi.x() * wo.x() + wi.y() * wo.y();
  if (!(dot > 0.0)) return T(0.0);
  return dot / (wi.z() > wo.z() ? wi.z() : wo.z());
}
// T's mean over the cosine-weighted hemisphere, 1 − 2∫(1 − c)⁵c dc: light arriving alike from
// every direction crosses the coat with this share on average.
inline constexpr double kMeanCoatTransmission = 20.0 / 21.0;
// The clear coat's transmission shape T(c) = 1 − (1 − c)⁵ at a cosine c in [0, 1].
template <typename T>
T CoatTransmission(const T& c) {
  const T m = T(1.0) - c;
  const T m2 = m * m;
  return T(1.0) - m2 * m2 * m;
}
// The diffuse term over ρd/π: 1 for Lambert's, A + B·OrenNayarG for Oren–Nayar's,
// T(cosθi)·T(cosθo) for the coated base's; wo and wi above the surface.
template <typename T>
T DiffuseFactor(const BrdfParamsT<T>& params, const Eigen::Matrix<T, 3, 1>& wo,
                const Eigen::Matrix<T, 3, 1>& wi) {
  switch (params.diffuse) {
    case recon::DiffuseShape::kOrenNayar:
      return OrenNayarA(params.sigma) + OrenNayarB(params.sigma) * OrenNayarG<T>(wo, wi);
    case recon::DiffuseShape::kCoated:
      return CoatTransmission<T>(wo.z()) * CoatTransmission<T>(wi.z());
    case recon::DiffuseShape::kLambert:
      break;
  }
  return T(1.0);
}
inline double DiffuseFactor(const BrdfParams& params, const Eigen::Vector3d& wo,
                            const Eigen::Vector3d& wi) {
  return DiffuseFactor<double>(params, wo, wi);
}

// The mean of OrenNayarG(wo, wi) over cosine-weighted wi for a view at cosθo = `cos_o` (by the
// term's symmetry, also its mean over cosine-weighted wo for a light at that angle): light
// arriving alike from every direction of the hemisphere reflects ρd·E·(A + B·OrenNayarMeanG)/π
// toward the view. 0 at normal viewing, 0.30 at 60°.
double OrenNayarMeanG(double cos_o);

// DiffuseFactor's mean over cosine-weighted light and view: light that arrives alike from the
// whole hemisphere leaves toward a view drawn alike (another surface's, on average) with radiance
// ρd·E·DiffuseMeanFactor/π. 1 for Lambert's, A + B·(OrenNayarMeanG's mean) for Oren–Nayar's,
// (20/21)² for the coated base's.
double DiffuseMeanFactor(const BrdfParams& params);

// f(wo, wi), RGB per steradian; zero when wo or wi is at or below the surface.
template <typename T>
Eigen::Matrix<T, 3, 1> EvalBrdf(const BrdfParamsT<T>& params, const Eigen::Matrix<T, 3, 1>& wo,
                                const Eigen::Matrix<T, 3, 1>& wi) {
  if (!(wo.z() > 0.0) || !(wi.z() > 0.0)) return Eigen::Matrix<T, 3, 1>::Zero();
  Eigen::Matrix<T, 3, 1> f = params.rho_d * (T(kInvPi) * DiffuseFactor<T>(params, wo, wi));
  if (recon::HasSpecularLobe(params.model)) {
    const LobeWeightsT<T> w =
        SpecularWeights<T>(params.model, params.AlphaX(), params.AlphaY(), params.ior, wo, wi);
    f += params.rho_s * w.scale + Eigen::Matrix<T, 3, 1>::Constant(w.offset);
  }
  return f;
}

// The double case, callable with Eigen expressions (the renderer's path).
inline Eigen::Vector3d EvalBrdf(const BrdfParams& params, const Eigen::Vector3d& wo,
                                const Eigen::Vector3d& wi) {
  return EvalBrdf<double>(params, wo, wi);
}

// ---------------------------------------------------------------------------------------------
// Importance sampling (double only).

enum class BrdfLobe { kNone, kDiffuse, kSpecular };

struct BrdfSample {
  Eigen::Vector3d wi = Eigen::Vector3d::UnitZ();     // local, unit
  Eigen::Vector3d f = Eigen::Vector3d::Zero();       // EvalBrdf(params, wo, wi)
  Eigen::Vector3d weight = Eigen::Vector3d::Zero();  // f·cosθi/pdf; zero unless Valid()
  double pdf = 0.0;                                  // BrdfPdf(params, wo, wi), per steradian
  BrdfLobe lobe = BrdfLobe::kNone;                   // the lobe that drew wi

  // False when the draw failed (pdf 0) or wi went below the surface (f 0): end the path.
  bool Valid() const { return pdf > 0.0 && wi.z() > 0.0; }
};

// Probability of drawing from the specular lobe given wo (local): s/(mean(ρd) + s) with s the
// lobe's mean reflectance estimate, mean(ρs) for Ward's lobes and Schlick's mean(ρs + (1 − ρs)·
// (1 − cosθo)⁵) for the microfacet ones; 0 for lambert and for an all-black material.
double SpecularLobeProbability(const BrdfParams& params, const Eigen::Vector3d& wo);

// EvalBrdf and BrdfPdf in one call (shares the half vector): what light sampling with MIS needs.
struct BrdfEval {
  Eigen::Vector3d f = Eigen::Vector3d::Zero();
  double pdf = 0.0;
};

namespace brdf_internal {
// SampleBrdf and EvalBrdfAndPdf of the models with a specular lobe (brdf.cpp).
BrdfSample SampleGlossyBrdf(const BrdfParams& params, const Eigen::Vector3d& wo, double u_lobe,
                            const Eigen::Vector2d& u);
BrdfEval EvalGlossyBrdfAndPdf(const BrdfParams& params, const Eigen::Vector3d& wo,
                              const Eigen::Vector3d& wi);
}  // namespace brdf_internal

// Draws wi for `wo` (local, unit) from three uniform numbers in [0,1): u_lobe picks the lobe, u
// the direction. wo at or below the surface gives an invalid sample. Lambert ignores u_lobe.
inline BrdfSample SampleBrdf(const BrdfParams& params, const Eigen::Vector3d& wo, double u_lobe,
                             const Eigen::Vector2d& u) {
  if (recon::HasSpecularLobe(params.model))
    return brdf_internal::SampleGlossyBrdf(params, wo, u_lobe, u);
  BrdfSample sample;  // no lobe: f = ρd/π·F, pdf = cosθ/π, weight = ρd·F exactly
  if (!(wo.z() > 0.0)) return sample;
  sample.lobe = BrdfLobe::kDiffuse;
  sample.wi = SampleCosineHemisphere(u);
  const double factor = sample.wi.z() > 0.0 ? DiffuseFactor(params, wo, sample.wi) : 0.0;
  sample.f = params.rho_d * (kInvPi * factor);
  sample.pdf = CosineHemispherePdf(sample.wi.z());
  if (sample.Valid()) sample.weight = params.rho_d * factor;
  return sample;
}

// The density (per steradian, over the whole sphere) with which SampleBrdf draws wi given wo.
// Below the surface it is the true density of the draws that land there (their f is 0), so over
// the sphere it integrates to 1 minus the probability of a failed draw; 0 when wo.z <= 0.
double BrdfPdf(const BrdfParams& params, const Eigen::Vector3d& wo, const Eigen::Vector3d& wi);

// EvalBrdf and BrdfPdf together (BrdfEval above).
inline BrdfEval EvalBrdfAndPdf(const BrdfParams& params, const Eigen::Vector3d& wo,
                               const Eigen::Vector3d& wi) {
  if (recon::HasSpecularLobe(params.model))
    return brdf_internal::EvalGlossyBrdfAndPdf(params, wo, wi);
  BrdfEval out;  // no lobe: no lobe choice, no half vector
  if (!(wo.z() > 0.0)) return out;
  if (wi.z() > 0.0) out.f = params.rho_d * (kInvPi * DiffuseFactor(params, wo, wi));
  out.pdf = CosineHemispherePdf(wi.z());
  return out;
}

}  // namespace igi::render
