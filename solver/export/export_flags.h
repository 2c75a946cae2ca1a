#pragma once
// igi-export's flags, defined once for the executable and for the Python package:
// igi.export's keyword arguments are these flags' names with '_' for '-'.

#include <CLI/CLI.hpp>
#include <string>

#include "solver/export/export.h"

namespace igi::exporter {

struct ExportFlags {
  ExportOptions options;
  std::string format;  // radiance, mitsuba or gltf, as typed
};

// Adds --format, --point-light-radius-m, --source-angle-deg and --mitsuba-spp to `app`.
void AddExportFlags(CLI::App& app, ExportFlags* flags);

// After parsing: the options with the format parsed and everything validated (InputError naming
// the flag).
ExportOptions FinishExportFlags(const ExportFlags& flags);

}  // namespace igi::exporter
