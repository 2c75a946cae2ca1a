#pragma once
// Internal to igi_solver: the state of one solve (solve.cpp: set-up and stage 1's image-based
// model; solve_stages.cpp: the iterations, stage 2, residuals and albedo maps).

#include <Eigen/Core>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "solver/brdf.h"
#include "solver/gather.h"
#include "solver/observation_draw.h"
#include "solver/observations.h"
#include "solver/patches.h"
#include "solver/region_fit.h"
#include "solver/render_internal.h"
#include "solver/sampling.h"
#include "solver/solve.h"
#include "solver/solve_memory.h"
#include "solver/uv_charts.h"

namespace igi {

struct MaterialState {
  BrdfParams params;  // complete: known values, or the current estimate
  bool reflective = false;
  bool unknown_rho_d = false, unknown_rho_s = false, unknown_alpha = false;
  bool no_highlight = false;  // ρs and α cannot be recovered: ρs is held at 0
  std::optional<Eigen::Vector3d> tangent;
  std::shared_ptr<const Image> known_map;    // a known rho_d_map
  std::vector<Eigen::Vector3d> patch_rho_d;  // per region slot; NaN = the region's rho_d
  RegionFitResult last_fit;
  bool stage1_albedo_varies = false;  // stage 1's decision, kept by the refinement
  // Factor applied to the albedo map built from the observations' πL/E (AlbedoMapOf): the
  // refinement's update of the region's scale (1 unless a stage-2 round moved its mean away
  // from its independent refit: the joint update, or a partial step).
  Eigen::Vector3d map_scale = Eigen::Vector3d::Ones();
  int observations = 0;
  // A region no photo sees whose ρd was fitted to the light it bounces onto the seen regions
  // (SolverState::FitUnobservedAlbedos): its relative uncertainty per channel (NaN: not fitted).
  Eigen::Vector3d bounce_fit_sigma = Eigen::Vector3d::Constant(NAN);
  bool NeedsFit() const { return reflective && (unknown_rho_d || unknown_rho_s || unknown_alpha); }
};

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
    const size_t k = n * n * Renderer::kDerivativeKinds;
    d_e.assign(k, Eigen::Vector3d::Zero());
    d_t.assign(k, Eigen::Vector3d::Zero());
    t.assign(n, Eigen::Vector3d::Zero());
  }
  // Region `r`'s observation: its derivative rows and its T.
  void Add(int r, const std::vector<Eigen::Vector3d>& de, const std::vector<Eigen::Vector3d>& dt,
           const Eigen::Vector3d& tr) {
    const size_t row = regions * Renderer::kDerivativeKinds, o = size_t(r) * row;
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
    return v[(size_t(r) * regions + j) * Renderer::kDerivativeKinds + kind];
  }
};

// The joint update's result per fitted region (NaN where the region's own refit stands):
// its albedo, its ρs, and per channel the relative change of its fitted light per unit relative
// change of every region's albedo ("feedback").
struct JointUpdate {
  std::vector<Eigen::Vector3d> rho_d, rho_s, feedback;
};

// "joint" (every region's ρd and ρs jointly, the α changes included) or "joint_albedo" (the
// albedos only, session 11's update).
inline bool IsJointUpdate(const std::string& update) {
  return update == "joint" || update == "joint_albedo";
}

// An albedo map as scene.json holds it when its region's fitted ρd exceeds 1 in some channel
// (BoundReflectances): scaled by `factor` per channel (1/ρd where ρd > 1, else 1) and its texels
// clipped at 1. Returns how many texel channels were clipped.
int ScaleMapHeldAtOne(const Eigen::Vector3d& factor, Image* map);

// The report's images of a photo (PhotoResidual) are at most this many pixels on a side: one
// report pixel per ReportStride pixels of the photo.
inline constexpr int kReportMaxSide = 640;
// The photo pixels per report pixel: the pixel stride, or more where the photo's longer side at
// the stride exceeds kReportMaxSide.
int ReportStride(int width, int height, int pixel_stride);

