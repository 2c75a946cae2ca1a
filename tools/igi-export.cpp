// igi-export: writes a solved scene (complete materials) in a format other renderers read —
// RADIANCE (.rad + .vf), Mitsuba 3 (XML + OBJ) or glTF 2.0 (.gltf + .bin) — plus
// export_report.json listing every approximation with its fitted error.
#include <spdlog/spdlog.h>

#include "recon/scene.h"
#include "solver/export/export.h"
#include "tools/common/cli.h"
#include "tools/common/error.h"

int main(int argc, char** argv) {
  CLI::App app{"Export a solved scene to RADIANCE, Mitsuba 3 or glTF 2.0", "igi-export"};
  igi::CommonFlags flags;
  igi::AddCommonFlags(app, &flags, /*computes=*/false);
  std::string scene_path, format_name, out_path;
  igi::exporter::ExportOptions options;
  app.add_option("scene", scene_path, "scene.json with every material value (igi-solve's)")
      ->required();
  app.add_option("--format", format_name, "radiance, mitsuba or gltf")->required();
  app.add_option("--out", out_path, "Output folder (absent or empty)")->required();
  app.add_option("--point-light-radius-m", options.point_light_radius_m,
                 "RADIANCE: radius of the sphere a point/spot light becomes")
      ->capture_default_str();
  app.add_option("--source-angle-deg", options.source_angle_deg,
                 "RADIANCE: apparent diameter of a directional light's source")
      ->capture_default_str();
  app.add_option("--mitsuba-spp", options.mitsuba_spp, "Mitsuba: samples per pixel")
      ->capture_default_str();
  return igi::RunMain(app, flags, argc, argv, [&] {
    const auto format = igi::exporter::ExportFormatFromName(format_name);
    if (!format) {
      throw igi::InputError(
          igi::DescribeProblem("", "--format", format_name, "must be radiance, mitsuba or gltf"));
    }
    options.format = *format;
    options.Validate();
    igi::exporter::CheckExportDir(out_path);
    igi::recon::SceneLoadOptions load;
    load.require_complete_materials = true;
    load.check_images = false;  // photos are not exported; textures are read when written
    const igi::recon::Scene scene = igi::recon::LoadScene(scene_path, load);
    const igi::exporter::ExportReport report = igi::exporter::ExportScene(scene, out_path, options);
    spdlog::info("{} export: {} files, {} approximations (see {}/export_report.json)",
                 igi::exporter::ExportFormatName(*format), report.files.size(),
                 report.approximations.size(), out_path);
    return 0;
  });
}
