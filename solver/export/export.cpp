#include "solver/export/export.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <system_error>

#include "solver/export/export_gltf.h"
#include "solver/export/export_mitsuba.h"
#include "solver/export/export_radiance.h"
#include "tools/common/enum_names.h"
#include "tools/common/error.h"
#include "tools/common/strings.h"

namespace igi::exporter {

constexpr EnumNames<ExportFormat, 3> kExportFormatNames{{{ExportFormat::kRadiance, "radiance"},
                                                         {ExportFormat::kMitsuba, "mitsuba"},
                                                         {ExportFormat::kGltf, "gltf"}}};

std::string_view ExportFormatName(ExportFormat format) { return kExportFormatNames.Name(format); }
std::optional<ExportFormat> ExportFormatFromName(std::string_view name) {
  return kExportFormatNames.FromName(name);
}

void ExportOptions::Validate() const {
  ProblemList problems;
  if (!(point_light_radius_m > 0) || !std::isfinite(point_light_radius_m)) {
    problems.Add("", "--point-light-radius-m", std::to_string(point_light_radius_m),
                 "must be a finite number > 0");
  }
  if (!(source_angle_deg > 0 && source_angle_deg < 180)) {
    problems.Add("", "--source-angle-deg", std::to_string(source_angle_deg), "must be in (0, 180)");
  }
  if (mitsuba_spp < 1) {
    problems.Add("", "--mitsuba-spp", std::to_string(mitsuba_spp), "must be >= 1");
  }
  problems.ThrowIfAny();
}

void ExportReport::Add(std::string item, std::string description,
                       std::optional<double> relative_error) {
  for (const Approximation& a : approximations) {
    if (a.item == item && a.description == description) return;
  }
  approximations.push_back({std::move(item), std::move(description), relative_error});
}

Json ExportReport::ToJson() const {
  Json j;
  j["format"] = "igi-export-report";
  j["version"] = 1;
  j["target"] = std::string(ExportFormatName(format));
  j["files"] = files;
  Json list = Json::array();
  for (const Approximation& a : approximations) {
    Json item;
    item["item"] = a.item;
    item["description"] = a.description;
    item["relative_error"] = a.relative_error ? Json(*a.relative_error) : Json(nullptr);
    list.push_back(item);
  }
  j["approximations"] = list;
  return j;
}

void CheckExportDir(const std::filesystem::path& out_dir) {
  std::error_code ec;
  if (!std::filesystem::exists(out_dir, ec)) return;
  if (!std::filesystem::is_directory(out_dir, ec)) {
    throw InputError(DescribeProblem(out_dir.string(), "--out", "", "exists and is not a folder"));
  }
  if (!std::filesystem::is_empty(out_dir, ec)) {
    throw InputError(
        DescribeProblem(out_dir.string(), "--out", "", "folder exists and is not empty"));
  }
}

void CheckExportableScene(const recon::Scene& scene) {
  ProblemList problems;
  for (const recon::Material& m : scene.materials) {
    const auto missing = m.MissingForRendering();
    if (!missing.empty()) {
      problems.Add(scene.file.string(), "materials." + m.name, Join(missing, ", "),
                   "missing: exporting needs complete materials (run igi-solve first)");
    }
  }
  problems.ThrowIfAny();
}

ExportReport ExportScene(const recon::Scene& scene, const std::filesystem::path& out_dir,
                         const ExportOptions& options) {
  options.Validate();
  CheckExportableScene(scene);
  CheckExportDir(out_dir);
  const std::filesystem::path final_dir = std::filesystem::absolute(out_dir).lexically_normal();
  const std::filesystem::path tmp_dir =
      final_dir.parent_path() /
      fmt::format(".{}.tmp{}", final_dir.filename().string(), ::getpid());
  std::filesystem::remove_all(tmp_dir);
  std::filesystem::create_directories(tmp_dir);
  ExportReport report;
  report.format = options.format;
  try {
    switch (options.format) {
      case ExportFormat::kRadiance:
        WriteRadianceExport(scene, options, tmp_dir, &report);
        break;
      case ExportFormat::kMitsuba:
        WriteMitsubaExport(scene, options, tmp_dir, &report);
        break;
      case ExportFormat::kGltf:
        WriteGltfExport(scene, options, tmp_dir, &report);
        break;
    }
    report.files.push_back("export_report.json");
    WriteJsonFile(tmp_dir / "export_report.json", report.ToJson(), 1);
    std::error_code ec;
    std::filesystem::remove(final_dir, ec);  // an empty folder (CheckExportDir) or nothing
    std::filesystem::rename(tmp_dir, final_dir);
  } catch (...) {
    std::error_code ec;
    std::filesystem::remove_all(tmp_dir, ec);
    throw;
  }
  spdlog::info("exported {} files to {} ({} approximations)", report.files.size(),
               final_dir.string(), report.approximations.size());
  return report;
}

}  // namespace igi::exporter
