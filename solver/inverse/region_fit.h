#pragma once
// Internal to igi_solver: fitting one region's reflectance to its observations (Yu et al. 1999
// §5: "fit the BRDF parameters of each region by nonlinear optimisation over the observed
// radiance samples"). Non-diffuse parameters (ρs, α) are constant per region; the diffuse albedo
// is either constant over the region or free per patch, whichever the data support.
//
// The model of one observation o (radiance L toward its camera, channel c):
//   L_c = ρd_c·E_c/π + ρs_c·T_c(α) + O_c(α),   T_c(α) = Σ_k scale(wo, wi_k; α)·v_k,c,
//   O_c(α) = Σ_k offset(wo, wi_k; α)·v_k,c
// with E the gathered irradiance and (wi_k, v_k) the incident samples (v = L_in·cosθ/pdf, so
// Σ v = E), and the lobe's scale and offset of render::SpecularWeights (solver/render/brdf.h):
// S·W and 0 for Ward's lobes (S the colourless specular factor, W the Fresnel weight), S·(1 − m)
// and S·m for the microfacet ones (Schlick's F = ρs + (1 − ρs)·m). For a given α the model is
// linear in ρd and ρs: they are projected out
// (variable projection) and α is found by a log-grid search refined by Brent's method; Ceres then
// polishes all parameters jointly (autodiff through EvalBrdf's specular factor) and gives their
// covariance. Residuals are weighted as for shot noise, 1/√((ρ̄E/π + 0.1·mean L)·mean L) per
// channel, ρ̄ the region's mean ratio of L to E/π: weights that follow neither the photos' noise nor
// that of the gathered irradiance (either would bias the fit).

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "recon/brdf_model.h"
#include "solver/render/brdf.h"

namespace igi::solver {

// One sample of the light arriving at an observation, in its local shading frame: the direction
// wi (unit) and the value v. 16 bytes: the direction as 16-bit octahedral coordinates (within
// 1e-4 rad), the value as float RGB. The incident lists are most of a refined solve's memory (at
// 24 bytes with a float direction, stage 2's lists of 300 000 observations took 4 GiB).
class IncidentLocal {
 public:
  IncidentLocal() = default;
  IncidentLocal(const Eigen::Vector3f& wi, const Eigen::Vector3f& value)
      : value_{value.x(), value.y(), value.z()} {
    // Onto the octahedron |x| + |y| + |z| = 1, the lower half folded over the upper.
    const float n = std::abs(wi.x()) + std::abs(wi.y()) + std::abs(wi.z());
    float x = n > 0 ? wi.x() / n : 0.0f, y = n > 0 ? wi.y() / n : 0.0f;
    if (wi.z() < 0) {
      const float fx = (1 - std::abs(y)) * (x >= 0 ? 1.0f : -1.0f);
      const float fy = (1 - std::abs(x)) * (y >= 0 ? 1.0f : -1.0f);
      x = fx, y = fy;
    }
    oct_[0] = Quantise(x), oct_[1] = Quantise(y);
  }
  Eigen::Vector3f Wi() const {
    float x = oct_[0] * (2.0f / 65535) - 1, y = oct_[1] * (2.0f / 65535) - 1;
    const float z = 1 - std::abs(x) - std::abs(y);
    if (z < 0) {
      const float fx = (1 - std::abs(y)) * (x >= 0 ? 1.0f : -1.0f);
      const float fy = (1 - std::abs(x)) * (y >= 0 ? 1.0f : -1.0f);
      x = fx, y = fy;
    }
    return Eigen::Vector3f(x, y, z).normalized();
  }
  Eigen::Vector3f Value() const { return {value_[0], value_[1], value_[2]}; }

