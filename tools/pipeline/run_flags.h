#pragma once
// igi-run's flags, defined once for the executable and for the Python package: igi.run's keyword
// arguments are these flags' names with '_' for '-'.

#include <CLI/CLI.hpp>
#include <filesystem>
#include <string>

#include "tools/pipeline/demo.h"
#include "tools/pipeline/pipeline.h"
#include "tools/pipeline/run_options.h"

namespace igi::pipeline {

struct RunFlags {
  RunOptions run;
  DemoOptions demo_options;
  DemoChoiceFlags demo_choices;  // --demo's choice flags as typed
  bool demo = false;
  std::string scene, camera, colour, lights, bin_dir;
};

// Adds --scene, --demo, --hdr-photos ... --demo-calibration to `app` (not PHOTOS_DIR and --out,
// which the executable takes itself).
void AddRunFlags(CLI::App& app, RunFlags* flags);

// What a run did: the chain's summary, and for --demo the recovered values beside the truth.
struct RunResult {
  RunSummary run;
  bool demo = false;
  Json demo_summary;               // DIR/demo_summary.json (--demo)
  std::vector<std::string> table;  // --demo: region, parameter, truth, recovered, error
};

// Runs the chain (or --demo) for the parsed flags into `out` with `threads` workers (0 = all
// cores); InputError for bad flags or input, nothing written.
RunResult RunFromFlags(const RunFlags& flags, const std::filesystem::path& photos,
                       const std::filesystem::path& out, int threads);

// The summary as JSON: {"stages": [{"stage", "status", "seconds", "cpu_seconds"}], "partial",
// "partial_lines", "report", "solved_scene", "seconds"}.
Json RunSummaryJson(const RunSummary& summary);

}  // namespace igi::pipeline
