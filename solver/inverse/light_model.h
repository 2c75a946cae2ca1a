#pragma once
// Internal to igi_solver: the light a solve models at its observations. Per lighting, the gather
// (solver/inverse/gather.h: its observations' points first, then one per patch) and the radiance
// leaving each patch; per observation, in the observation set's order
// (solver/inverse/observation_set.h), its direct and indirect irradiance (the indirect smoothed
// over neighbours into `e`), its incident samples in the local frame (regions with a specular lobe)
// and its specular term T = Σ S·W·v at the current α.

#include <Eigen/Core>
#include <vector>

#include "recon/scene.h"
#include "solver/inverse/gather.h"
#include "solver/inverse/material_estimate.h"
#include "solver/inverse/observation_set.h"
#include "solver/inverse/patches.h"
#include "solver/inverse/region_fit.h"
#include "solver/render/render.h"

namespace igi::solver {

struct LightingState {
  bool active = false;
  std::vector<int> obs;  // observations under this lighting
  GatherSet gather;      // their points first, then one per patch
  int first_patch_point = 0;
  std::vector<Eigen::Vector3f> patch_d;  // diffuse radiance leaving each patch
  std::vector<Eigen::Vector3f> patch_e;  // irradiance of each patch
  std::vector<int> lobe_begin;           // per patch (+1): representative direct samples
  std::vector<DirectSample> lobes;
};

// Stage 2's joint update: the rendered light's derivatives with respect to every region's
// parameters (Renderer::ReflectedRadiance: the log-scales of ρd, ρs and α), summed per fitted
// region r over its fit observations. Row r of d_e: the derivatives of the raw indirect
// irradiance E; of d_t: those of the specular term T = Σ S·W·v at the rendered α (glossy
// regions); t: ΣT itself. Rows are regions × Renderer::kDerivativeKinds long.
struct JointSums {
  size_t regions = 0;
  std::vector<Eigen::Vector3d> d_e, d_t, t;
  void Resize(size_t n) {
    regions = n;
    const size_t k = n * n * render::Renderer::kDerivativeKinds;
    d_e.assign(k, Eigen::Vector3d::Zero());
    d_t.assign(k, Eigen::Vector3d::Zero());
    t.assign(n, Eigen::Vector3d::Zero());
  }
  // Region `r`'s observation: its derivative rows and its T.
  void Add(int r, const std::vector<Eigen::Vector3d>& de, const std::vector<Eigen::Vector3d>& dt,
           const Eigen::Vector3d& tr) {
    const size_t row = regions * render::Renderer::kDerivativeKinds, o = size_t(r) * row;
    for (size_t j = 0; j < row; ++j) d_e[o + j] += de[j], d_t[o + j] += dt[j];
    t[r] += tr;
  }
  void Add(const JointSums& other) {
    if (other.regions != regions) return;
    for (size_t j = 0; j < d_e.size(); ++j) d_e[j] += other.d_e[j], d_t[j] += other.d_t[j];
    for (size_t j = 0; j < t.size(); ++j) t[j] += other.t[j];
  }
  // Row r's entry for region j's parameter `kind`.
  const Eigen::Vector3d& E(const std::vector<Eigen::Vector3d>& v, int r, int j, int kind) const {
    return v[(size_t(r) * regions + j) * render::Renderer::kDerivativeKinds + kind];
  }
};

struct LightModel {
  std::vector<LightingState> lightings;  // per scene lighting (active: some photo's)
  std::vector<int> point;                // per observation: its point in its lighting's gather
  // Per observation: direct and indirect irradiance, and their sum with the indirect smoothed
  // (SmoothIrradiance): the irradiance the fits divide by; `e` at the end of stage 1.
  std::vector<Eigen::Vector3d> e_direct, e_indirect, e, e_stage1;
  std::vector<std::vector<IncidentLocal>> incident;  // in the local frame (glossy regions)
  // Per observation: how many of its incident samples, first in its list, are the lights' direct
  // samples; the rest are Monte Carlo hemisphere rays (FitSample::incident_rays_from).
  std::vector<int32_t> incident_direct;
  std::vector<Eigen::Vector3d> t;  // T = Σ scale·v at the current α
  // O = Σ offset·v at the current α: the lobe's part that ρs does not scale (the microfacet
  // models' grazing Fresnel; zero for Ward's lobes), so that the lobe is ρs∘T + O.
  std::vector<Eigen::Vector3d> t0;
  // Per observation: the radius its indirect irradiance is smoothed over (empty until the
  // solve first smooths).
  std::vector<float> smoothing_radius;
  // Stage 2's joint update (empty otherwise): the rendered light's derivatives, summed per
  // fitted region over its fit observations.
  JointSums joint_sums;
};

// The mean of `values` (per observation) over each observation's neighbours: same region,
// normals within ~25°, within `radius` (or point_radius[i], each at most `radius`), and
// (same_photo) in the same photo, else any photo of the same lighting
// (solver/inverse/neighbour_mean.h).
std::vector<Eigen::Vector3d> NeighbourMean(const ObservationSet& obs,
                                           const std::vector<LightingState>& lightings,
                                           const std::vector<Eigen::Vector3d>& values,
                                           double radius, bool same_photo, int num_threads,
                                           const std::vector<float>* point_radius = nullptr);

// light->e: each observation's direct irradiance plus its indirect irradiance averaged over the
// observations within its smoothing radius (light->smoothing_radius) on the same region under
// the same lighting: the indirect light varies slowly over a surface, its per-point estimate is
// noisy.
void SmoothIrradiance(const ObservationSet& obs, int num_threads, LightModel* light);

// Per observation: its specular term T = Σ scale·v over its incident samples (`incident`, in the
// local frame) with its region's lobe at the current α widened by the pixel's spread of normals
// (render::SpecularWeights), and in `offsets` O = Σ offset·v; zero for regions without a lobe.
std::vector<Eigen::Vector3d> SpecularTerms(const ObservationSet& obs,
                                           const MaterialEstimate& materials,
                                           const std::vector<std::vector<IncidentLocal>>& incident,
                                           int num_threads, std::vector<Eigen::Vector3d>* offsets);

// The direct part of a point's specular term T: Σ scale·v over its direct samples d[0..n) (world
// directions) with the lobe of `p` widened by the spread of normals `blur2` (as SpecularTerms),
// in `frame`, seen from `view` (world, unit); its O = Σ offset·v in `offset`.
Eigen::Vector3d DirectSpecularTerm(const render::BrdfParams& p, double blur2,
                                   const render::Frame& frame, const Eigen::Vector3d& view,
                                   const DirectSample* d, int64_t n, Eigen::Vector3d* offset);

// Per observation: DirectSpecularTerm over its gather point's direct samples (O in `offsets`);
// zero for regions without a lobe.
std::vector<Eigen::Vector3d> DirectSpecularTerms(const recon::Scene& scene,
                                                 const ObservationSet& obs,
                                                 const MaterialEstimate& materials,
                                                 const LightModel& light, int num_threads,
                                                 std::vector<Eigen::Vector3d>* offsets);

// Each patch's direct samples (its gather point's) grouped into at most four representative
// directions, for the specular part of the radiance it sends toward other points.
void BuildPatchLobes(const PatchSet& patches, const MaterialEstimate& materials, LightingState* st);

// The radiance arriving along an indirect sample: its patch's radiance toward the sample's point
// (the diffuse patch_d plus the patch's lobe over its representative directions) plus the
// specular light its glossy hit reflects from the sample's bounce.
Eigen::Vector3d IndirectRadiance(const PatchSet& patches, const MaterialEstimate& materials,
                                 const LightingState& st, const IndirectSample& s);

// D_q, st->patch_d: the diffuse radiance of each patch, the photos' mean over its observations
// (of st->obs) less their predicted specular part ρs∘t + t0; patches no photo of the lighting
// sees get ρd·E/π, their irradiance E (st->patch_e) from the patches' new radiance (two sweeps).
void UpdatePatchRadiance(const ObservationSet& obs, const PatchSet& patches,
                         const MaterialEstimate& materials, const std::vector<Eigen::Vector3d>& t,
                         const std::vector<Eigen::Vector3d>& t0, int num_threads,
                         LightingState* st);

// Per observation of the active lightings: light->e_direct (its gather point's), light->
// e_indirect (its indirect samples' radiance from the patches) and light->incident (both as
// local-frame samples, for regions with a lobe).
void IncidentFromPatches(const ObservationSet& obs, const PatchSet& patches,
                         const MaterialEstimate& materials, int num_threads, LightModel* light);

// A gather point's direct samples in the local shading frame, with room reserved for `more`
// samples to follow.
std::vector<IncidentLocal> DirectIncident(const LightingState& st, const GatherPoint& gp,
                                          const render::Frame& frame, int64_t more);

}  // namespace igi::solver
