#pragma once
// Fits of a specular lobe (Ward's or a microfacet one: solver/render/brdf.h) by the lobes other
// renderers implement, for the exporters of solver/export/. Every fit is a weighted least-squares
// match of the specular BRDF values (ρd left out: the diffuse terms map exactly) over a grid of
// direction pairs covering the lobe: view directions θo in [0°, max_theta_o_deg] (and several
// azimuths for an anisotropic source), light directions parameterised by the half vector around the
// source's lobe (tanθh up to 8 α). The residuals are those of f·cosθi·cosθo (the BRDF in projected
// solid angle on both sides, which stays bounded at grazing angles where f itself grows like
// 1/cos²), i.e. each pair is weighted by cos²θi·cos²θo·dωi·dωo.
//
// The scale k of the target is solved in closed form for each roughness; the roughness is
// searched by golden section on log α. The error reported is the relative RMS error
//   sqrt(Σ w (f_fit − f_src)² / Σ w f_src²)   (0 = identical lobes).

#include <string_view>

#include "solver/render/brdf.h"

namespace igi::exporter {

enum class LobeTarget {
  // RADIANCE plastic/metal = contract ward_gmd: k·S_gmd(α); k is the fitted (grey) ρs.
  kWardGmd,
  // Mitsuba 3 roughplastic, distribution "beckmann": k·F(c, η)·D_beckmann(α)·G_smith / (4 cosθi
  // cosθo), F the unpolarised dielectric Fresnel of relative index η, G_smith = G1(wi)·G1(wo)
  // (Mitsuba's separable form); k = specular_reflectance.
  kBeckmannDielectric,
  // Mitsuba 3 roughplastic, distribution "ggx": as kBeckmannDielectric with GGX's D and G1.
  kGgxDielectric,
  // glTF 2.0 metallic-roughness, metallic 0: F_schlick(c, F0 = k)·D_ggx(α)·V_smith_correlated(α),
  // where glTF's roughness is √α (α = roughness²); k is the fitted normal-incidence reflectance.
  kGgxSchlick,
};
std::string_view LobeTargetName(LobeTarget target);

struct LobeFitOptions {
  // The lobe model the Ward lobe is fitted by (LobeTarget).
  LobeTarget target = LobeTarget::kWardGmd;
  // kBeckmannDielectric only: relative index of refraction of the target's Fresnel term.
  double target_ior = 1.5;
  // View elevations fitted: [0, max]. Past ~60° the models part ways for reasons no (α, k)
  // can fix (Fresnel and shadowing terms), and fitting them would spoil the lobe where most
  // highlights are seen; the error up to 88° is reported separately.
  double max_theta_o_deg = 60;
  int theta_o_steps = 16;  // view elevations
  int half_steps = 48;     // half-vector elevations and azimuths (each)
};

struct LobeFit {
  double alpha = 0;           // fitted roughness (Beckmann/GMD α, or GGX α = roughness²)
  double scale = 0;           // fitted k (see LobeTarget)
  double relative_error = 0;  // relative RMS error over the fitted domain (θo <= max)
  double relative_error_to_88deg = 0;  // the same fitted lobe compared over θo in [0, 88°]
};

// Fits the specular lobe of `source` (its ρs taken as grey: the mean of rho_s; rho_d ignored;
// the *_fresnel models include their Fresnel weight; anisotropic models are fitted by an
// isotropic lobe). `source` must have a specular lobe and pass CheckBrdfParams.
LobeFit FitSpecularLobe(const render::BrdfParams& source, const LobeFitOptions& options = {});

// The target lobes' specular BRDF values (local frame, z = normal; 0 below the surface), exposed
// for tests and reports. `scale` is k of LobeTarget.
double TargetLobeValue(LobeTarget target, double alpha, double scale, double target_ior,
                       const Eigen::Vector3d& wo, const Eigen::Vector3d& wi);

// Unpolarised Fresnel reflectance of a dielectric of relative index `eta` (> 1) at cosine `c`.
double DielectricFresnel(double c, double eta);

}  // namespace igi::exporter
