#pragma once
// igi-run's report (DIR/report.html): one self-contained page built from the stage folders —
// stage table, response curves, registered cameras, parameter table with uncertainties, photo /
// re-render / residual, relit renders under every lighting, and the diagnosis steps.

#include <filesystem>

#include "tools/common/json.h"

namespace igi::pipeline {

struct RunReportInputs {
  std::filesystem::path out;  // the run's DIR (stage folders under it)
  int max_photos = 4;         // photos shown with their re-render (renders/photo_K.exr)
  // Per format ("radiance", "mitsuba", "gltf"): {"dir": folder relative to the run's DIR} or
  // {"error": the line igi-export failed with}.
  Json exports = Json::object();
};

// Builds DIR/report.html from what the stages left (absent parts are named, not fatal).
void WriteRunReport(const RunReportInputs& in);

}  // namespace igi::pipeline
