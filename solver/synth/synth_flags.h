#pragma once
// igi-synth's flags, defined once for the executable and for the Python package:
// igi.synth.synthesize's keyword arguments are these flags' names with '_' for '-'.

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "solver/synth/synth_options.h"

namespace igi::synth {

// The flags as typed, where they are text that FinishSynthFlags parses.
struct SynthFlags {
  SynthOptions options;
  SynthChoiceFlags choices;
  std::string noise = "none", response = "gamma", unknowns = "rho_d,rho_s,alpha";
  std::string photo_lightings = "L0", validation_lightings = "L1", lamp_position;
  std::vector<std::string> effects;
};

// Adds --out ... --effect to `app`, writing into `flags`.
void AddSynthFlags(CLI::App& app, SynthFlags* flags);

// After parsing: the options with every text flag parsed and everything validated (InputError
// listing each problem, naming the flag), with the worker threads (0 = all cores).
SynthOptions FinishSynthFlags(const SynthFlags& flags, int threads);

}  // namespace igi::synth
