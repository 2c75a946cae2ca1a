#include "solver/export/export_mitsuba.h"

#include <fmt/format.h>

#include <cmath>
#include <memory>
#include <set>

#include "solver/export/export_common.h"
#include "tools/common/error.h"
#include "tools/common/geometry.h"
#include "tools/common/html_report.h"
#include "tools/common/image.h"

namespace igi::exporter {
namespace {

using internal::Num;
using internal::SafeName;

// ---------------------------------------------------------------------------------------------
// The scene description both outputs render: Mitsuba objects (plugin instances) with their
// properties in order. The XML writer and the load_dict writer read only this, so the two
// cannot disagree on an object, a name or a value.

struct MiObject;

// One property of an object: a value, a nested object or a reference to a top-level object.
struct MiProperty {
  enum class Kind {
    kFloat,
    kInteger,
    kBoolean,
    kString,
    kFilename,  // a string naming a file relative to the export folder
    kRgb,
    kPoint,
    kVector,
    kLookAt,  // the to_world transform: origin `v`, target, up
    kObject,
    kRef,  // `text` is the referenced object's id
  };
  Kind kind = Kind::kFloat;
  std::string name;  // the property name (XML name attribute, dict key); unset for kObject
  double number = 0;
  std::string text;
  Eigen::Vector3d v = Eigen::Vector3d::Zero(), target = Eigen::Vector3d::Zero(),
                  up = Eigen::Vector3d::Zero();
  std::shared_ptr<const MiObject> object;
};

struct MiObject {
  std::string tag;      // the XML element: scene child tags (sensor, bsdf, shape, ...) or nested
  std::string type;     // the plugin
  std::string id;       // top-level objects: the XML id and the dict key
  std::string name;     // nested objects read by name (textures): XML name and dict key
  std::string comment;  // an XML comment written before a top-level object
  std::vector<MiProperty> properties;

  MiObject(std::string tag_in, std::string type_in, std::string id_in = {})
      : tag(std::move(tag_in)), type(std::move(type_in)), id(std::move(id_in)) {}

  // The key of this object in its parent's dict: the id, else the name, else the tag.
  const std::string& Key() const { return !id.empty() ? id : !name.empty() ? name : tag; }

