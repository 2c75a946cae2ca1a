// igi-export: writes a solved scene (complete materials) in a format other renderers read —
// RADIANCE (.rad + .vf), Mitsuba 3 (XML + OBJ) or glTF 2.0 (.gltf + .bin) — plus
// export_report.json listing every approximation with its fitted error.
#include <spdlog/spdlog.h>

#include "recon/scene.h"
#include "solver/export/export.h"
#include "solver/export/export_flags.h"
#include "tools/common/cli.h"
#include "tools/common/error.h"

int main(int argc, char** argv) {
  CLI::App app{"Export a solved scene to RADIANCE, Mitsuba 3 or glTF 2.0", "igi-export"};
  igi::CommonFlags common;
  igi::AddCommonFlags(app, &common, /*computes=*/false);
  std::string scene_path, out_path;
  igi::exporter::ExportFlags flags;
  app.add_option("scene", scene_path, "scene.json with every material value (igi-solve's)")
      ->required();
  app.add_option("--out", out_path, "Output folder (absent or empty)")->required();
  igi::exporter::AddExportFlags(app, &flags);
  return igi::RunMain(app, common, argc, argv, [&] {
    const igi::exporter::ExportOptions options = igi::exporter::FinishExportFlags(flags);
    igi::exporter::CheckExportDir(out_path);
    igi::recon::SceneLoadOptions load;
    load.require_complete_materials = true;
    load.check_images = false;  // photos are not exported; textures are read when written
    const igi::recon::Scene scene = igi::recon::LoadScene(scene_path, load);
    const igi::exporter::ExportReport report = igi::exporter::ExportScene(scene, out_path, options);
    spdlog::info("{} export: {} files, {} approximations (see {}/export_report.json)",
                 igi::exporter::ExportFormatName(options.format), report.files.size(),
                 report.approximations.size(), out_path);
    return 0;
  });
}
