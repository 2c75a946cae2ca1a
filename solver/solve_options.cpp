#include "solver/solve_options.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "tools/common/error.h"

namespace igi {

int FinalRoundRays(int refine_final_rays, int observations) {
  const double scale = double(kFinalRoundRegionObservations) / std::max(1, observations);
  const double rays = refine_final_rays * std::clamp(scale, 1.0, 8.0);
  return int(std::min(4096.0, std::ceil(rays)));
}

void SolveOptions::Validate() const {
  ProblemList problems;
  auto check = [&](bool ok, const char* flag, const std::string& value, const char* rule) {
    if (!ok) problems.Add(DescribeProblem("", flag, value, rule));
  };
  check(pixel_stride >= 1 && pixel_stride <= 64, "--pixel-stride", std::to_string(pixel_stride),
        "must be in [1, 64]");
  check(memory_budget >= 0, "--memory-budget", fmt::format("{}", memory_budget),
        "must be >= 0 GiB (0 = the machine's memory less a margin)");
  check(max_observations >= 0, "--max-observations", std::to_string(max_observations),
        "must be >= 0 (0 = as many as the memory budget allows)");
  check(max_observation_block >= 1 && max_observation_block <= 64, "--max-observation-block",
        std::to_string(max_observation_block), "must be in [1, 64]");
  check(saturation >= 0, "--saturation", fmt::format("{}", saturation), "must be >= 0 (0 = auto)");
  check(patch_size_m >= 0, "--patch-size-m", fmt::format("{}", patch_size_m),
        "must be >= 0 (0 = auto)");
  check(light_samples >= 1 && light_samples <= 1024, "--light-samples",
        std::to_string(light_samples), "must be in [1, 1024]");
  check(indirect_rays >= 0 && indirect_rays <= 4096, "--indirect-rays",
        std::to_string(indirect_rays), "must be in [0, 4096]");
  check(smoothing_radius_m >= 0, "--smoothing-radius-m", fmt::format("{}", smoothing_radius_m),
        "must be >= 0 (0 = auto)");
  check(smoothing_accuracy >= 0 && smoothing_accuracy <= 10, "--smoothing-accuracy",
        fmt::format("{}", smoothing_accuracy), "must be in [0, 10] (0 = a fixed radius)");
  check(max_iterations >= 1 && max_iterations <= 100, "--max-iterations",
        std::to_string(max_iterations), "must be in [1, 100]");
  check(tolerance > 0 && tolerance < 1, "--tolerance", fmt::format("{}", tolerance),
        "must be in (0, 1)");
  check(specular_colour == "grey" || specular_colour == "rgb", "--specular-colour", specular_colour,
        "must be grey or rgb");
  check(albedo_maps == "auto" || albedo_maps == "all" || albedo_maps == "none", "--albedo-maps",
        albedo_maps, "must be auto, all or none");
  check(albedo_map_pass == "auto" || albedo_map_pass == "always" || albedo_map_pass == "never",
        "--albedo-map-pass", albedo_map_pass, "must be auto, always or never");
  check(texel_size_m >= 0, "--texel-size-m", fmt::format("{}", texel_size_m),
        "must be >= 0 (0 = auto)");
  check(max_highlight_samples >= 1, "--max-highlight-samples",
        std::to_string(max_highlight_samples), "must be >= 1");
  check(max_fit_samples >= 3, "--max-fit-samples", std::to_string(max_fit_samples), "must be >= 3");
  check(refine_iterations >= 0 && refine_iterations <= 20, "--refine-iterations",
        std::to_string(refine_iterations), "must be in [0, 20]");
  check(refine_rays >= 1 && refine_rays <= 4096, "--refine-rays", std::to_string(refine_rays),
        "must be in [1, 4096]");
  check(refine_final_rays >= 1 && refine_final_rays <= 4096, "--refine-final-rays",
        std::to_string(refine_final_rays), "must be in [1, 4096]");
  check(refine_albedo_step > 0 && refine_albedo_step <= 1, "--refine-albedo-step",
        std::to_string(refine_albedo_step), "must be in (0, 1]");
  check(
      refine_update == "joint" || refine_update == "joint_albedo" || refine_update == "independent",
      "--refine-update", refine_update, "must be joint, joint_albedo or independent");
  check(photo_scale == "given" || photo_scale == "solve", "--photo-scale", photo_scale,
        "must be given or solve");
  check(holdout_fraction >= 0 && holdout_fraction < 1, "--holdout-fraction",
        fmt::format("{}", holdout_fraction), "must be in [0, 1)");
  check(holdout_block_px >= 1, "--holdout-block-px", std::to_string(holdout_block_px),
        "must be >= 1");
  problems.ThrowIfAny();
}

}  // namespace igi
