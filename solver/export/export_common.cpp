#include "solver/export/export_common.h"

#include <fmt/format.h>

#include <cmath>
#include <map>

#include "tools/common/atomic_file.h"
#include "tools/common/image.h"

namespace igi::exporter::internal {

std::string SafeName(std::string_view name) {
  std::string out(name);
  for (char& c : out) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                    c == '_' || c == '.' || c == '-';
    if (!ok) c = '_';
  }
  return out.empty() ? std::string("_") : out;
}

std::vector<RegionMesh> SplitByRegion(const recon::TriangleMesh& mesh) {
  std::vector<RegionMesh> regions(mesh.region_names.size());
  std::vector<std::map<int, int>> remap(regions.size());
  for (size_t t = 0; t < mesh.num_triangles(); ++t) {
    const int r = mesh.triangle_region[t];
    RegionMesh& out = regions[r];
    Eigen::Vector3i tri;
    for (int k = 0; k < 3; ++k) {
      const int v = mesh.triangles[t][k];
      auto [it, added] = remap[r].emplace(v, int(out.positions.size()));
      if (added) {
        out.positions.push_back(mesh.positions[v]);
        out.normals.push_back(mesh.normals[v]);
        if (mesh.has_uvs()) out.uvs.push_back(mesh.uvs[v]);
      }
      tri[k] = it->second;
    }
    out.triangles.push_back(tri);
  }
  return regions;
}

RegionMesh WholeMesh(const recon::TriangleMesh& mesh) {
  return {mesh.positions, mesh.normals, mesh.uvs, mesh.triangles};
}

std::string ObjText(const RegionMesh& mesh) {
  std::string text = "# written by igi-export\n";
  for (const auto& p : mesh.positions) text += fmt::format("v {} {} {}\n", p.x(), p.y(), p.z());
  for (const auto& uv : mesh.uvs) text += fmt::format("vt {} {}\n", uv.x(), uv.y());
  for (const auto& n : mesh.normals) text += fmt::format("vn {} {} {}\n", n.x(), n.y(), n.z());
  const bool uvs = !mesh.uvs.empty();
  for (const auto& t : mesh.triangles) {
    text += "f";
    for (int k = 0; k < 3; ++k) {
      const int i = t[k] + 1;
      text += uvs ? fmt::format(" {}/{}/{}", i, i, i) : fmt::format(" {}//{}", i, i);
    }
    text += "\n";
  }
  return text;
}

render::BrdfParams ParamsOf(const recon::Material& material) {
  render::BrdfParams p;
  p.model = material.brdf;
  p.rho_d = RegionRhoD(material);
  if (material.rho_s) p.rho_s = *material.rho_s;
  if (material.alpha) p.alpha = *material.alpha;
  if (material.alpha_x) p.alpha_x = *material.alpha_x;
  if (material.alpha_y) p.alpha_y = *material.alpha_y;
  p.ior = material.ior.value_or(recon::Material::kDefaultIor);
  p.diffuse = material.diffuse;
  p.sigma = material.sigma.value_or(0.0);
  return p;
}

Eigen::Vector3d RegionRhoD(const recon::Material& material) {
  if (material.rho_d) return *material.rho_d;
  if (!material.rho_d_map) return Eigen::Vector3d::Zero();
  const Image image = ReadImage(*material.rho_d_map, 3);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (size_t i = 0; i + 2 < image.pixels.size(); i += 3) {
    sum += Eigen::Vector3d(image.pixels[i], image.pixels[i + 1], image.pixels[i + 2]);
  }
  const double n = double(image.width) * image.height;
  return n > 0 ? Eigen::Vector3d(sum / n) : Eigen::Vector3d::Zero();
}

LobeFit FitAndReport(const recon::Material& material, const LobeFitOptions& options,
                     std::string_view target_label, ExportReport* report) {
  const render::BrdfParams params = ParamsOf(material);
  const LobeFit fit = FitSpecularLobe(params, options);
  std::string how = fmt::format(
      "{} specular lobe fitted by {} (least squares of f cos(i) cos(o), view angles up to {} "
      "deg): alpha {:.6g}, scale {:.6g}; relative error {:.3g} (up to 88 deg: {:.3g})",
      recon::BrdfModelName(material.brdf), target_label, options.max_theta_o_deg, fit.alpha,
      fit.scale, fit.relative_error, fit.relative_error_to_88deg);
  if (recon::IsAnisotropic(material.brdf)) how += "; anisotropy dropped (isotropic fit)";
  if (recon::HasFresnel(material.brdf)) how += "; igi's Schlick weight folded into the fit";
  report->Add("materials." + material.name, how, fit.relative_error);
  return fit;
}

void ReportDiffuseShape(const recon::Material& material, std::string_view target,
                        ExportReport* report) {
  if (material.diffuse == recon::DiffuseShape::kCoated) {
    report->Add("materials." + material.name,
                fmt::format("coated diffuse written as {}'s Lambertian diffuse with the same "
                            "rho_d: the coat's transmittances T(cos theta_i)·T(cos theta_o) are "
                            "left out (each {:.4g} on average over the hemisphere)",
                            target, render::kMeanCoatTransmission),
                1.0 - render::kMeanCoatTransmission * render::kMeanCoatTransmission);
    return;
  }
  if (material.diffuse != recon::DiffuseShape::kOrenNayar) return;
  const double sigma = material.sigma.value_or(0.0);
  report->Add(
      "materials." + material.name,
      fmt::format("oren_nayar diffuse (sigma {:.4g}) written as {}'s Lambertian diffuse "
                  "with the same rho_d: {} has no rough-diffuse model (Oren-Nayar's A "
                  "{:.4g}, B {:.4g} left out)",
                  sigma, target, target, render::OrenNayarA(sigma), render::OrenNayarB(sigma)),
      1.0 - render::OrenNayarA(sigma));
}

void WriteText(const std::filesystem::path& dir, const std::string& relative,
               const std::string& text, ExportReport* report) {
  std::filesystem::create_directories((dir / relative).parent_path());
  WriteFileAtomic(dir / relative, text);
  report->files.push_back(relative);
}

std::string Num(double value) {
  if (value == 0) return "0";
  return fmt::format("{:.9g}", value);
}

}  // namespace igi::exporter::internal
