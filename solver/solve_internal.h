#pragma once
// Internal to igi_solver: the state of one solve (solve.cpp: set-up and stage 1's image-based
// model; solve_stages.cpp: the iterations, stage 2, residuals and albedo maps). Its data are the
// observation set, the material estimate and the light model (solver/observation_set.h,
// solver/material_estimate.h, solver/light_model.h); the stages that only read and write those
// are functions of them there and in solver/fit_inputs.h.

#include <Eigen/Core>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "solver/albedo_map.h"
#include "solver/albedo_map_stage.h"
#include "solver/brdf.h"
#include "solver/gather.h"
#include "solver/light_model.h"
#include "solver/material_estimate.h"
#include "solver/observation_set.h"
#include "solver/patches.h"
#include "solver/region_fit.h"
#include "solver/render_internal.h"
#include "solver/sampling.h"
#include "solver/solve.h"
#include "solver/solve_memory.h"
#include "solver/uv_charts.h"

namespace igi {

// The joint update's result per fitted region (NaN where the region's own refit stands):
// its albedo, its ρs, and per channel the relative change of its fitted light per unit relative
// change of every region's albedo ("feedback").
struct JointUpdate {
  std::vector<Eigen::Vector3d> rho_d, rho_s, feedback;
};

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
  // The memory estimate (solver/solve_memory.h), planned before any photo is read.
  SolveMemoryEstimate memory;
  std::vector<std::unique_ptr<Renderer::Impl>> lighting_scenes;  // per lighting (null: unused)
  // The solve's three products, each a plain structure that the stages read and write: the
  // observations (and the draw they were collected under), the material estimate, and the
  // light modelled at the observations.
  ObservationSet obs;
  MaterialEstimate materials;
  LightModel light;

  SolverState(const Scene& s, const SolveOptions& o) : scene(s), options(o) {}

  // solve.cpp
  void Prepare();  // everything before the rays (Solve() then gathers and fits)
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
  void CollectAllObservations();
  // The fit samples (obs.in_fit: SelectFitSamples in solver/observation_set.h) of the regions
  // with an unknown.
  void SelectFitSamples();
  void GatherAll();
  GatherQuery::Footprint PixelFootprint(const Observation& o) const;

  // solve_stages.cpp
  void IncidentFromRenderer(const Scene& model, uint64_t round);
  // light.e (SmoothIrradiance in solver/light_model.h), the smoothing radii computed first
  // where there are none yet.
  void SmoothIrradiance();
  // light.smoothing_radius: per observation, its smoothing radius (the adaptive smoothing's,
  // SolveOptions::smoothing_accuracy, from stage 1's gather).
  void ComputeSmoothingRadii(double radius);
  std::vector<float> DrawnSmoothingRadii(double radius) const;
  // light.t at the current materials (SpecularTerms in solver/light_model.h).
  void ComputeSpecularTerms() {
    light.t = SpecularTerms(obs, materials, light.incident, options.num_threads);
  }
  double FitAll(int stage, int iteration);  // returns the largest relative change
  // The joint update (per entry of `regions`, from their fits `fits`): the solution of the
  // fixed point p_r = fit_r(light(p)) with the light linearised by joint_sums.
  JointUpdate JointParams(const std::vector<int>& regions,
                          const std::vector<RegionFitResult>& fits) const;
  void RunStage1();
  // Every active lighting's patch radiances, the observations' indirect irradiance and its
  // smoothing from the current materials (light.e).
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
  // The model's residual rendered at the observed pixels (report.json's render_residual, and
  // stage 2's acceptance test); `model` is CompleteScene's as_written.
  void RenderResiduals(Scene model, int stage);
  // The albedo-map stage's view of the solve (solver/albedo_map_stage.h).
  MapStageData MapData() const;
  void BuildAlbedoMaps();
  // The albedo maps of `regions` on `atlases` (one each) from every photo read again, every pixel
  // at the stride (solver/albedo_stream.cpp): for observations drawn to a budget, whose own
  // spacing is coarser than the photos'. Also each map's seen texels and coverage.
  std::vector<Image> StreamAlbedoMaps(const std::vector<int>& regions,
                                      const std::vector<RegionAtlas>& atlases,
                                      const MapLight& map_light, std::vector<Image>* seen,
                                      std::vector<double>* coverage) const;

  // solve.cpp
  void SummariseRegions();
  void ChooseTexelSize();
  void AnalyseCoverage();
  void FinishRegions();
  void BoundReflectances(size_t r);
};

}  // namespace igi
