#pragma once
// igi-diagnose's flags that set DiagnoseOptions, defined once for the executable and for the
// Python package: igi.diagnose's keyword arguments are these flags' names with '_' for '-'.

#include <CLI/CLI.hpp>

#include "solver/diagnose/diagnose_options.h"

namespace igi::diagnose {

// Adds --spp ... --seed to `app`, writing into `options`.
void AddDiagnoseFlags(CLI::App& app, DiagnoseOptions* options);

// After parsing: the options validated (InputError naming the flag), with the worker threads
// (0 = all cores) and whether a progress bar may be drawn.
DiagnoseOptions FinishDiagnoseFlags(const DiagnoseOptions& options, int threads,
                                    bool show_progress);

}  // namespace igi::diagnose
