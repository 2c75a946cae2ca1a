#include "solver/export/export_flags.h"

#include "tools/common/error.h"

namespace igi::exporter {

void AddExportFlags(CLI::App& app, ExportFlags* flags) {
  ExportOptions& options = flags->options;
  app.add_option("--format", flags->format, "radiance, mitsuba or gltf")->required();
  app.add_option("--point-light-radius-m", options.point_light_radius_m,
                 "RADIANCE: radius of the sphere a point/spot light becomes")
      ->capture_default_str();
  app.add_option("--source-angle-deg", options.source_angle_deg,
                 "RADIANCE: apparent diameter of a directional light's source")
      ->capture_default_str();
  app.add_option("--mitsuba-spp", options.mitsuba_spp, "Mitsuba: samples per pixel")
      ->capture_default_str();
}

ExportOptions FinishExportFlags(const ExportFlags& flags) {
  const std::optional<ExportFormat> format = ExportFormatFromName(flags.format);
  if (!format) {
    throw InputError(
        DescribeProblem("", "--format", flags.format, "must be radiance, mitsuba or gltf"));
  }
  ExportOptions options = flags.options;
  options.format = *format;
  options.Validate();
  return options;
}

}  // namespace igi::exporter
