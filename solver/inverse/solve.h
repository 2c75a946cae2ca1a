#pragma once
// igi-solve (docs/solve.md): inverse global illumination after Yu, Debevec, Malik and Hawkins
// (SIGGRAPH 1999), then a joint refinement against the path tracer.
//
// Stage 1, the paper's method: the surfaces are split into patches (region → triangle → patch);
// each photo pixel that sees a surface cleanly is an observation. At every observation the
// light arriving from the lights (Embree shadow rays) and from the other patches (hemisphere
// rays) is gathered; the radiance a patch sends toward another point is what the photos saw of
// it (its diffuse part, image-based) plus a specular part that depends on the unknown BRDF. The
// solver alternates: fit each region's ρs and α (constant per region) and albedo (constant, or
// free per patch where the data say it varies) to the observations, recompute the patches'
// radiance with the new specular parameters ("specular differences"), refit, until converged.
//
// Stage 2, beyond the paper: the light arriving at every observation is re-rendered with the
// full path tracer using the current model (all bounces, every surface, seen or not), all
// parameters are refitted against the photos with the same model (gradients through the BRDF
// by Ceres autodiff), and this is repeated. The albedos are refitted per region against the
// light rendered from the old ones, or (SolveOptions::refine_update kJoint) jointly, with the
// rendered light's derivatives with respect to every region's albedo, ρs and α scales (the
// renderer's gradients): each round then solves for the albedos and ρs that match the photos
// with the light those parameters would send, instead of overshooting in bright rooms or
// following a glossy surface's reflected light. Both stages are reported.
//
// Finally the albedo of every texel of the regions that need a map is π(L − specular)/E
// averaged over the observations that fall in it.

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "recon/scene.h"
#include "solver/inverse/highlight_coverage.h"
#include "solver/inverse/observations.h"
#include "solver/inverse/photometric_scale.h"
#include "solver/inverse/region_fit.h"
#include "solver/inverse/solve_options.h"
#include "solver/render/brdf.h"
#include "tools/common/image.h"
#include "tools/common/json.h"

