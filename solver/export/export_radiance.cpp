#include "solver/export/export_radiance.h"

#include <fmt/format.h>

#include <cmath>

#include "solver/export/export_common.h"

namespace igi::exporter {
namespace {

using internal::Num;
using internal::SafeName;

std::string Triple(const Eigen::Vector3d& v) {
  return Num(v.x()) + " " + Num(v.y()) + " " + Num(v.z());
}

// "void TYPE NAME\n0\n<strings>\n<n> <reals>\n".
std::string Primitive(const std::string& modifier, const std::string& type, const std::string& name,
                      const std::string& strings, const std::vector<double>& reals) {
  std::string text = fmt::format("{} {} {}\n{}\n0\n{}", modifier, type, name,
                                 strings.empty() ? "0" : strings, reals.size());
  for (double r : reals) {
    text += ' ';
    text += Num(r);
  }
  text += "\n\n";
  return text;
}

// ρs proportional to ρd (within 1e-3 relative): the ratio t, else nullopt.
std::optional<double> ProportionalRatio(const Eigen::Vector3d& rho_d,
                                        const Eigen::Vector3d& rho_s) {
  if (!(rho_d.minCoeff() > 0)) return std::nullopt;
  const Eigen::Vector3d t = rho_s.cwiseQuotient(rho_d);
  if (t.maxCoeff() - t.minCoeff() > 1e-3 * t.maxCoeff()) return std::nullopt;
  return t.mean();
}

// plastic/metal (or plastic2/metal2 with `aniso_args`) for ward_gmd values ρd, ρs, α.
std::string GmdMaterial(const recon::Material& m, const Eigen::Vector3d& rho_d,
                        const Eigen::Vector3d& rho_s, const std::vector<double>& rough,
                        const std::string& aniso_strings, ExportReport* report) {
  const std::string name = SafeName(m.name);
  const bool two = rough.size() == 2;
  const bool grey = rho_s.maxCoeff() - rho_s.minCoeff() <= 1e-9 * std::max(1.0, rho_s.maxCoeff());
  std::string type = two ? "plastic2" : "plastic";
  double spec = rho_s.mean();
  if (!grey) {
    if (auto t = ProportionalRatio(rho_d, rho_s)) {
      type = two ? "metal2" : "metal";
      spec = *t / (1.0 + *t);
    } else {
      const double err = (rho_s - Eigen::Vector3d::Constant(spec)).norm() / rho_s.norm();
      report->Add("materials." + m.name,
                  "coloured rho_s not proportional to rho_d: RADIANCE plastic uses its mean " +
                      Num(spec) + " (grey highlight); relative error = |rho_s - mean|/|rho_s|",
                  err);
    }
  }
  if (spec >= 1.0) {
    report->Add("materials." + m.name, "specular reflectance >= 1 clamped to 0.999", std::nullopt);
    spec = 0.999;
  }
  std::vector<double> reals = {rho_d.x() / (1 - spec), rho_d.y() / (1 - spec),
                               rho_d.z() / (1 - spec), spec};
  reals.insert(reals.end(), rough.begin(), rough.end());
  return Primitive("void", type, name, aniso_strings, reals);
}

std::string MaterialText(const recon::Material& m, ExportReport* report) {
  const std::string name = SafeName(m.name);
  std::string text;
  if (m.rho_d_map) {
    text += "# " + m.name + ": albedo map " + m.rho_d_map->string() +
            " replaced by the region mean rho_d (colorpict on per-triangle polygons is not "
            "written)\n";
    report->Add("materials." + m.name,
                "rho_d_map replaced by the region mean rho_d (RADIANCE polygons carry no UVs)");
  }
  if (m.brdf == recon::BrdfModel::kEmitter) {
    return text + Primitive("void", "light", name, "",
                            {(*m.radiance)[0], (*m.radiance)[1], (*m.radiance)[2]});
  }
  const Eigen::Vector3d rho_d =
      m.brdf == recon::BrdfModel::kBlack ? Eigen::Vector3d::Zero() : internal::RegionRhoD(m);
  internal::ReportDiffuseShape(m, "RADIANCE", report);
  if (!recon::HasSpecularLobe(m.brdf)) {
    return text + Primitive("void", "plastic", name, "", {rho_d.x(), rho_d.y(), rho_d.z(), 0, 0});
  }
  Eigen::Vector3d rho_s = *m.rho_s;
  std::vector<double> rough;
  std::string strings;
  if (recon::IsAnisotropic(m.brdf)) {
    rough = {*m.alpha_x, *m.alpha_y};
    strings = fmt::format("4 {} .", Triple(*m.tangent));
  } else {
    rough = {*m.alpha};
  }
  if (m.brdf != recon::BrdfModel::kWardGmd && m.brdf != recon::BrdfModel::kWardGmdAniso) {
    LobeFitOptions fit_options;
    fit_options.target = LobeTarget::kWardGmd;
    const LobeFit fit = internal::FitAndReport(m, fit_options, "RADIANCE plastic", report);
    rho_s *= fit.scale / rho_s.mean();  // the fit's k is the grey ρs of the fitted lobe
    const double ratio =
        fit.alpha / std::sqrt(rough.size() == 2 ? rough[0] * rough[1] : rough[0] * rough[0]);
    for (double& r : rough) r *= ratio;
    text += fmt::format("# {}: {} converted to the GMD Ward of RADIANCE (fitted error {:.3g})\n",
                        m.name, recon::BrdfModelName(m.brdf), fit.relative_error);
  }
  return text + GmdMaterial(m, rho_d, rho_s, rough, strings, report);
}

std::string PolygonText(const std::string& modifier, const std::string& name,
                        const recon::TriangleMesh& mesh, size_t t) {
  std::vector<double> reals;
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3f& p = mesh.positions[mesh.triangles[t][k]];
    reals.insert(reals.end(), {p.x(), p.y(), p.z()});
  }
  return Primitive(modifier, "polygon", name, "", reals);
}

std::string SceneText(const recon::Scene& scene, ExportReport* report) {
  std::string text =
      "# igi-export: RADIANCE scene description (materials and geometry). Build the octree with\n"
      "#   oconv scene.rad lighting_<L>.rad > scene.oct\n"
      "# Mapping: see solver/export/export_radiance.h (contract ward_gmd = RADIANCE plastic:\n"
      "#   RGB = rho_d/(1-spec), spec = rho_s, rough = alpha).\n\n";
  for (const recon::Material& m : scene.materials) text += MaterialText(m, report);
  const recon::TriangleMesh& mesh = scene.mesh;
  std::vector<std::vector<size_t>> by_region(mesh.region_names.size());
  for (size_t t = 0; t < mesh.num_triangles(); ++t) by_region[mesh.triangle_region[t]].push_back(t);
  for (size_t r = 0; r < by_region.size(); ++r) {
    const std::string mod = SafeName(scene.materials[r].name);
    text +=
        fmt::format("# region {}: {} triangles\n", scene.materials[r].name, by_region[r].size());
    for (size_t i = 0; i < by_region[r].size(); ++i) {
      text += PolygonText(mod, fmt::format("{}.t{}", mod, i), mesh, by_region[r][i]);
    }
  }
  report->Add("geometry", "one flat polygon per triangle: vertex normals are not exported");
  return text;
}

// Full angle (degrees) at which the spot's relative intensity falls to half its axis value.
double HalfPeakFullAngleDeg(const recon::SpotProfile& profile) {
  const double axis = profile.Relative(0, 0);
  for (double deg = 0.05; deg < 180; deg += 0.05) {
    if (profile.Relative(deg * render::kPi / 180, 0) < 0.5 * axis) return 2 * deg;
  }
  return 360;
}

std::string LightText(const recon::Light& light, const ExportOptions& options,
                      ExportReport* report) {
  const std::string name = SafeName(light.name), mat = name + ".mat";
  const std::string item = "lights." + light.name;
  const double r = options.point_light_radius_m;
  switch (light.type) {
    case recon::LightType::kSphere:
      return Primitive("void", "light", mat, "",
                       {light.radiance.x(), light.radiance.y(), light.radiance.z()}) +
             Primitive(mat, "sphere", name, "",
                       {light.center.x(), light.center.y(), light.center.z(), light.radius});
    case recon::LightType::kPoint:
    case recon::LightType::kSpot: {
      const Eigen::Vector3d radiance = light.intensity / (render::kPi * r * r);
      std::string text;
      if (light.type == recon::LightType::kSpot &&
          light.profile.kind != recon::SpotProfile::Kind::kNone) {
        const double angle = HalfPeakFullAngleDeg(light.profile);
        if (light.profile.kind == recon::SpotProfile::Kind::kIes) {
          text += "# " + light.name + ": IES profile " + light.profile.ies_file.string() +
                  " (convert it with ies2rad for the exact distribution)\n";
        }
        text += Primitive("void", "spotlight", mat, "",
                          {radiance.x(), radiance.y(), radiance.z(), angle, light.direction.x(),
                           light.direction.y(), light.direction.z()});
        report->Add(item, "spot profile replaced by a RADIANCE spotlight of full angle " +
                              Num(angle) + " deg (twice the half-peak angle)");
      } else {
        text += Primitive("void", "light", mat, "", {radiance.x(), radiance.y(), radiance.z()});
      }
      report->Add(item, "point emitter as a light sphere of radius " + Num(r) +
                            " m with radiance intensity/(pi r^2)");
      return text + Primitive(mat, "sphere", name, "",
                              {light.position.x(), light.position.y(), light.position.z(), r});
    }
    case recon::LightType::kDirectional: {
      const double half = options.source_angle_deg * render::kPi / 360;
      const Eigen::Vector3d radiance = light.irradiance / (2 * render::kPi * (1 - std::cos(half)));
      const Eigen::Vector3d to_source = -light.direction.normalized();
      report->Add(item, "directional light as a RADIANCE source of diameter " +
                            Num(options.source_angle_deg) + " deg and radiance E/solid angle");
      return Primitive("void", "light", mat, "", {radiance.x(), radiance.y(), radiance.z()}) +
             Primitive(mat, "source", name, "",
                       {to_source.x(), to_source.y(), to_source.z(), options.source_angle_deg});
    }
    case recon::LightType::kAmbient:
      report->Add(item, "ambient light has no RADIANCE primitive: render with -av " +
                            Num(light.radiance.x()) + " " + Num(light.radiance.y()) + " " +
                            Num(light.radiance.z()) +
                            " -aw 0 (RADIANCE applies it where ambient bounces end)");
      return "# " + light.name + ": ambient radiance " + Num(light.radiance.x()) + " " +
             Num(light.radiance.y()) + " " + Num(light.radiance.z()) + " (use rpict -av)\n";
    case recon::LightType::kArea: {
      std::string text = Primitive("void", "light", mat, "",
                                   {light.radiance.x(), light.radiance.y(), light.radiance.z()});
      for (size_t t = 0; t < light.mesh.num_triangles(); ++t) {
        text += PolygonText(mat, fmt::format("{}.t{}", name, t), light.mesh, t);
      }
      return text;
    }
  }
  return {};
}

std::string ViewText(const recon::Camera& camera, ExportReport* report) {
  const Eigen::Matrix3d world_from_cam =
      camera.cam_from_world.rotation.toRotationMatrix().transpose();
  const Eigen::Vector3d vp = camera.CenterInWorld();
  const Eigen::Vector3d vd = world_from_cam.col(2), vu = -world_from_cam.col(1);
  const double vh = 2 * std::atan(camera.width / (2 * camera.focal_x_px())) * 180 / render::kPi;
  const double vv = 2 * std::atan(camera.height / (2 * camera.focal_y_px())) * 180 / render::kPi;
  // Shifts: image centre relative to the optical axis, in image widths (right) / heights (up).
  const double vs = (0.5 * camera.width - camera.principal_x_px()) / camera.width;
  const double vl = (camera.principal_y_px() - 0.5 * camera.height) / camera.height;
  if (camera.model == recon::CameraModel::kOpenCv) {
    report->Add("cameras." + camera.name,
                "OPENCV distortion (k1, k2, p1, p2) dropped: RADIANCE views are pinhole");
  }
  return fmt::format("rview -vtv -vp {} -vd {} -vu {} -vh {} -vv {} -vs {} -vl {}\n", Triple(vp),
                     Triple(vd), Triple(vu), Num(vh), Num(vv), Num(vs), Num(vl));
}

}  // namespace

void WriteRadianceExport(const recon::Scene& scene, const ExportOptions& options,
                         const std::filesystem::path& dir, ExportReport* report) {
  using internal::WriteText;
  WriteText(dir, "scene.rad", SceneText(scene, report), report);
  for (const recon::Lighting& lighting : scene.lightings) {
    std::string text = "# igi-export: lights of lighting " + lighting.name + "\n\n";
    for (int l : lighting.lights) text += LightText(scene.lights[l], options, report);
    WriteText(dir, "lighting_" + SafeName(lighting.name) + ".rad", text, report);
  }
  for (const recon::Camera& camera : scene.cameras) {
    WriteText(dir, SafeName(camera.name) + ".vf", ViewText(camera, report), report);
  }
}

}  // namespace igi::exporter
