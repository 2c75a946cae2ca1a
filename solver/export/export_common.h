#pragma once
// Helpers shared by the writers of solver/export/ (not part of the public API): safe names,
// per-region sub-meshes, OBJ output, region albedos and the Ward lobe conversions with their
// report lines.

#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "recon/scene.h"
#include "solver/export/export.h"
#include "solver/export/ward_fit.h"
#include "solver/render/brdf.h"

namespace igi::exporter::internal {

// `name` with every character outside [A-Za-z0-9_.-] replaced by '_' (RADIANCE identifiers,
// file names, XML ids).
std::string SafeName(std::string_view name);

// A region's triangles as a standalone mesh (vertices compacted; normals and UVs kept).
struct RegionMesh {
  std::vector<Eigen::Vector3f> positions, normals;
  std::vector<Eigen::Vector2f> uvs;  // empty = none
  std::vector<Eigen::Vector3i> triangles;
};
// One RegionMesh per region of `mesh` (index = region); regions without triangles are empty.
std::vector<RegionMesh> SplitByRegion(const recon::TriangleMesh& mesh);
RegionMesh WholeMesh(const recon::TriangleMesh& mesh);

// Wavefront OBJ with v/vt/vn (vt as stored: u right, v up).
std::string ObjText(const RegionMesh& mesh);

// The material as BrdfParams (absent values zero / 0.1).
render::BrdfParams ParamsOf(const recon::Material& material);
// The region's diffuse albedo: rho_d, or the mean of rho_d_map when only the map is given.
Eigen::Vector3d RegionRhoD(const recon::Material& material);

// Fits the material's specular lobe to `target` and records the approximation in `report`
// under "materials.<name>" with the fitted error.
LobeFit FitAndReport(const recon::Material& material, const LobeFitOptions& options,
                     std::string_view target_label, ExportReport* report);

// Records that `material`'s Oren–Nayar diffuse term (if it has one) is written as Lambert's with
// the same ρd, which none of the targets can do otherwise; the error given is 1 − A(σ), the
// darkening at normal viewing the written model leaves out (toward grazing views and
// back-scatter Oren–Nayar's albedo rises back toward ρd). A coated diffuse term is written the
// same way, its error 1 − (20/21)², the mean of the coat's two transmittances left out.
void ReportDiffuseShape(const recon::Material& material, std::string_view target,
                        ExportReport* report);

// Writes `text` to dir/relative and records the file in the report.
void WriteText(const std::filesystem::path& dir, const std::string& relative,
               const std::string& text, ExportReport* report);

// printf-like number for text formats: up to 9 significant digits, no trailing zeros.
std::string Num(double value);

}  // namespace igi::exporter::internal
