#include "solver/diagnose/diagnose_options.h"

#include <fmt/format.h>

#include "tools/common/error.h"

namespace igi::diagnose {

void DiagnoseOptions::Validate() const {
  ProblemList problems;
  auto check = [&](bool ok, const char* flag, const std::string& value, const char* rule) {
    if (!ok) problems.Add(DescribeProblem("", flag, value, rule));
  };
  check(spp >= 1 && spp <= 65536, "--spp", std::to_string(spp), "must be in [1, 65536]");
  check(spp_max == -1 || spp_max == 0 || (spp_max >= spp && spp_max <= 65536), "--spp-max",
        std::to_string(spp_max),
        "must be -1 (auto), 0 (the paths fixed at --spp) or in [--spp, 65536]");
  check(render_noise_share > 0 && render_noise_share <= 4, "--render-noise-share",
        fmt::format("{}", render_noise_share), "must be in (0, 4]");
  check(pixel_stride >= 1 && pixel_stride <= 64, "--pixel-stride", std::to_string(pixel_stride),
        "must be in [1, 64]");
  check(max_steps >= 0 && max_steps <= 20, "--max-steps", std::to_string(max_steps),
        "must be in [0, 20]");
  check(analysis_megapixels == 0 || (analysis_megapixels >= 0.01 && analysis_megapixels <= 1000),
        "--analysis-megapixels", fmt::format("{}", analysis_megapixels),
        "must be 0 (full size) or in [0.01, 1000]");
  check(holdout_fraction > 0 && holdout_fraction < 0.9, "--holdout-fraction",
        fmt::format("{}", holdout_fraction), "must be in (0, 0.9)");
  check(holdout_block_px >= 2 && holdout_block_px <= 1024, "--holdout-block-px",
        std::to_string(holdout_block_px), "must be in [2, 1024]");
  check(min_gain >= 0 && min_gain < 1, "--min-gain", fmt::format("{}", min_gain),
        "must be in [0, 1)");
  check(min_z >= 0, "--min-z", fmt::format("{}", min_z), "must be >= 0");
  check(light_samples >= 1 && light_samples <= 256, "--light-samples",
        std::to_string(light_samples), "must be in [1, 256]");
  problems.ThrowIfAny();
  solve.Validate();
}

}  // namespace igi::diagnose