  MiObject& Add(MiProperty::Kind kind, std::string key, double number = 0, std::string text = {}) {
    MiProperty p;
    p.kind = kind;
    p.name = std::move(key);
    p.number = number;
    p.text = std::move(text);
    properties.push_back(std::move(p));
    return *this;
  }
  MiObject& Float(std::string key, double v) { return Add(MiProperty::Kind::kFloat, key, v); }
  MiObject& Integer(std::string key, int v) { return Add(MiProperty::Kind::kInteger, key, v); }
  MiObject& Boolean(std::string key, bool v) { return Add(MiProperty::Kind::kBoolean, key, v); }
  MiObject& String(std::string key, std::string v) {
    return Add(MiProperty::Kind::kString, key, 0, std::move(v));
  }
  MiObject& Filename(std::string relative) {
    return Add(MiProperty::Kind::kFilename, "filename", 0, std::move(relative));
  }
  MiObject& Vec(MiProperty::Kind kind, std::string key, const Eigen::Vector3d& v) {
    Add(kind, std::move(key));
    properties.back().v = v;
    return *this;
  }
  MiObject& Rgb(std::string key, const Eigen::Vector3d& v) {
    return Vec(MiProperty::Kind::kRgb, key, v);
  }
  MiObject& Point(std::string key, const Eigen::Vector3d& v) {
    return Vec(MiProperty::Kind::kPoint, key, v);
  }
  MiObject& Vector(std::string key, const Eigen::Vector3d& v) {
    return Vec(MiProperty::Kind::kVector, key, v);
  }
  MiObject& LookAt(const Eigen::Vector3d& origin, const Eigen::Vector3d& target,
                   const Eigen::Vector3d& up) {
    Vec(MiProperty::Kind::kLookAt, "to_world", origin);
    properties.back().target = target;
    properties.back().up = up;
    return *this;
  }
  MiObject& Child(MiObject child) {
    Add(MiProperty::Kind::kObject, {});
    properties.back().object = std::make_shared<const MiObject>(std::move(child));
    return *this;
  }
  // A reference to the top-level object `ref_id`, read under `key` (the dict key; XML's <ref>
  // carries no name).
  MiObject& Ref(std::string key, std::string ref_id) {
    return Add(MiProperty::Kind::kRef, std::move(key), 0, std::move(ref_id));
  }
};

// A Mitsuba 3 scene: its integrator and top-level objects in writing order.
struct MiScene {
  std::string lighting;
  std::vector<MiObject> objects;  // the integrator first
};

// --- XML -------------------------------------------------------------------------------------

std::string Csv(const Eigen::Vector3d& v) {
  return Num(v.x()) + ", " + Num(v.y()) + ", " + Num(v.z());
}

std::string XmlElement(const MiObject& object);

std::string XmlProperty(const MiProperty& p) {
  using Kind = MiProperty::Kind;
  const std::string name = HtmlEscape(p.name);
  switch (p.kind) {
    case Kind::kFloat:
      return fmt::format("<float name=\"{}\" value=\"{}\"/>", name, Num(p.number));
    case Kind::kInteger:
      return fmt::format("<integer name=\"{}\" value=\"{}\"/>", name, int64_t(p.number));
    case Kind::kBoolean:
      return fmt::format("<boolean name=\"{}\" value=\"{}\"/>", name,
                         p.number != 0 ? "true" : "false");
    case Kind::kString:
    case Kind::kFilename:
      return fmt::format("<string name=\"{}\" value=\"{}\"/>", name, HtmlEscape(p.text));
    case Kind::kRgb:
      return fmt::format("<rgb name=\"{}\" value=\"{}\"/>", name, Csv(p.v));
    case Kind::kPoint:
    case Kind::kVector:
      return fmt::format("<{} name=\"{}\" x=\"{}\" y=\"{}\" z=\"{}\"/>",
                         p.kind == Kind::kPoint ? "point" : "vector", name, Num(p.v.x()),
                         Num(p.v.y()), Num(p.v.z()));
    case Kind::kLookAt:
      return fmt::format(
          "<transform name=\"{}\"><lookat origin=\"{}\" target=\"{}\" up=\"{}\"/></transform>",
          name, Csv(p.v), Csv(p.target), Csv(p.up));
    case Kind::kObject:
      return XmlElement(*p.object);
    case Kind::kRef:
      return "<ref id=\"" + HtmlEscape(p.text) + "\"/>";
  }
  return {};
}

// One object as one element on one line: <tag type="..." id="..." name="...">...</tag>.
std::string XmlElement(const MiObject& object) {
  std::string out = "<" + object.tag + " type=\"" + HtmlEscape(object.type) + "\"";
  if (!object.id.empty()) out += " id=\"" + HtmlEscape(object.id) + "\"";
  if (!object.name.empty()) out += " name=\"" + HtmlEscape(object.name) + "\"";
  if (object.properties.empty()) return out + "/>";
  out += ">";
  for (const MiProperty& p : object.properties) out += XmlProperty(p);
  return out + "</" + object.tag + ">";
}

// A comment's text with a space between two '-' (XML comments may not hold "--" or end in '-').
std::string CommentText(std::string_view text) {
  std::string out;
  for (char c : text) {
    if (c == '-' && !out.empty() && out.back() == '-') out += ' ';
    out += c;
  }
  if (!out.empty() && out.back() == '-') out += ' ';
  return out;
}

std::string XmlText(const MiScene& scene) {
  std::string xml = "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n<!-- igi-export: lighting " +
                    CommentText(scene.lighting) +
                    "; mapping in solver/export/export_mitsuba.h -->\n<scene version=\"3.0.0\">\n";
  for (const MiObject& object : scene.objects) {
    if (!object.comment.empty()) xml += "  <!-- " + CommentText(object.comment) + " -->\n";
    xml += "  " + XmlElement(object) + "\n";
  }
  return xml + "</scene>\n";
}

// --- load_dict -------------------------------------------------------------------------------

Json Triple(const Eigen::Vector3d& v) { return Json::array({v.x(), v.y(), v.z()}); }

// Mitsuba's Transform4f::look_at as a row-major 4x4 matrix: columns left = up × dir, up' =
// dir × left, dir = (target − origin)/|…|, and the origin.
Json LookAtMatrix(const Eigen::Vector3d& origin, const Eigen::Vector3d& target,
                  const Eigen::Vector3d& up) {
  const Eigen::Vector3d dir = (target - origin).normalized();
  const Eigen::Vector3d left = up.cross(dir).normalized();
  const Eigen::Vector3d new_up = dir.cross(left);
  Json rows = Json::array();
  for (int r = 0; r < 3; ++r) {
    rows.push_back(Json::array({left(r), new_up(r), dir(r), origin(r)}));
  }
  rows.push_back(Json::array({0.0, 0.0, 0.0, 1.0}));
  return rows;
}

Json DictObject(const MiObject& object, const std::filesystem::path& dir) {
  using Kind = MiProperty::Kind;
  Json d = Json::object();
  d["type"] = object.type;
  for (const MiProperty& p : object.properties) {
    const std::string& key = p.kind == Kind::kObject ? p.object->Key() : p.name;
    if (d.contains(key)) throw Error("Mitsuba dict: two properties named '" + key + "'");
    Json& value = d[key];
    switch (p.kind) {
      case Kind::kFloat:
        value = p.number;
        break;
      case Kind::kInteger:
        value = int64_t(p.number);
        break;
      case Kind::kBoolean:
        value = p.number != 0;
        break;
      case Kind::kString:
        value = p.text;
        break;
      case Kind::kFilename:
        value = (dir / p.text).generic_string();
        break;
      case Kind::kRgb:
        value = Json{{"type", "rgb"}, {"value", Triple(p.v)}};
        break;
      case Kind::kPoint:
      case Kind::kVector:
        value = Triple(p.v);
        break;
      case Kind::kLookAt:
        value = Json{{"type", "transform"}, {"matrix", LookAtMatrix(p.v, p.target, p.up)}};
        break;
      case Kind::kObject:
        value = DictObject(*p.object, dir);
        break;
      case Kind::kRef:
        value = Json{{"type", "ref"}, {"id", p.text}};
        break;
    }
  }
  return d;
}

Json DictScene(const MiScene& scene, const std::filesystem::path& dir) {
  Json d = Json::object();
  d["type"] = "scene";
  for (const MiObject& object : scene.objects) {
    if (d.contains(object.Key()))
      throw Error("Mitsuba dict: two objects keyed '" + object.Key() + "'");
    d[object.Key()] = DictObject(object, dir);
  }
  return d;
}

// ---------------------------------------------------------------------------------------------
// The scene's objects.

// The ids of the scene's objects, unique over the whole scene (the dict's keys): SafeName of the
// camera, region or light name, with "_2", "_3", ... appended to a name already taken. A region
// also takes "bsdf.<id>" (its BSDF's id); "integrator" and "type" are the dict's own keys.
struct MitsubaIds {
  std::vector<std::string> cameras, regions, lights;
};

MitsubaIds AssignIds(const recon::Scene& scene) {
  std::set<std::string> used = {"integrator", "type"};
  const auto take = [&used](const std::string& name, bool with_bsdf) {
    const std::string base = SafeName(name);
    std::string id = base;
    for (int k = 2; used.count(id) != 0 || (with_bsdf && used.count("bsdf." + id) != 0); ++k) {
      id = base + "_" + std::to_string(k);
    }
    used.insert(id);
    if (with_bsdf) used.insert("bsdf." + id);
    return id;
  };
  MitsubaIds ids;
  for (const recon::Camera& c : scene.cameras) ids.cameras.push_back(take(c.name, false));
  for (const recon::Material& m : scene.materials) ids.regions.push_back(take(m.name, true));
  for (const recon::Light& l : scene.lights) ids.lights.push_back(take(l.name, false));
  return ids;
}

MiObject BlackDiffuse() {
  return std::move(MiObject("bsdf", "diffuse").Rgb("reflectance", Eigen::Vector3d::Zero()));
}

// The diffuse reflectance as `key` of `bsdf`: a bitmap of rho_d_map (written as EXR) or an rgb.
void AddDiffuseValue(const recon::Material& m, const std::string& id, const std::string& key,
                     const std::filesystem::path& dir, ExportReport* report, MiObject* bsdf) {
  if (!m.rho_d_map) {
    bsdf->Rgb(key, internal::RegionRhoD(m));
    return;
  }
  const std::string relative = "textures/" + id + ".exr";
  std::filesystem::create_directories(dir / "textures");
  Image image = ReadImage(*m.rho_d_map, 3);
  image.metadata.clear();
  WriteImageOptions write;
  write.type = PixelType::kFloat;
  write.compression = "zip";
  WriteImage(dir / relative, image, write);
  report->files.push_back(relative);
  MiObject texture("texture", "bitmap");
  texture.name = key;
  texture.Filename(relative).Boolean("raw", true);
  bsdf->Child(std::move(texture));
}

MiObject BsdfObject(const recon::Material& m, const std::string& id,
                    const std::filesystem::path& dir, ExportReport* report) {
  internal::ReportDiffuseShape(m, "Mitsuba 3", report);
  MiObject twosided("bsdf", "twosided", "bsdf." + id);
  twosided.comment = m.name + " (" + std::string(recon::BrdfModelName(m.brdf)) + ")";
  if (m.brdf == recon::BrdfModel::kEmitter || m.brdf == recon::BrdfModel::kBlack) {
    return std::move(twosided.Child(BlackDiffuse()));
  }
  if (!recon::HasSpecularLobe(m.brdf) || !(m.rho_s->mean() > 0)) {
    MiObject diffuse("bsdf", "diffuse");
    AddDiffuseValue(m, id, "reflectance", dir, report, &diffuse);
    return std::move(twosided.Child(std::move(diffuse)));
  }
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
  MiObject plastic("bsdf", "roughplastic");
  plastic.String("distribution", distribution)
      .Float("alpha", fit.alpha)
      .Float("int_ior", eta)
      .Float("ext_ior", 1.0)
      .Boolean("nonlinear", false);
  AddDiffuseValue(m, id, "diffuse_reflectance", dir, report, &plastic);
  plastic.Rgb("specular_reflectance", fit.scale * *m.rho_s / m.rho_s->mean());
  return std::move(twosided.Child(std::move(plastic)));
}

MiObject SensorObject(const recon::Camera& camera, const std::string& id, int spp,
                      ExportReport* report) {
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
  MiObject sensor("sensor", "perspective", id);
  sensor.comment = "camera " + camera.name;
  sensor.String("fov_axis", "x")
      .Float("fov", fov)
      .Float("near_clip", 0.01)
      .Float("principal_point_offset_x",
             (camera.principal_x_px() - 0.5 * camera.width) / camera.width)
      .Float("principal_point_offset_y",
             (camera.principal_y_px() - 0.5 * camera.height) / camera.height)
      .LookAt(c, c + world_from_cam.col(2), -world_from_cam.col(1))
      .Child(std::move(MiObject("sampler", "independent").Integer("sample_count", spp)))
      .Child(std::move(MiObject("film", "hdrfilm")
                           .Integer("width", camera.width)
                           .Integer("height", camera.height)
                           .Child(MiObject("rfilter", "box"))));
  return sensor;
}

// The 90% and 10% angles (degrees, at most 90) of a spot profile.
double SpotAngleDeg(const recon::SpotProfile& profile, double fraction) {
  const double axis = profile.Relative(0, 0);
  for (double deg = 0.05; deg < 90; deg += 0.05) {
    if (profile.Relative(deg * render::kPi / 180, 0) < fraction * axis) return deg;
  }
  return 90;
}

MiObject AreaEmitter(const Eigen::Vector3d& radiance) {
  return std::move(MiObject("emitter", "area").Rgb("radiance", radiance));
}

std::string AreaLightMeshFile(const std::string& id) { return "meshes/light." + id + ".obj"; }

MiObject EmitterObject(const recon::Light& light, const std::string& id, ExportReport* report) {
  switch (light.type) {
    case recon::LightType::kPoint:
      return std::move(MiObject("emitter", "point", id)
                           .Point("position", light.position)
                           .Rgb("intensity", light.intensity));
    case recon::LightType::kSpot: {
      const recon::SpotProfile& p = light.profile;
      if (p.kind == recon::SpotProfile::Kind::kNone) {
        return std::move(MiObject("emitter", "point", id)
                             .Point("position", light.position)
                             .Rgb("intensity", light.intensity));
      }
      double beam = SpotAngleDeg(p, 0.9), cutoff = SpotAngleDeg(p, 0.1);
      if (p.kind == recon::SpotProfile::Kind::kCone) beam = p.inner_deg, cutoff = p.outer_deg;
      report->Add("lights." + light.name, "spot profile as Mitsuba's spot (beam_width " +
                                              Num(beam) + " deg, cutoff_angle " + Num(cutoff) +
                                              " deg, its own falloff)");
      const Eigen::Vector3d up = FrameFromAxis(light.direction).col(0);
      return std::move(MiObject("emitter", "spot", id)
                           .Rgb("intensity", light.intensity)
                           .Float("beam_width", std::min(beam, cutoff))
                           .Float("cutoff_angle", cutoff)
                           .LookAt(light.position, light.position + light.direction, up));
    }
    case recon::LightType::kDirectional:
      return std::move(MiObject("emitter", "directional", id)
                           .Vector("direction", light.direction)
                           .Rgb("irradiance", light.irradiance));
    case recon::LightType::kSphere:
      return std::move(MiObject("shape", "sphere", id)
                           .Point("center", light.center)
                           .Float("radius", light.radius)
                           .Child(BlackDiffuse())
                           .Child(AreaEmitter(light.radiance)));
    case recon::LightType::kAmbient:
      return std::move(MiObject("emitter", "constant", id).Rgb("radiance", light.radiance));
    case recon::LightType::kArea:
      return std::move(MiObject("shape", "obj", id)
                           .Filename(AreaLightMeshFile(id))
                           .Child(BlackDiffuse())
                           .Child(AreaEmitter(light.radiance)));
  }
  return MiObject("emitter", "point", id);
}

MiObject Integrator() { return std::move(MiObject("integrator", "path").Integer("max_depth", -1)); }

// The objects every lighting shares, in writing order: the sensors, then per region with
// triangles its BSDF and its shape. Writes the regions' meshes and textures into `dir`.
std::vector<MiObject> SharedObjects(const recon::Scene& scene, const MitsubaIds& ids,
                                    const ExportOptions& options, const std::filesystem::path& dir,
                                    ExportReport* report) {
  std::vector<MiObject> objects;
  for (size_t c = 0; c < scene.cameras.size(); ++c) {
    objects.push_back(SensorObject(scene.cameras[c], ids.cameras[c], options.mitsuba_spp, report));
  }
  const auto regions = internal::SplitByRegion(scene.mesh);
  for (size_t r = 0; r < regions.size(); ++r) {
    if (regions[r].triangles.empty()) continue;
    const recon::Material& m = scene.materials[r];
    const std::string& id = ids.regions[r];
    objects.push_back(BsdfObject(m, id, dir, report));
    const std::string mesh = "meshes/" + id + ".obj";
    internal::WriteText(dir, mesh, internal::ObjText(regions[r]), report);
    MiObject shape("shape", "obj", id);
    shape.Filename(mesh).Ref("bsdf", "bsdf." + id);
    if (m.brdf == recon::BrdfModel::kEmitter) shape.Child(AreaEmitter(*m.radiance));
    objects.push_back(std::move(shape));
  }
  return objects;
}

void WriteAreaLightMesh(const recon::Light& light, const std::string& id,
                        const std::filesystem::path& dir, ExportReport* report) {
  if (light.type != recon::LightType::kArea) return;
  internal::WriteText(dir, AreaLightMeshFile(id),
                      internal::ObjText(internal::WholeMesh(light.mesh)), report);
}

MiScene LightingScene(const recon::Scene& scene, const recon::Lighting& lighting,
                      const MitsubaIds& ids, const std::vector<MiObject>& shared,
                      ExportReport* report) {
  MiScene out;
  out.lighting = lighting.name;
  out.objects.push_back(Integrator());
  out.objects.insert(out.objects.end(), shared.begin(), shared.end());
  for (int l : lighting.lights) {
    out.objects.push_back(EmitterObject(scene.lights[size_t(l)], ids.lights[size_t(l)], report));
  }
  return out;
}

}  // namespace

void WriteMitsubaExport(const recon::Scene& scene, const ExportOptions& options,
                        const std::filesystem::path& dir, ExportReport* report) {
  const MitsubaIds ids = AssignIds(scene);
  const std::vector<MiObject> shared = SharedObjects(scene, ids, options, dir, report);
  for (size_t l = 0; l < scene.lights.size(); ++l) {
    WriteAreaLightMesh(scene.lights[l], ids.lights[l], dir, report);
  }
  for (const recon::Lighting& lighting : scene.lightings) {
    const MiScene mi = LightingScene(scene, lighting, ids, shared, report);
    internal::WriteText(dir, "scene_" + SafeName(lighting.name) + ".xml", XmlText(mi), report);
  }
}

Json MitsubaSceneDict(const recon::Scene& scene, int lighting, const ExportOptions& options,
                      const std::filesystem::path& dir, ExportReport* report) {
  options.Validate();
  CheckExportableScene(scene);
  if (lighting < 0 || size_t(lighting) >= scene.lightings.size()) {
    throw InputError(DescribeProblem(scene.file.string(), "lighting", std::to_string(lighting),
                                     "no lighting with that index"));
  }
  const std::filesystem::path out_dir = std::filesystem::absolute(dir).lexically_normal();
  std::error_code ec;
  if (std::filesystem::exists(out_dir, ec) && !std::filesystem::is_directory(out_dir, ec)) {
    throw InputError(
        DescribeProblem(out_dir.string(), "out_dir", "", "exists and is not a folder"));
  }
  std::filesystem::create_directories(out_dir);
  report->format = ExportFormat::kMitsuba;
  const MitsubaIds ids = AssignIds(scene);
  const std::vector<MiObject> shared = SharedObjects(scene, ids, options, out_dir, report);
  const recon::Lighting& chosen = scene.lightings[size_t(lighting)];
  for (int l : chosen.lights) {
    WriteAreaLightMesh(scene.lights[size_t(l)], ids.lights[size_t(l)], out_dir, report);
  }
  return DictScene(LightingScene(scene, chosen, ids, shared, report), out_dir);
}

}  // namespace igi::exporter
