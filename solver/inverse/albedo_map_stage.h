#pragma once
// Internal to igi_solver: the albedo-map stage as functions of the solve's data — the
// observation set, the light model at the observations, the material estimate and its patches
// — and the options. Which regions scene.json gives a map (MapCandidate, WritesMap) and the maps
// built from the observations (AlbedoMapOf). Maps of observations drawn to a budget come from
// their own pass over the photos instead (SolverState::StreamAlbedoMaps, which reads them).

#include <Eigen/Core>
#include <vector>

#include "recon/scene.h"
#include "solver/inverse/albedo_map.h"
#include "solver/inverse/light_model.h"
#include "solver/inverse/material_estimate.h"
#include "solver/inverse/observation_set.h"
#include "solver/inverse/patches.h"
#include "solver/inverse/solve_options.h"
#include "solver/inverse/uv_charts.h"
#include "tools/common/image.h"

namespace igi::solver {

// What the stage reads; every reference outlives the call.
struct MapStageData {
  const recon::Scene& scene;
  const SolveOptions& options;
  const ObservationSet& obs;
  const MaterialEstimate& materials;
  const PatchSet& patches;
  const LightModel& light;
  double texel_size_m = 0;   // the atlases' texel edge (SolveSummary::texel_size_m)
  double scene_scale_m = 0;  // the scene's length scale (SolveSummary::scene_scale_m)
  // The refinement: rounds run, and whether its model was kept (SolveSummary).
  int stage2_iterations = 0;
  bool refinement_accepted = false;
};

// Per observation, what the maps divide by and subtract. `e`: the irradiance. After joint
// stage-2 rounds it is stage 1's (gathered from the photographed patches: less noisy than the
// rounds' few path-traced directions) times the ratio of the rounds' to stage 1's irradiance
// averaged over 4 smoothing radii, so that the maps' texel detail keeps stage 1's noise while
// their level follows the path tracer; after a rejected refinement stage 1's; else the light
// model's. `t`: the specular term T, its direct part the observation's own and its indirect part
// (`t_indirect`) averaged over neighbours in the same photo: few incident samples carry the
// reflected room, so the indirect part is noisy (the same view, nearly), while the direct part
// from the light samples is not, and near a highlight it varies within a smoothing radius, where
// a mean over neighbours would subtract the highlight's flanks from the albedo.
// Per observation: the specular term per unit ρs (t, its indirect part t_indirect smoothed over
// the neighbours), the lobe's part that ρs does not scale (t0, t0_indirect likewise) and the
// irradiance e the maps use.
struct MapLight {
  std::vector<Eigen::Vector3d> t, t_indirect, t0, t0_indirect, e;
};
MapLight MapLightOf(const MapStageData& d);

// Whether the options let region r have a map (not --albedo-maps none, and among
// albedo_map_regions when those are listed).
bool MapAllowed(const MapStageData& d, size_t r);
// Whether region r may have a map: observed, of unknown ρd, MapAllowed.
bool MapCandidate(const MapStageData& d, size_t r);
// Region r's atlas at the stage's texel size.
RegionAtlas MapAtlas(const MapStageData& d, int r);

// The albedo map of region r: π(L − ρs·T)/E accumulated per texel over its observations, each
// weighted by its diffuse share. With photo_parity 0 or 1, only the photos of even or odd index
// contribute. `coverage` and `seen` as AlbedoMapBuilder gives them (when not null).
Image AlbedoMapOf(const MapStageData& d, int r, const RegionAtlas& atlas, const MapLight& light,
                  double* coverage = nullptr, Image* seen = nullptr, int photo_parity = -1);

// The albedo map the refinement renders a region fitted per patch with: the map of its
// observations (as AlbedoMapOf) at the texels they estimate directly, and at every other texel
// of the region the fit's albedo of the patch holding the texel's centre
// (MaterialEstimate::PatchAlbedo: a patch without observations has the region's ρd). The
// push-pull fill of AlbedoMapOf would instead carry a texel seen only by a single edge pixel
// (one path of a few-path photo can be many times the albedo) over the unseen surface around
// it, which is much of what the other regions see of it.
Image RefinementAlbedoMap(const MapStageData& d, int r, const RegionAtlas& atlas,
                          const MapLight& light);

// A region whose fit keeps a constant albedo still gets a map (and its ρd from the map) when its
// texture's relative standard deviation at the texel scale, beyond the noise, exceeds this.
// 0.1: a constant sphere's smooth shading errors read 5 %, the demo's noise-textured box and
// sphere (42 % standard deviation) about 20 %; a constant sphere whose Ward fit has the wrong
// lobe shape 5 % (10.8 % with the channels' relative variances averaged).
inline constexpr double kTexelTextureMin = 0.10;
// ... and when that variation is significant: its covariance over its standard error.
inline constexpr double kTexelTextureZ = 3.0;

// Whether scene.json gives region r a map: a MapCandidate with --albedo-maps all, an albedo
// fitted per patch, or (auto) an albedo that varies from texel to texel beyond the photos'
// noise, significantly: SharedTexelDetail of two maps from the even and the odd photos (each
// half's noise independent of the other's, both seeing the same texture and, nearly, the same
// errors of the gathered irradiance), in *detail when that test ran.
bool WritesMap(const MapStageData& d, size_t r, const RegionAtlas& atlas, const MapLight& light,
               TexelDetail* detail);

}  // namespace igi::solver
