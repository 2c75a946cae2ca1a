#pragma once
// Where the photos show the specular highlights: a region's ρs and α can only be
// recovered from pixels that see the light mirrored in it, i.e. whose half vector between the
// direction to a light and the direction to the camera lies inside the specular lobe. For every
// region with a specular lobe and an unknown ρs or α this finds the observations inside the lobe
// of some unshadowed light and, for a region none shows, where a camera would need to stand.
//
// Frames and units: world frame, metres. The lobe test: a pixel shows the highlight of a light
// when tanθh < lobe_tan_factor · α for some unshadowed sample of that light (θh the angle between
// the shading normal and the half vector). α is the region's known roughness (the geometric mean
// of α_x and α_y for anisotropic models) or, when unknown, alpha_assumed.

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "recon/scene.h"
#include "solver/inverse/observations.h"
#include "solver/render/render.h"
#include "tools/common/json.h"

namespace igi::solver {

struct HighlightCoverageOptions {
  double alpha_assumed = 0.1;    // roughness used where the region's α is unknown (lobe width)
  double lobe_tan_factor = 2.0;  // inside the lobe: tanθh < lobe_tan_factor · α
  int light_samples = 16;        // per extended light (sphere, area, emitters) per point
  int candidate_points = 200;    // surface points sampled per unobserved region
  int max_suggestions = 3;       // per unobserved region, best first
  uint64_t seed = 1;             // light and surface sampling (results are deterministic)

  void Validate() const;  // throws igi::Error on a value out of range
};

// One place a camera could stand to see a region's highlight.
struct HighlightSuggestion {
  std::string lighting, light;   // names in the scene
  Eigen::Vector3d position;      // camera centre, world, metres
  Eigen::Vector3d look_at;       // the surface point whose highlight it sees
  double distance_m = 0;         // |position - look_at|
  double highlight_area_m2 = 0;  // estimated region area showing the highlight from there
  std::string text;              // "stand at (x, y, z) m looking at (x, y, z) to see ..."
};

struct RegionHighlightCoverage {
  int region = -1;   // index into Scene::materials
  std::string name;  // the material's name
  double alpha = 0;  // roughness used for the lobe test
  bool alpha_known = false;
  bool observed = false;            // some unshadowed observation lies inside some light's lobe
  int highlight_pixels = 0;         // observations inside the lobe (all photos)
  int observations = 0;             // observations of the region under an analysed lighting
  std::vector<std::string> photos;  // photo files (relative to the scene's folder) showing it
  double min_tan_theta_h_over_alpha = 0;         // closest approach; infinity when none is lit
  std::vector<HighlightSuggestion> suggestions;  // when not observed, best first
};

// For every region whose material has a specular lobe (HasSpecularLobe) and an unknown ρs or
// roughness, in material order. `lighting_scenes[l]` is std::make_unique<RayScene>(scene, l), or
// null for a lighting not photographed (observations under a null lighting are not analysed;
// suggestions use the non-null lightings only).
std::vector<RegionHighlightCoverage> AnalyseHighlightCoverage(
    const recon::Scene& scene, const std::vector<Observation>& observations,
    const std::vector<std::unique_ptr<render::RayScene>>& lighting_scenes,
    const HighlightCoverageOptions& options);

// A JSON array for report.json: one object per region (infinity written as null).
Json HighlightCoverageJson(const std::vector<RegionHighlightCoverage>& coverage);

}  // namespace igi::solver