struct SolverState {
  const Scene& scene;
  SolveOptions options;
  SolveSummary summary;
  PatchSet patches;
  std::vector<MaterialState> materials;
  std::vector<std::vector<int>> region_patches;  // per region: its patches (slot order)
  std::vector<int> patch_slot;                   // per patch: index within its region
  // The memory estimate and the observations' draw (solver/observation_draw.h), planned before
  // any photo is read.
  SolveMemoryEstimate memory;
  ObservationDraw draw;
  std::vector<std::unique_ptr<Renderer::Impl>> lighting_scenes;  // per lighting (null: unused)
  std::vector<Observation> obs;
  std::vector<char> in_fit;    // per observation: used by the region fits
  std::vector<int> obs_point;  // per observation: its point in its lighting's gather
  std::vector<LightingState> lighting_state;
  // Per observation, refreshed each iteration: direct and indirect irradiance (the indirect
  // smoothed over neighbours), the incident samples in the local frame (regions with a
  // specular lobe) and T = Σ S·W·v at the current α.
  std::vector<Eigen::Vector3d> obs_e_direct, obs_e_indirect, obs_e;
  std::vector<std::vector<IncidentLocal>> obs_incident;
  // Stage 2's joint update (empty otherwise): the rendered light's derivatives, summed per
  // fitted region over its fit observations.
  JointSums joint_sums;
  std::vector<Eigen::Vector3d> obs_e_stage1;  // obs_e at the end of stage 1
  std::vector<Eigen::Vector3d> obs_t;
  // Per observation of a textured glossy region: the other photos' observations off the
  // highlights at the albedo map's texel (solver/held_out_albedo.h): their πL/E and their lobe
  // per unit ρs, πT/E (the albedo is the first less ρs times the second); NaN elsewhere.
  std::vector<Eigen::Vector3d> obs_rho_d_held, obs_held_lobe;
  std::vector<std::unique_ptr<RegionAtlas>> held_atlases;  // per region, built when needed

  SolverState(const Scene& s, const SolveOptions& o) : scene(s), options(o) {}

  // solve.cpp
  void Prepare();  // everything before the rays (Solve() then gathers and fits)
  void InitMaterials();
  // A photo as the solver reads it: linear radiance and its 8-bit mask (0 = ignore; empty:
  // every pixel), the held-out and (for photos that are not plain radiance) clipped pixels
  // masked out.
  struct LoadedPhoto {
    Image radiance;
    std::vector<uint8_t> mask;
  };
  LoadedPhoto LoadPhoto(int photo) const;
  void BuildLightingScenes();
  // The memory estimate and the observations' draw: every pixel at the stride when they fit the
  // budget, else a census and the draw's probabilities; throws InputError when not even the
  // largest photo and the fits' fewest observations fit.
  void PlanObservations();
  // The share of region r's pixels at the stride (near a highlight or not) that observations were
  // drawn at (their density), and the hash threshold they were drawn under (the same for single
  // pixels, larger for blocks: solver/observation_draw.h).
  double DrawnShare(int region, bool near) const {
    return draw.census ? draw.Probability(region, near) : 1.0;
  }
  double DrawnThreshold(int region, bool near) const {
    return draw.census ? draw.Threshold(region, near) : 1.0;
  }
  void CollectAllObservations();
  void SelectFitSamples();
  void GatherAll();
  GatherQuery::Footprint PixelFootprint(const Observation& o) const;
  void BuildPatchLobes(LightingState* st) const;
  Frame LocalFrame(int region, const Eigen::Vector3d& n) const;
  Eigen::Vector3d PatchAlbedo(int patch) const;
  Eigen::Vector3d PatchSpecular(const LightingState& st, int q,
                                const Eigen::Vector3d& toward) const;
  Eigen::Vector3d PatchRadiance(const LightingState& st, int q,
                                const Eigen::Vector3d& toward) const;
  // The radiance arriving along an indirect sample: its patch's radiance toward the sample's
  // point plus the specular light its glossy hit reflects from the sample's bounce.
  Eigen::Vector3d BounceRadiance(const LightingState& st, const IndirectSample& s) const;
  Eigen::Vector3d IndirectRadiance(const LightingState& st, const IndirectSample& s) const;
  void UpdatePatchRadiance(LightingState* st);

