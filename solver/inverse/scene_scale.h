#pragma once
// The length scale of the space the photos see, which the solver's patches and smoothing radii
// follow (patch edges and the irradiance smoothing radius are a 96th of it by default).
//
// The bounding box's diagonal is the size of a single room, but not of a building's rooms, a
// corridor, or a room whose geometry holds a far backdrop or ground plane. The free path is
// local: from the surface points the photos see (a grid of each camera's pixels), rays into the
// hemisphere facing the camera, cosine-weighted, and the mean distance to the next surface, each
// origin weighted by the surface area its pixel covers (pixel solid angle × distance² / cos),
// so that for a convex room seen all round it is Cauchy's mean chord 4V/S. The scale is the
// diagonal, or kDiagonalPerFreePath free paths where that is shorter: a room keeps its
// diagonal (a furnished box room's diagonal is 2.5-3.5 of its free paths), a building, a
// corridor or a scene with a far backdrop takes its rooms' size. Where under half of the rays
// meet a surface (an open scene) there is no free path, and the diagonal stands.

#include "recon/scene.h"
#include "solver/render/ray_scene.h"

namespace igi::solver {

inline constexpr double kDiagonalPerFreePath = 3.5;

struct SceneScale {
  double diagonal_m = 0;     // of the geometry's bounding box
  double free_path_m = NAN;  // mean free path from the seen surfaces (NaN: an open scene)
  double hit_fraction = 0;   // of the free-path rays that met a surface
  double scale_m = 0;        // min(diagonal, kDiagonalPerFreePath × free path)
};

// `geometry`: a render scene of `scene` (any lighting; light geometry is passed through), null
// for the diagonal alone. `pixels_per_camera` origins per camera on a regular grid.
SceneScale MeasureSceneScale(const recon::Scene& scene, const render::RayScene* geometry,
                             int pixels_per_camera = 2048);

// MeasureSceneScale on a render scene of the scene's first lighting (the diagonal alone when it
// has none).
SceneScale MeasureSceneScale(const recon::Scene& scene);

}  // namespace igi::solver
