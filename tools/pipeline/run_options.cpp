#include "tools/pipeline/run_options.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "tools/common/error.h"

namespace igi::pipeline {

void RunOptions::Validate() const {
  ProblemList problems;
  if (scene.empty()) problems.Add("", "--scene", "", "is required");
  if (out.empty()) problems.Add("", "--out", "", "is required");
  if (photos_dir.empty() && !hdr_photos) {
    problems.Add("", "PHOTOS_DIR", "", "is required (unless --hdr-photos)");
  }
  if (report_spp < 1) problems.Add("", "--report-spp", std::to_string(report_spp), "must be >= 1");
  if (report_photos < 1) {
    problems.Add("", "--report-photos", std::to_string(report_photos), "must be >= 1");
  }
  if (report_lightings < 1) {
    problems.Add("", "--report-lightings", std::to_string(report_lightings), "must be >= 1");
  }
  if (!(report_megapixels == 0 || (report_megapixels >= 0.001 && report_megapixels <= 1000))) {
    problems.Add("", "--report-megapixels", fmt::format("{}", report_megapixels),
                 "must be 0 or in [0.001, 1000]");
  }
  if (diagnose_spp < 0) {
    problems.Add("", "--diagnose-spp", std::to_string(diagnose_spp), "must be >= 0");
  }
  if (!(radiance_scale > 0) || !std::isfinite(radiance_scale)) {
    problems.Add("", "--radiance-scale", std::to_string(radiance_scale), "must be > 0 and finite");
  }
  const std::vector<std::string> stages = {"",         "01-response", "02-hdr",   "03-register",
                                           "04-solve", "05-diagnose", "06-report"};
  if (std::find(stages.begin(), stages.end(), stop_after) == stages.end()) {
    problems.Add("", "stop_after", stop_after, "must name a stage (01-response ... 06-report)");
  }
  if (num_threads < 0) problems.Add("", "--threads", std::to_string(num_threads), "must be >= 0");
  problems.ThrowIfAny();
}

}  // namespace igi::pipeline