namespace igi::solver {

// What became of a region: kKnown (nothing to estimate), kSolved, kUnobserved (unknowns but no
// observation: values are placeholders, or ρd fitted to the light it bounces), kNoHighlight (ρs
// and α cannot be recovered: no photo shows the highlight; ρs set to 0).
enum class RegionStatus { kKnown, kSolved, kUnobserved, kNoHighlight };
// "known", "solved", "unobserved", "no_highlight" (report.json's "status").
std::string_view RegionStatusName(RegionStatus status);
std::optional<RegionStatus> RegionStatusFromName(std::string_view name);

struct RegionSolution {
  std::string name;
  RegionStatus status = RegionStatus::kKnown;  // RegionStatus (above); kKnown by default
  std::vector<std::string> unknowns;           // scene.json keys estimated
  RegionFitResult stage1, stage2;              // stage2 == final (stage1 when refinement is off)
  render::BrdfParams final_params;             // every value of the solved material
  int observations = 0;
  // Albedo map (when estimated): the image, its file name under the output folder, coverage.
  std::optional<Image> albedo_map;
  std::string albedo_map_file;
  double albedo_map_coverage = 0;
  // Per texel of albedo_map: 1 where observations estimate it directly, 0 where it was filled
  // from its neighbours (seen by no photo, or outside the region's charts). One channel.
  std::optional<Image> albedo_map_seen;
  bool albedo_map_generated_uvs = false;
  // With --albedo-maps auto, a region whose fit kept a constant albedo: its albedo's relative
  // standard deviation from texel to texel beyond the photos' noise (two maps from disjoint
  // halves of the photos, each less its local mean; NaN: not measured). Above 10 % the region
  // gets a map anyway: a texture finer than the patches averages out in the fit's per-patch test.
  double texel_variation = NAN;
  // texel_variation's covariance over its standard error (SharedTexelDetail): the region gets a
  // map only above 3 as well, so that a photo's heavy-tailed noise on few texels gives none.
  double texel_variation_z = NAN;
  // The map's mean over its seen texels (equal areas: a texel is texel_size_m square on the
  // surface), NaN without a map (report.json's albedo_map.seen_mean). It is the region's final ρd
  // (final_params.rho_d, scene.json's rho_d; rho_d_from_map) where it is positive; stage1/stage2
  // keep the fit's region mean (each patch with samples weighted by its area), which runs a few
  // per cent off on textured regions (bench/RESULTS.md).
  Eigen::Vector3d albedo_map_seen_mean = Eigen::Vector3d::Constant(NAN);
  bool rho_d_from_map = false;
  // An unobserved region whose ρd was fitted to the light it bounces onto the regions the photos
  // show (stage 1): its relative uncertainty per channel; NaN where its ρd is a placeholder.
  Eigen::Vector3d bounce_fit_sigma = Eigen::Vector3d::Constant(NAN);
  bool RhoDFromBouncedLight() const { return bounce_fit_sigma.allFinite(); }
  // A reflectance is at most 1 (scene.json's rule). When a fit comes out above it (photos brighter
  // than any passive surface under the declared lights: a light too weak, an exposure_scale too
  // low, light the scene leaves out), the written model holds it at 1 and these say what the fit
  // wanted: the fitted ρd / ρs per channel (NaN where not bounded), and how many albedo-map texels
  // were above 1 (the map is scaled by the region's bound, then clipped at 1).
  Eigen::Vector3d rho_d_fitted = Eigen::Vector3d::Constant(NAN);
  Eigen::Vector3d rho_s_fitted = Eigen::Vector3d::Constant(NAN);
  long long albedo_texels_clipped = 0;
  bool Bounded() const {
    return rho_d_fitted.allFinite() || rho_s_fitted.allFinite() || albedo_texels_clipped > 0;
  }
};

struct SolveIteration {
  int stage = 1;
  int iteration = 0;
  double relative_rms = 0;  // over all fitted samples
  double max_change = 0;    // largest relative parameter change from the previous iteration
  Json params;              // per region: rho_d, rho_s, alpha
  // Stage 2: the round's update (SolveOptions::refine_update; unset in stage 1), and per
  // region in `params` also "rho_d_independent" (the region's own refit, πL/E at the rendered E)
  // and, for a joint update, "rho_d_joint" (the albedo that matches the photos with the light it
  // would send, before the step share) and "feedback" (per channel, the relative change of the
  // region's gathered irradiance per relative change of every fitted albedo together); for
  // kJoint, a region with unknown ρs also has "rho_s_independent" and "rho_s_joint".
  std::optional<RefineUpdate> albedo_update;
  double albedo_step = 1;  // SolveOptions::refine_albedo_step
};

// Per photo: the residual of docs/file-formats.md (diagnosis.json) at the observed pixels, the
// photo and the model.
struct PhotoResidual {
  std::string file;
  double stage1 = 0, stage2 = 0;  // path-traced render vs photo, relative RMS
  Image photo, render, residual;  // at the observation grid (stride), linear, for the report
};

struct SolveSummary {
  std::vector<RegionSolution> regions;  // one per material, scene order
  std::vector<SolveIteration> history;
  std::vector<PhotoObservationStats> photos;
  std::vector<PhotoResidual> residuals;
  std::vector<RegionHighlightCoverage> coverage;
  bool converged = false;
  std::string message;  // why stage 1 stopped
  int stage1_iterations = 0, stage2_iterations = 0;
  double stage1_model_residual = 0;   // the paper's image-based model vs the photos
  double stage1_render_residual = 0;  // path-traced render of the stage-1 model vs the photos
  double stage2_render_residual = 0;  // the same for the final model
  int render_residual_spp = 0;
  // Standard errors of the squared render residuals (the estimate is noisy at a few paths).
  double stage1_render_residual_sq_se = 0, stage2_render_residual_sq_se = 0;
  // Whether the refinement's parameters were kept (false: they explained the photos worse, and
  // the paper stage's are the result; both are reported).
  bool refinement_accepted = true;
  // The photos' scale k (photo = k × radiance) estimated from the reference regions when
  // SolveOptions::photo_scale is "solve" (solver/inverse/photometric_scale.h); nullopt: given.
  std::optional<PhotoScaleEstimate> photo_scale;
  double patch_size_m = 0, texel_size_m = 0;
  // The photos' own pixel footprint at the stride (texel_size_m where given): the texel of maps
  // from their own pass over the photos (SolveOptions::albedo_map_pass), where texel_size_m, the
  // drawn observations' spacing, serves the fits and stage 2's model.
  double map_texel_size_m = 0;
  double scene_diagonal_m = 0;  // of the geometry's bounding box
  // The mean free path from the seen surfaces (NaN: an open scene) and the length scale the
  // patches and smoothing radii follow (solver/inverse/scene_scale.h).
  double free_path_m = NAN, scene_scale_m = 0;
  int patches = 0, observations = 0;
  // Pixels at the stride that saw a reflective surface (observations plus those not drawn), the
  // observation budget (infinity: none), whether the draw thinned the photos, and the memory:
  // the budget, the estimated peak for the observations drawn, the process's measured peak.
  double observations_available = 0;
  double observation_budget = 0;
  bool observations_thinned = false;
  double memory_budget_bytes = 0, memory_estimate_bytes = 0, peak_memory_bytes = 0;
  std::vector<std::pair<std::string, double>> peak_after;  // per stage: the peak so far, bytes
  uint64_t rays = 0;
  double seconds_total = 0, seconds_rays = 0, seconds_fit = 0;
  // The solved scene.json document (paths relative to the output folder) and any mesh with
  // generated texture charts (written as geometry/solved.obj).
  Json scene_document;
  std::optional<recon::TriangleMesh> charted_mesh;
};

// Solves `scene` (loaded with complete geometry). `out_dir` is only used to express the paths
// of the returned scene document relative to it; nothing is written. Throws InputError for bad
// input (a photographed lighting without light, a photo with no valid pixel, a photo whose size
// differs from its camera's).
SolveSummary Solve(const recon::Scene& scene, const SolveOptions& options,
                   const std::filesystem::path& out_dir);

// The input scene.json document with every material value filled in
// (solver/inverse/solve_output.cpp): rho_d (region mean) always, rho_s/alpha where the model has
// them, rho_d_map where a map was estimated ("albedo/<region>.exr"), geometry replaced by
// "geometry/solved.obj" when texture charts were generated; every other relative path rewritten
// relative to `out_dir`.
Json SolvedSceneDocument(const recon::Scene& scene, const SolveSummary& summary,
                         const std::filesystem::path& out_dir);

// report.json (solver/inverse/solve_output.cpp).
Json SolveReportJson(const SolveSummary& summary, const SolveOptions& options);

// Writes DIR/scene.json, albedo maps, the charted mesh, report.json and report.html, each
// atomically, the scene last (solver/inverse/solve_output.cpp).
void WriteSolveOutputs(const SolveSummary& summary, const SolveOptions& options,
                       const std::filesystem::path& out_dir);

}  // namespace igi::solver