  // solve_stages.cpp
  void IncidentFromPatches();
  void IncidentFromRenderer(const Scene& model, uint64_t round);
  void SmoothIrradiance();
  std::vector<Eigen::Vector3d> NeighbourMean(
      const std::vector<Eigen::Vector3d>& values, double radius, bool same_photo,
      const std::vector<float>* point_radius = nullptr) const;
  // Per observation, its smoothing radius (the adaptive smoothing's, SolveOptions::
  // smoothing_accuracy, from stage 1's gather); empty until SmoothIrradiance first needs it.
  std::vector<float> obs_smoothing_radius;
  void ComputeSmoothingRadii(double radius);
  std::vector<float> DrawnSmoothingRadii(double radius) const;
  void ComputeSpecularTerms();
  void HeldOutAlbedos();
  double FitAll(int stage, int iteration);  // returns the largest relative change
  // The joint update (per entry of `regions`, from their fits `fits`): the solution of the
  // fixed point p_r = fit_r(light(p)) with the light linearised by joint_sums.
  JointUpdate JointParams(const std::vector<int>& regions,
                          const std::vector<RegionFitResult>& fits) const;
  void RunStage1();
  // Every active lighting's patch radiances, the observations' indirect irradiance and its
  // smoothing from the current materials (obs_e).
  void UpdateIrradiance();
  // The ρd of regions no photo sees, from the light they bounce onto the regions the photos show
  // (stage 1, from its second iteration): returns the largest relative change.
  double FitUnobservedAlbedos();
  // One refinement round: the model as it stands (its albedo maps written under temp_dir),
  // rendered incident light, smoothing, FitAll(2, round), specular terms.
  void RefineRound(int round, const std::filesystem::path& temp_dir);
  void RunStage2();
  // The model as it stands. Per-patch albedo maps (written under temp_dir) go to the regions
  // fitted per patch, or, as_written, to exactly the regions BuildAlbedoMaps gives a map
  // (WritesMap): the refinement's rounds model the bounced light with the per-patch albedos
  // whatever the options write, the report renders the model scene.json will hold.
  Scene CompleteScene(std::vector<RegionAtlas>* atlases, std::vector<Image>* maps,
                      const std::filesystem::path& temp_dir, bool as_written = false) const;
  // Whether the options let region r have an albedo map in scene.json (not --albedo-maps none,
  // and among albedo_map_regions when those are listed).
  bool MapAllowed(size_t r) const;
  // Whether region r may have an albedo map in scene.json: observed, of unknown ρd, MapAllowed.
  bool MapCandidate(size_t r) const;
  // Whether scene.json gives region r an albedo map: a MapCandidate with --albedo-maps all, an
  // albedo fitted per patch, or (auto) an albedo that varies from texel to texel beyond the photos'
  // noise (its variation in *texel_variation when that test ran).
  bool WritesMap(size_t r, const RegionAtlas& atlas, const std::vector<Eigen::Vector3d>& smooth_t,
                 const std::vector<Eigen::Vector3d>& map_e, double* texel_variation) const;
  // The model's residual rendered at the observed pixels (report.json's render_residual, and
  // stage 2's acceptance test); `model` is CompleteScene's as_written.
  void RenderResiduals(Scene model, int stage);
  // The irradiance the albedo maps divide by. After joint stage-2 rounds: stage 1's per
  // observation (gathered from the photographed patches: less noisy than the rounds' few
  // path-traced directions) times the ratio of the rounds' to stage 1's irradiance averaged over
  // 4 smoothing radii, so that the maps' texel detail keeps stage 1's noise while their level
  // follows the path tracer; otherwise obs_e (stage 1's after a rejected refinement).
  std::vector<Eigen::Vector3d> MapIrradiance() const;
  void BuildAlbedoMaps();
  // The albedo maps of `regions` on `atlases` (one each) from every photo read again, every pixel
  // at the stride (solver/albedo_stream.cpp): for observations drawn to a budget, whose own
  // spacing is coarser than the photos'. Also each map's seen texels and coverage.
  std::vector<Image> StreamAlbedoMaps(const std::vector<int>& regions,
                                      const std::vector<RegionAtlas>& atlases,
                                      const std::vector<Eigen::Vector3d>& smooth_t,
                                      const std::vector<Eigen::Vector3d>& map_e,
                                      std::vector<Image>* seen,
                                      std::vector<double>* coverage) const;
  Eigen::Vector3d KnownAlbedo(const Observation& o) const;

  // solve.cpp
  void SummariseRegions();
  void ChooseTexelSize();
  void AnalyseCoverage();
  void FinishRegions();
  void BoundReflectances(size_t r);
};

}  // namespace igi
