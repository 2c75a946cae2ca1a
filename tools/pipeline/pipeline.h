#pragma once
// igi-run's chain (docs/run.md): response -> HDR -> registration -> solve -> diagnose ->
// report, each stage in its own folder of RunOptions::out with a marker (stage_marker.h), so a
// rerun resumes from the first unfinished stage and redoes a stage whose inputs changed.
//
//   DIR/01-response/  response.json (igi-calib response on the longest LDR bracket)
//   DIR/02-hdr/       NAME.exr, NAME_mask.png per photo (igi-hdr)
//   DIR/03-register/  images/NAME.png (tone-mapped), register/ (igi-register --out),
//                     scene.json (the solvable scene: registered cameras, HDR photos)
//   DIR/04-solve/     igi-solve --out (scene.json, report.json, report.html, albedo/)
//   DIR/05-diagnose/  igi-diagnose --out (diagnosis.json, scene.json, report.html)
//   DIR/06-report/    renders/ (igi-render: photo re-renders, relit renders)
//   DIR/report.html   the run's report (run_report.h)
// Each stage folder has log.txt (the tools' output) and stage.json (the marker).

#include <filesystem>
#include <string>
#include <vector>

#include "tools/pipeline/run_options.h"

namespace igi::pipeline {

struct StageOutcome {
  std::string stage;   // "04-solve"
  std::string status;  // "done", "partial", "skipped" (does not apply) or "kept" (resumed)
  double seconds = 0;  // this run's time (0 for kept stages)
  // CPU time (user + sys) of igi-run and the tools it ran during the stage (0 for kept stages):
  // what the stage costs on a shared machine, where wall time is only an upper bound.
  double cpu_seconds = 0;
};

struct RunSummary {
  std::vector<StageOutcome> stages;
  bool partial = false;  // some stage exited 3 (e.g. photos that did not register)
  std::vector<std::string> partial_lines;
  std::filesystem::path report;  // DIR/report.html
  std::filesystem::path solved_scene;
  double seconds = 0;
};

// User + sys CPU seconds of this process and of its children it has waited for (getrusage).
double ProcessCpuSeconds();

// The stage folders, in order.
const std::vector<std::string>& StageNames();

// Validates everything before writing (InputError: exit 2, nothing written), then runs or resumes
// the stages. A failing stage throws igi::Error naming it (exit 1); finished stages are kept.
RunSummary RunPipeline(const RunOptions& options);

}  // namespace igi::pipeline
