#include "solver/export/export_mitsuba.h"

#include <fmt/format.h>

#include <cmath>

#include "solver/export/export_common.h"
#include "tools/common/image.h"

namespace igi::exporter {
namespace {

using internal::Num;
using internal::SafeName;

std::string Rgb(const std::string& name, const Eigen::Vector3d& v) {
  return fmt::format("<rgb name=\"{}\" value=\"{}, {}, {}\"/>", name, Num(v.x()), Num(v.y()),
                     Num(v.z()));
}
std::string Point(const std::string& tag, const std::string& name, const Eigen::Vector3d& v) {
  return fmt::format("<{} name=\"{}\" x=\"{}\" y=\"{}\" z=\"{}\"/>", tag, name, Num(v.x()),
                     Num(v.y()), Num(v.z()));
}
std::string Float(const std::string& name, double v) {
  return fmt::format("<float name=\"{}\" value=\"{}\"/>", name, Num(v));
}
std::string LookAt(const Eigen::Vector3d& origin, const Eigen::Vector3d& target,
                   const Eigen::Vector3d& up) {
  auto csv = [](const Eigen::Vector3d& v) {
    return Num(v.x()) + ", " + Num(v.y()) + ", " + Num(v.z());
  };
  return fmt::format(
      "<transform name=\"to_world\"><lookat origin=\"{}\" target=\"{}\" up=\"{}\"/></transform>",
      csv(origin), csv(target), csv(up));
}

// The diffuse reflectance: a bitmap of rho_d_map (written as EXR) or an rgb value.
std::string DiffuseValue(const recon::Material& m, const std::string& name,
                         const std::filesystem::path& dir, ExportReport* report) {
  if (!m.rho_d_map) return Rgb(name, internal::RegionRhoD(m));
  const std::string relative = "textures/" + SafeName(m.name) + ".exr";
  std::filesystem::create_directories(dir / "textures");
  Image image = ReadImage(*m.rho_d_map, 3);
  image.metadata.clear();
  WriteImageOptions write;
  write.type = PixelType::kFloat;
  write.compression = "zip";
  WriteImage(dir / relative, image, write);
  report->files.push_back(relative);
  return fmt::format(
      "<texture type=\"bitmap\" name=\"{}\"><string name=\"filename\" value=\"{}\"/>"
      "<boolean name=\"raw\" value=\"true\"/></texture>",
      name, relative);
}

std::string BsdfText(const recon::Material& m, const std::filesystem::path& dir,
                     ExportReport* report) {
  const std::string id = SafeName(m.name);
  internal::ReportDiffuseShape(m, "Mitsuba 3", report);
  std::string inner;
  if (m.brdf == recon::BrdfModel::kEmitter || m.brdf == recon::BrdfModel::kBlack) {
    inner = "<bsdf type=\"diffuse\">" + Rgb("reflectance", Eigen::Vector3d::Zero()) + "</bsdf>";
  } else if (!recon::HasSpecularLobe(m.brdf) || !(m.rho_s->mean() > 0)) {
    inner = "<bsdf type=\"diffuse\">" + DiffuseValue(m, "reflectance", dir, report) + "</bsdf>";
  } else {
    const double f0 = std::clamp(m.rho_s->mean(), 1e-4, 0.5);
    const double eta = (1 + std::sqrt(f0)) / (1 - std::sqrt(f0));
    // GGX lobes keep their distribution; Ward's and Beckmann's lobes take Beckmann's.
    const bool ggx = recon::Lobe(m.brdf) == recon::LobeShape::kGgx;
    const std::string distribution = ggx ? "ggx" : "beckmann";
    LobeFitOptions options;
    options.target = ggx ? LobeTarget::kGgxDielectric : LobeTarget::kBeckmannDielectric;
    options.target_ior = eta;
    const LobeFit fit =
        internal::FitAndReport(m, options, "Mitsuba roughplastic (" + distribution + ")", report);
    report->Add("materials." + m.name,
                "roughplastic's diffuse term carries Fresnel transmittances and internal "
                "reflection: diffuse_reflectance = rho_d is not compensated");
    const Eigen::Vector3d spec = fit.scale * *m.rho_s / m.rho_s->mean();
    inner = "<bsdf type=\"roughplastic\"><string name=\"distribution\" value=\"" + distribution +
            "\"/>" + Float("alpha", fit.alpha) + Float("int_ior", eta) + Float("ext_ior", 1.0) +
            "<boolean name=\"nonlinear\" value=\"false\"/>" +
            DiffuseValue(m, "diffuse_reflectance", dir, report) +
            Rgb("specular_reflectance", spec) + "</bsdf>";
  }
  return fmt::format("  <!-- {} ({}) -->\n  <bsdf type=\"twosided\" id=\"bsdf.{}\">{}</bsdf>\n",
                     m.name, recon::BrdfModelName(m.brdf), id, inner);
}

std::string SensorText(const recon::Camera& camera, int spp, ExportReport* report) {
  const Eigen::Matrix3d world_from_cam =
      camera.cam_from_world.rotation.toRotationMatrix().transpose();
  const Eigen::Vector3d c = camera.CenterInWorld();
  const double fov = 2 * std::atan(camera.width / (2 * camera.focal_x_px())) * 180 / render::kPi;
  if (camera.model == recon::CameraModel::kOpenCv ||
      std::abs(camera.focal_x_px() - camera.focal_y_px()) > 1e-6 * camera.focal_x_px()) {
    report->Add("cameras." + camera.name,
                "Mitsuba perspective has one focal length and no distortion: fy and lens "
                "distortion dropped");
  }
  if (std::abs(camera.principal_x_px() - 0.5 * camera.width) > 1e-6 ||
      std::abs(camera.principal_y_px() - 0.5 * camera.height) > 1e-6) {
    report->Add("cameras." + camera.name,
                "principal point written as principal_point_offset_x/y = (cx - W/2)/W, "
                "(cy - H/2)/H (film fractions; sign convention not checked against a Mitsuba "
                "render)");
  }
  return fmt::format(
      "  <!-- camera {} -->\n  <sensor type=\"perspective\" id=\"{}\">\n"
      "    <string name=\"fov_axis\" value=\"x\"/>{}{}{}{}\n    {}\n"
      "    <sampler type=\"independent\"><integer name=\"sample_count\" value=\"{}\"/></sampler>\n"
      "    <film type=\"hdrfilm\"><integer name=\"width\" value=\"{}\"/><integer name=\"height\" "
      "value=\"{}\"/><rfilter type=\"box\"/></film>\n  </sensor>\n",
      camera.name, SafeName(camera.name), Float("fov", fov), Float("near_clip", 0.01),
      Float("principal_point_offset_x",
            (camera.principal_x_px() - 0.5 * camera.width) / camera.width),
      Float("principal_point_offset_y",
            (camera.principal_y_px() - 0.5 * camera.height) / camera.height),
      LookAt(c, c + world_from_cam.col(2), -world_from_cam.col(1)), spp, camera.width,
      camera.height);
}

// The 90% and 10% angles (degrees, at most 90) of a spot profile.
double SpotAngleDeg(const recon::SpotProfile& profile, double fraction) {
  const double axis = profile.Relative(0, 0);
  for (double deg = 0.05; deg < 90; deg += 0.05) {
    if (profile.Relative(deg * render::kPi / 180, 0) < fraction * axis) return deg;
  }
  return 90;
}

std::string EmitterText(const recon::Light& light, ExportReport* report) {
  const std::string item = "lights." + light.name;
  switch (light.type) {
    case recon::LightType::kPoint:
      return "  <emitter type=\"point\" id=\"" + SafeName(light.name) + "\">" +
             Point("point", "position", light.position) + Rgb("intensity", light.intensity) +
             "</emitter>\n";
    case recon::LightType::kSpot: {
      const recon::SpotProfile& p = light.profile;
      if (p.kind == recon::SpotProfile::Kind::kNone) {
        return "  <emitter type=\"point\" id=\"" + SafeName(light.name) + "\">" +
               Point("point", "position", light.position) + Rgb("intensity", light.intensity) +
               "</emitter>\n";
      }
      double beam = SpotAngleDeg(p, 0.9), cutoff = SpotAngleDeg(p, 0.1);
      if (p.kind == recon::SpotProfile::Kind::kCone) beam = p.inner_deg, cutoff = p.outer_deg;
      report->Add(item, "spot profile as Mitsuba's spot (beam_width " + Num(beam) +
                            " deg, cutoff_angle " + Num(cutoff) + " deg, its own falloff)");
      const Eigen::Vector3d up = FrameFromAxis(light.direction).col(0);
      return "  <emitter type=\"spot\" id=\"" + SafeName(light.name) + "\">" +
             Rgb("intensity", light.intensity) + Float("beam_width", std::min(beam, cutoff)) +
             Float("cutoff_angle", cutoff) +
             LookAt(light.position, light.position + light.direction, up) + "</emitter>\n";
    }
    case recon::LightType::kDirectional:
      return "  <emitter type=\"directional\" id=\"" + SafeName(light.name) + "\">" +
             Point("vector", "direction", light.direction) + Rgb("irradiance", light.irradiance) +
             "</emitter>\n";
    case recon::LightType::kSphere:
      return "  <shape type=\"sphere\" id=\"" + SafeName(light.name) + "\">" +
             Point("point", "center", light.center) + Float("radius", light.radius) +
             "<bsdf type=\"diffuse\">" + Rgb("reflectance", Eigen::Vector3d::Zero()) +
             "</bsdf><emitter type=\"area\">" + Rgb("radiance", light.radiance) +
             "</emitter></shape>\n";
    case recon::LightType::kAmbient:
      return "  <emitter type=\"constant\" id=\"" + SafeName(light.name) + "\">" +
             Rgb("radiance", light.radiance) + "</emitter>\n";
    case recon::LightType::kArea:
      return "  <shape type=\"obj\" id=\"" + SafeName(light.name) +
             "\"><string name=\"filename\" value=\"meshes/light." + SafeName(light.name) +
             ".obj\"/><bsdf type=\"diffuse\">" + Rgb("reflectance", Eigen::Vector3d::Zero()) +
             "</bsdf><emitter type=\"area\">" + Rgb("radiance", light.radiance) +
             "</emitter></shape>\n";
  }
  return {};
}

}  // namespace

void WriteMitsubaExport(const recon::Scene& scene, const ExportOptions& options,
                        const std::filesystem::path& dir, ExportReport* report) {
  using internal::WriteText;
  const auto regions = internal::SplitByRegion(scene.mesh);
  std::string common;
  for (const recon::Camera& camera : scene.cameras) {
    common += SensorText(camera, options.mitsuba_spp, report);
  }
  for (size_t r = 0; r < regions.size(); ++r) {
    if (regions[r].triangles.empty()) continue;
    const recon::Material& m = scene.materials[r];
    const std::string id = SafeName(m.name);
    common += BsdfText(m, dir, report);
    WriteText(dir, "meshes/" + id + ".obj", internal::ObjText(regions[r]), report);
    common += "  <shape type=\"obj\" id=\"" + id + "\"><string name=\"filename\" value=\"meshes/" +
              id + ".obj\"/><ref id=\"bsdf." + id + "\"/>";
    if (m.brdf == recon::BrdfModel::kEmitter) {
      common += "<emitter type=\"area\">" + Rgb("radiance", *m.radiance) + "</emitter>";
    }
    common += "</shape>\n";
  }
  for (const recon::Light& light : scene.lights) {
    if (light.type != recon::LightType::kArea) continue;
    WriteText(dir, "meshes/light." + SafeName(light.name) + ".obj",
              internal::ObjText(internal::WholeMesh(light.mesh)), report);
  }
  for (const recon::Lighting& lighting : scene.lightings) {
    std::string xml = "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n<!-- igi-export: lighting " +
                      lighting.name +
                      "; mapping in solver/export/export_mitsuba.h -->\n<scene version=\"3.0.0\">\n"
                      "  <integrator type=\"path\"><integer name=\"max_depth\" "
                      "value=\"-1\"/></integrator>\n" +
                      common;
    for (int l : lighting.lights) xml += EmitterText(scene.lights[l], report);
    xml += "</scene>\n";
    WriteText(dir, "scene_" + SafeName(lighting.name) + ".xml", xml, report);
  }
}

}  // namespace igi::exporter
