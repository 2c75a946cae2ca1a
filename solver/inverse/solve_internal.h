#pragma once
// Internal to igi_solver: the state of one solve, which orchestrates its stages (solve.cpp: the
// set-up, reading the photos and the gather; solve_model.cpp: the refinement's rounds, the
// residual renders and the albedo maps). Its data are the observation set, the material estimate
// and the light model (solver/inverse/observation_set.h, solver/inverse/material_estimate.h,
// solver/inverse/light_model.h); the stages are functions of them: solver/inverse/paper_stage.h,
// solver/inverse/fit_stage.h, solver/inverse/refine_stage.h, solver/inverse/albedo_map_stage.h.

#include <Eigen/Core>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "solver/inverse/albedo_map.h"
#include "solver/inverse/albedo_map_stage.h"
#include "solver/inverse/gather.h"
#include "solver/inverse/light_model.h"
#include "solver/inverse/material_estimate.h"
#include "solver/inverse/observation_set.h"
#include "solver/inverse/paper_stage.h"
#include "solver/inverse/patches.h"
#include "solver/inverse/region_fit.h"
#include "solver/inverse/solve.h"
#include "solver/inverse/solve_memory.h"
#include "solver/inverse/uv_charts.h"
#include "solver/render/brdf.h"
#include "solver/render/ray_scene.h"
#include "solver/render/sampling.h"

namespace igi::solver {

// An albedo map as scene.json holds it when its region's fitted ρd exceeds 1 in some channel
// (BoundReflectances): each channel whose `factor` is not 1 (1/ρd where ρd > 1) scaled by it and
// its texels clipped at 1. A channel of factor 1 is left as it is: its texels above 1 are the
// photos' noise about a level below 1 (a texel seen by one pixel of a few paths), and clipping
// them would darken the map's mean below the ρd scene.json gives the region. Returns how many
// texel channels were clipped.
int ScaleMapHeldAtOne(const Eigen::Vector3d& factor, Image* map);

// The report's images of a photo (PhotoResidual) are at most this many pixels on a side: one
// report pixel per ReportStride pixels of the photo.
inline constexpr int kReportMaxSide = 640;
// The photo pixels per report pixel: the pixel stride, or more where the photo's longer side at
// the stride exceeds kReportMaxSide.
int ReportStride(int width, int height, int pixel_stride);

struct SolverState {
  const recon::Scene& scene;
  SolveOptions options;
  SolveSummary summary;
  PatchSet patches;
  // The memory estimate (solver/inverse/solve_memory.h), planned before any photo is read.
  SolveMemoryEstimate memory;
  std::vector<std::unique_ptr<render::RayScene>> lighting_scenes;  // per lighting (null: unused)
  // The solve's three products, each a plain structure that the stages read and write: the
  // observations (and the draw they were collected under), the material estimate, and the
  // light modelled at the observations.
  ObservationSet obs;
  MaterialEstimate materials;
  LightModel light;

  SolverState(const recon::Scene& s, const SolveOptions& o) : scene(s), options(o) {}

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
  // The fit samples (obs.in_fit: SelectFitSamples in solver/inverse/observation_set.h) of the
  // regions with an unknown.
  void SelectFitSamples();
  void GatherAll();
  GatherQuery::Footprint PixelFootprint(const Observation& o) const;

  // What the stages read besides the estimate they update (solver/inverse/fit_stage.h).
  StageData Stage() const {
    return {scene,
            options,
            obs,
            patches,
            summary.scene_scale_m,
            summary.patch_size_m,
            summary.texel_size_m};
  }
  // Per lighting, the offset of a ray's origin from the surface (0 where the lighting is unused).
  std::vector<double> RayEpsilons() const {
    std::vector<double> eps(lighting_scenes.size(), 0.0);
    for (size_t l = 0; l < eps.size(); ++l) {
      if (lighting_scenes[l]) eps[l] = lighting_scenes[l]->ray_epsilon();
    }
    return eps;
  }
  // The paper's stage (RunPaperStage in solver/inverse/paper_stage.h) on the solve's data.
  void RunStage1() { RunPaperStage(Stage(), &materials, &light, &summary); }
  // One refinement round: the model as it stands (its albedo maps written under temp_dir),
  // its light at the observations (RenderIncident), smoothing, FitRegions(stage 2), specular
  // terms.
  void RefineRound(int round, const std::filesystem::path& temp_dir);
  void RunStage2();
  // The model as it stands, its albedo maps written under temp_dir. For the refinement's rounds
  // the regions fitted per patch get RefinementAlbedoMap's (the unseen texels at their patches'
  // albedos), whatever the options write; as_written, exactly the regions BuildAlbedoMaps gives
  // a map (WritesMap) get the map from the observations (AlbedoMapOf): the report renders the
  // model scene.json holds.
  recon::Scene CompleteScene(std::vector<RegionAtlas>* atlases, std::vector<Image>* maps,
                             const std::filesystem::path& temp_dir, bool as_written = false) const;
  // The model's residual rendered at the observed pixels (report.json's render_residual, and
  // stage 2's acceptance test); `model` is CompleteScene's as_written.
  void RenderResiduals(recon::Scene model, int stage);
  // The albedo-map stage's view of the solve (solver/inverse/albedo_map_stage.h).
  MapStageData MapData() const;
  void BuildAlbedoMaps();
  // The albedo maps of `regions` on `atlases` (one each) from every photo read again, every pixel
  // at the stride (solver/inverse/albedo_stream.cpp): for observations drawn to a budget, whose own
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

}  // namespace igi::solver
