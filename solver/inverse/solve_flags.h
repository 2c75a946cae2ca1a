#pragma once
// igi-solve's flags that set SolveOptions, defined once for the executable and for the Python
// package: igi.solve's keyword arguments are these flags' names with '_' for '-'
// (pixel_stride=2 is --pixel-stride 2).

#include <CLI/CLI.hpp>

#include "solver/inverse/solve_options.h"

namespace igi::solver {

struct SolveFlags {
  SolveOptions options;
  SolveChoiceFlags choices;  // the choice flags as typed
};

// Adds --pixel-stride ... --seed to `app`, writing into `flags`.
void AddSolveFlags(CLI::App& app, SolveFlags* flags);

// After parsing: the options with the choices parsed and everything validated (InputError naming
// the flag), the worker threads (0 = all cores) and whether a progress bar may be drawn.
SolveOptions FinishSolveFlags(const SolveFlags& flags, int threads, bool show_progress);

}  // namespace igi::solver
