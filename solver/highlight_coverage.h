#pragma once
// TEMPORARY stub (the real module comes from the wt-cover branch).
#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "recon/scene.h"
#include "solver/observations.h"
#include "solver/render_internal.h"
#include "tools/common/json.h"

namespace igi {
struct HighlightCoverageOptions {
  double alpha_assumed = 0.1;
  double lobe_tan_factor = 2.0;
  int light_samples = 16;
  void Validate() const {}
};
struct HighlightSuggestion {
  std::string lighting, light;
  Eigen::Vector3d position, look_at;
  double distance_m = 0;
  std::string text;
};
struct RegionHighlightCoverage {
  int region = -1;
  std::string name;
  bool observed = true;
  int highlight_pixels = 0;
  std::vector<std::string> photos;
  double min_tan_theta_h_over_alpha = 0;
  std::vector<HighlightSuggestion> suggestions;
};
inline std::vector<RegionHighlightCoverage> AnalyseHighlightCoverage(
    const Scene&, const std::vector<Observation>&,
    const std::vector<std::unique_ptr<Renderer::Impl>>&, const HighlightCoverageOptions&) {
  return {};
}
inline Json HighlightCoverageJson(const std::vector<RegionHighlightCoverage>&) {
  return Json::array();
}
}  // namespace igi