 private:
  static uint16_t Quantise(float c) {
    return uint16_t(std::lround(std::clamp((c + 1) * 0.5f, 0.0f, 1.0f) * 65535));
  }
  float value_[3] = {0, 0, 0};
  uint16_t oct_[2] = {32768, 32768};  // +z
};

struct FitSample {
  Eigen::Vector3d observed = Eigen::Vector3d::Zero();     // L
  Eigen::Vector3d irradiance = Eigen::Vector3d::Zero();   // E
  Eigen::Vector3d rho_d_known = Eigen::Vector3d::Zero();  // used when the region's ρd is known
  int slot = 0;                                           // its patch among the region's slots
  // The albedo at this point seen by the other photos off their highlights (solver/
  // held_out_albedo.h), as two parts: their πL/E (rho_d_held) and the lobe they carry per unit
  // ρs, πT/E (held_lobe, at the previous iteration's α; zero when unknown): the albedo is
  // rho_d_held − ρs·held_lobe. NaN when unknown. Used by RegionFitInput::use_held_albedo.
  Eigen::Vector3d rho_d_held = Eigen::Vector3d::Constant(NAN);
  Eigen::Vector3d held_lobe = Eigen::Vector3d::Constant(NAN);
  Eigen::Vector3f wo = Eigen::Vector3f::UnitZ();  // local, toward the camera
  // Added to α² (αx², αy²) in this sample's lobe: its pixel's spread of normals
  // (Observation::lobe_blur2).
  double lobe_blur2 = 0;
  // Its incident samples: `incident_count` of them at `incident` (the solver's list of the
  // observation, or RegionFitInput::incident's storage), which must outlive the fit; the pointer
  // also names the sample to the fit's lobe table.
  const IncidentLocal* incident = nullptr;
  int64_t incident_count = 0;
  // The index of its first incident sample that is a Monte Carlo hemisphere ray (those before it
  // are exact, or the lights' own samples); the fit splits the rays into two halves to take
  // their noise out of the specular column (LobeTerms::half). Default: no ray.
  int64_t incident_rays_from = std::numeric_limits<int64_t>::max();
};

// What a region's fit knows and decides, apart from its samples.
struct RegionFitSettings {
  std::string name;
  recon::BrdfModel model = recon::BrdfModel::kLambert;
  bool fit_rho_d = true;             // false: FitSample::rho_d_known is used
  std::optional<double> rho_s_grey;  // known ρs (grey) or unknown
  std::optional<Eigen::Vector3d> rho_s_rgb;
  std::optional<double> alpha;             // isotropic models
  std::optional<double> alpha_x, alpha_y;  // anisotropic models
  double ior = 1.5;
  // The diffuse term: Lambert's, or Oren–Nayar's with a known or an unknown σ. With Oren–Nayar
  // the diffuse column is ρd·(A(σ)·E + B(σ)·G)/π, G = Σ_k OrenNayarG(wo, wi_k)·v_k over the
  // sample's incident list (solver/render/brdf.h): for a σ, linear in ρd as Lambert's. An unknown
  // σ is searched over [0, 1] (a grid of 11, then Brent's method), the α search and the linear
  // solve at each. With the coated base's term (no parameter) the column is
  // ρd·Σ_k T(cosθo)·T(cosθi_k)·v_k/π, fitted as Lambert's.
  recon::DiffuseShape diffuse = recon::DiffuseShape::kLambert;
  std::optional<double> sigma;
  bool grey_specular = true;  // one ρs for the three channels
  // The previous iteration's α (isotropic models): the search then starts near it instead of
  // scanning the whole range (it still scans when the minimum leaves the window).
  std::optional<double> alpha_hint;
  // Whether the albedo varies over the region, when an earlier fit decided it (the refinement's
  // noisier irradiance would otherwise tip the test); unset: decided from these samples.
  std::optional<bool> albedo_varies;
  // When the albedo varies (per patch): fit ρs and α to the samples whose rho_d_held is known,
  // each with that albedo (texel-scale, from the other photos), instead of their patch's
  // off-highlight mean. A patch is coarser than a texture's detail, and a highlight patch that
  // only highlight pixels see would otherwise take the region's mean albedo, its texture's
  // deviation from the mean going into ρs and α. The sample's model is then
  //   L = (rho_d_held − ρs·held_lobe)·E/π + ρs·T(α) = rho_d_held·E/π + ρs·(T(α) − held_lobe·E/π):
  // ρs is fitted through both terms at once. (Subtracting the previous iteration's lobe from the
  // held-out samples instead feeds its error back: a ρs too low leaves lobe in the albedo, which
  // lowers the next ρs; on the igi-synth floor this doubled ρs's error.)
  bool use_held_albedo = false;
  int num_slots = 1;
  std::vector<double> slot_area;  // m², per slot
};

struct RegionFitInput : RegionFitSettings {
  std::vector<FitSample> samples;
  // Storage the samples' incident pointers may point into (not read by the fit itself): the
  // solver points them at its per-observation lists instead, so that the fit copies nothing.
  std::vector<IncidentLocal> incident;
};

// How a fit models a region's diffuse albedo: one value over the region (kConstant) or one per
// patch (kPerPatch).
enum class AlbedoModel { kConstant, kPerPatch };
// "constant", "per_patch" (report.json's "albedo_model").
std::string_view AlbedoModelName(AlbedoModel model);
std::optional<AlbedoModel> AlbedoModelFromName(std::string_view name);

struct RegionFitResult {
  bool fitted = false;                                // false: nothing to fit (no samples)
  AlbedoModel albedo_model = AlbedoModel::kConstant;  // kConstant (default) or kPerPatch
  bool albedo_varies = false;                         // per-patch albedo significantly non-uniform
  Eigen::Vector3d rho_d = Eigen::Vector3d::Zero();    // region mean (area-weighted)
  std::vector<Eigen::Vector3d> slot_rho_d;            // per slot (NaN where no sample)
  std::vector<int> slot_count;                        // samples per slot
  Eigen::Vector3d rho_s = Eigen::Vector3d::Zero();
  double alpha = 0, alpha_x = 0, alpha_y = 0;
  double sigma = 0;  // Oren–Nayar's σ (0 with Lambert's diffuse)
  // One-sigma uncertainties (NaN where unknown or not fitted).
  Eigen::Vector3d sigma_rho_d = Eigen::Vector3d::Constant(NAN);
  double sigma_rho_s = NAN, sigma_alpha = NAN, sigma_alpha_x = NAN, sigma_alpha_y = NAN;
  double relative_rms = 0;  // sqrt(Σ(pred−L)²/ΣL²) over the samples, all channels
  int samples = 0;
  bool converged = true;
  std::string message;  // why it stopped, or what went wrong
};

struct RegionFitOptions {
  int max_polish_iterations = 30;  // Ceres iterations of the final joint polish
  int num_threads = 1;             // Ceres threads
};

RegionFitResult FitRegion(const RegionFitInput& input, const RegionFitOptions& options);

// The lobe of one direction pair (double): ρs_c·scale + offset (render::SpecularWeights; for
// Ward's lobes scale = S·W and offset 0).
render::LobeWeights LobeWeight(recon::BrdfModel model, double alpha_x, double alpha_y, double ior,
                               const Eigen::Vector3d& wo, const Eigen::Vector3d& wi);

}  // namespace igi::solver
