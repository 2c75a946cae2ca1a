#pragma once
// Exports a solved scene (every material value present: LoadScene with
// SceneLoadOptions::require_complete_materials) to formats other renderers read:
//   radiance  RADIANCE scene description: scene.rad (materials + one polygon per triangle,
//             grouped per region), lighting_<L>.rad per lighting, <camera>.vf per camera;
//   mitsuba   Mitsuba 3 XML: scene_<L>.xml per lighting (all cameras as sensors), meshes/*.obj,
//             textures/*.exr;
//   gltf      glTF 2.0: scene.gltf + scene.bin (+ textures/*.png), every light through
//             KHR_lights_punctual (lightings listed in the asset's extras).
// Every export also writes export_report.json (ExportReport::ToJson): the files written and every
// approximation made, with the fitted relative error where one was fitted (solver/export/
// ward_fit.h). Each writer's header documents its mapping.
//
// Nothing is written on bad input: the output folder must be absent or empty; everything is
// written into a temporary sibling folder that is renamed into place at the end.

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "recon/scene.h"
#include "tools/common/json.h"

namespace igi::exporter {

enum class ExportFormat { kRadiance, kMitsuba, kGltf };
std::string_view ExportFormatName(ExportFormat format);
// "radiance", "mitsuba", "gltf"; nullopt for anything else.
std::optional<ExportFormat> ExportFormatFromName(std::string_view name);

struct ExportOptions {
  // The target: radiance, mitsuba or gltf (see the top of this file).
  ExportFormat format = ExportFormat::kGltf;
  // RADIANCE: radius (metres) of the small emitting sphere a point or spot light becomes.
  double point_light_radius_m = 0.01;
  // RADIANCE: apparent diameter (degrees) of the `source` a directional light becomes.
  double source_angle_deg = 0.533;
  // Mitsuba: samples per pixel of the sensors' sampler.
  int mitsuba_spp = 256;

  // Throws InputError naming the bad field.
  void Validate() const;
};

// One approximation made by an export: what (a key path of scene.json, e.g. "materials.box"),
// how, and the fitted relative error when one was measured.
struct Approximation {
  std::string item;
  std::string description;
  std::optional<double> relative_error;
};

struct ExportReport {
  ExportFormat format = ExportFormat::kGltf;
  std::vector<std::string> files;  // relative to the output folder, in writing order
  std::vector<Approximation> approximations;

  // Records an approximation (an identical item + description is recorded once).
  void Add(std::string item, std::string description,
           std::optional<double> relative_error = std::nullopt);
  // {"format": "igi-export-report", "version": 1, "target", "files", "approximations"}.
  Json ToJson() const;
};

// InputError unless `out_dir` is absent or an empty folder.
void CheckExportDir(const std::filesystem::path& out_dir);

// Checks that every material of `scene` is complete (InputError listing every missing value).
void CheckExportableScene(const recon::Scene& scene);

// Writes the export of `scene` into `out_dir` (see the top of this file) and returns its report
// (also written as out_dir/export_report.json).
ExportReport ExportScene(const recon::Scene& scene, const std::filesystem::path& out_dir,
                         const ExportOptions& options);

}  // namespace igi::exporter
