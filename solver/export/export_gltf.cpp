#include "solver/export/export_gltf.h"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstring>
#include <set>

#include "solver/export/export_common.h"
#include "tools/common/atomic_file.h"
#include "tools/common/image.h"

namespace igi::exporter {
namespace {

using internal::RegionMesh;
using internal::SafeName;

constexpr int kFloat = 5126, kUInt32 = 5125;
constexpr int kArrayBuffer = 34962, kElementArrayBuffer = 34963;

Json Array3(const Eigen::Vector3d& v) { return Json::array({v.x(), v.y(), v.z()}); }

// glTF node rotation [x, y, z, w] of a rotation matrix.
Json Rotation(const Eigen::Matrix3d& m) {
  const Eigen::Quaterniond q(m);
  return Json::array({q.x(), q.y(), q.z(), q.w()});
}

// color = v/max, intensity = max (KHR_lights_punctual splits them that way).
void ColorIntensity(const Eigen::Vector3d& v, Json* light) {
  const double peak = v.maxCoeff();
  (*light)["color"] = Array3(peak > 0 ? Eigen::Vector3d(v / peak) : Eigen::Vector3d::Ones());
  (*light)["intensity"] = peak;
}

double SrgbEncode(double c) {
  c = std::clamp(c, 0.0, 1.0);
  return c <= 0.0031308 ? 12.92 * c : 1.055 * std::pow(c, 1.0 / 2.4) - 0.055;
}

class GltfBuilder {
 public:
  GltfBuilder(const recon::Scene& scene, const std::filesystem::path& dir, ExportReport* report)
      : scene_(scene), dir_(dir), report_(report) {
    doc_["asset"] = {{"version", "2.0"}, {"generator", "igi-export"}};
    for (const char* key : {"scenes", "nodes", "meshes", "materials", "accessors", "bufferViews",
                            "cameras", "images", "textures", "samplers"}) {
      doc_[key] = Json::array();
    }
  }

  void AddRegions();
  void AddLights();
  void AddCameras();
  void Write();

 private:
  int AddAccessor(const void* data, size_t bytes, int target, Json accessor);
  int AddMesh(const std::string& name, const RegionMesh& mesh, int material);
  int AddMaterial(const recon::Material& m);
  int AddTexture(const recon::Material& m);
  void AddNode(Json node) {
    roots_.push_back(int(doc_["nodes"].size()));
    doc_["nodes"].push_back(std::move(node));
  }
  Json LightFor(const recon::Light& light);

  const recon::Scene& scene_;
  std::filesystem::path dir_;
  ExportReport* report_;
  Json doc_;
  Json lights_ = Json::array();
  std::vector<int> roots_;
  std::string bin_;
  std::set<std::string> extensions_;
};

int GltfBuilder::AddAccessor(const void* data, size_t bytes, int target, Json accessor) {
  while (bin_.size() % 4 != 0) bin_.push_back('\0');
  const size_t offset = bin_.size();
  bin_.append(static_cast<const char*>(data), bytes);
  doc_["bufferViews"].push_back(
      {{"buffer", 0}, {"byteOffset", offset}, {"byteLength", bytes}, {"target", target}});
  accessor["bufferView"] = int(doc_["bufferViews"].size()) - 1;
  doc_["accessors"].push_back(std::move(accessor));
  return int(doc_["accessors"].size()) - 1;
}

int GltfBuilder::AddMesh(const std::string& name, const RegionMesh& mesh, int material) {
  const size_t n = mesh.positions.size();
  Eigen::Vector3f lo = mesh.positions[0], hi = mesh.positions[0];
  for (const auto& p : mesh.positions) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  Json attributes;
  attributes["POSITION"] = AddAccessor(mesh.positions.data(), n * 12, kArrayBuffer,
                                       {{"componentType", kFloat},
                                        {"count", n},
                                        {"type", "VEC3"},
                                        {"min", {lo.x(), lo.y(), lo.z()}},
                                        {"max", {hi.x(), hi.y(), hi.z()}}});
  attributes["NORMAL"] = AddAccessor(mesh.normals.data(), n * 12, kArrayBuffer,
                                     {{"componentType", kFloat}, {"count", n}, {"type", "VEC3"}});
  if (!mesh.uvs.empty()) {
    std::vector<float> st;
    for (const auto& uv : mesh.uvs) st.insert(st.end(), {uv.x(), 1.0f - uv.y()});
    attributes["TEXCOORD_0"] =
        AddAccessor(st.data(), st.size() * 4, kArrayBuffer,
                    {{"componentType", kFloat}, {"count", n}, {"type", "VEC2"}});
  }
  const int indices = AddAccessor(
      mesh.triangles.data(), mesh.triangles.size() * 12, kElementArrayBuffer,
      {{"componentType", kUInt32}, {"count", mesh.triangles.size() * 3}, {"type", "SCALAR"}});
  Json primitive = {
      {"attributes", attributes}, {"indices", indices}, {"material", material}, {"mode", 4}};
  doc_["meshes"].push_back({{"name", name}, {"primitives", Json::array({primitive})}});
  return int(doc_["meshes"].size()) - 1;
}

int GltfBuilder::AddTexture(const recon::Material& m) {
  Image image = ReadImage(*m.rho_d_map, 3);
  for (float& v : image.pixels) v = float(SrgbEncode(v));
  image.metadata.clear();
  const std::string relative = "textures/" + SafeName(m.name) + ".png";
  std::filesystem::create_directories(dir_ / "textures");
  WriteImageOptions write;
  write.type = PixelType::kUInt8;
  WriteImage(dir_ / relative, image, write);
  report_->files.push_back(relative);
  report_->Add("materials." + m.name, "rho_d_map written as an 8-bit sRGB PNG (quantised)");
  if (doc_["samplers"].empty())
    doc_["samplers"].push_back({{"magFilter", 9729}, {"minFilter", 9987}});
  doc_["images"].push_back({{"uri", relative}, {"name", m.name}});
  doc_["textures"].push_back({{"source", int(doc_["images"].size()) - 1}, {"sampler", 0}});
  return int(doc_["textures"].size()) - 1;
}

int GltfBuilder::AddMaterial(const recon::Material& m) {
  internal::ReportDiffuseShape(m, "glTF", report_);
  Json pbr = {{"metallicFactor", 0.0}, {"roughnessFactor", 1.0}};
  Json material = {{"name", m.name}, {"doubleSided", true}};
  Json ext;
  if (m.brdf == recon::BrdfModel::kEmitter) {
    pbr["baseColorFactor"] = {0.0, 0.0, 0.0, 1.0};
    const double peak = m.radiance->maxCoeff();
    material["emissiveFactor"] =
        Array3(peak > 0 ? Eigen::Vector3d(*m.radiance / peak) : Eigen::Vector3d::Zero());
    ext["KHR_materials_emissive_strength"] = {{"emissiveStrength", peak}};
  } else {
    Eigen::Vector3d base =
        m.brdf == recon::BrdfModel::kBlack ? Eigen::Vector3d::Zero() : internal::RegionRhoD(m);
    if (m.rho_d_map) {
      pbr["baseColorTexture"] = {{"index", AddTexture(m)}};
      base.setOnes();
    }
    if (base.maxCoeff() > 1) report_->Add("materials." + m.name, "baseColor clamped to 1");
    base = base.cwiseMin(1.0);
    pbr["baseColorFactor"] = {base.x(), base.y(), base.z(), 1.0};
    Json specular = {{"specularFactor", 0.0}};
    const bool exact_ggx = m.brdf == recon::BrdfModel::kGgx;
    const bool metal = exact_ggx && !m.rho_d_map && !(internal::RegionRhoD(m).maxCoeff() > 0);
    if (metal) {
      // glTF's metal is F_schlick(baseColor)·D_ggx·V_smith_correlated: igi's ggx with ρd = 0.
      pbr["metallicFactor"] = 1.0;
      pbr["roughnessFactor"] = std::sqrt(*m.alpha);
      pbr["baseColorFactor"] = {m.rho_s->x(), m.rho_s->y(), m.rho_s->z(), 1.0};
      report_->Add("materials." + m.name,
                   "ggx with rho_d 0 as metallic 1: baseColor = rho_s, roughness = sqrt(alpha) "
                   "(exact)",
                   0.0);
    } else if (exact_ggx) {
      // The same lobe on a dielectric: F0 = 0.04·specularColorFactor.
      pbr["roughnessFactor"] = std::sqrt(*m.alpha);
      specular = {{"specularFactor", 1.0}, {"specularColorFactor", Array3(*m.rho_s / 0.04)}};
      report_->Add("materials." + m.name,
                   "ggx lobe exact (roughness = sqrt(alpha), F0 = 0.04*specularColorFactor = "
                   "rho_s); glTF weights the diffuse term by 1 - F, not compensated");
    } else if (recon::HasSpecularLobe(m.brdf)) {
      LobeFitOptions options;
      options.target = LobeTarget::kGgxSchlick;
      const LobeFit fit = internal::FitAndReport(m, options, "glTF GGX + Schlick", report_);
      pbr["roughnessFactor"] = std::min(1.0, std::sqrt(fit.alpha));
      const Eigen::Vector3d f0 = fit.scale * *m.rho_s / std::max(1e-12, m.rho_s->mean());
      specular = {{"specularFactor", 1.0}, {"specularColorFactor", Array3(f0 / 0.04)}};
    }
    if (!metal) ext["KHR_materials_specular"] = specular;
  }
  for (auto it = ext.begin(); it != ext.end(); ++it) extensions_.insert(it.key());
  material["pbrMetallicRoughness"] = pbr;
  material["extensions"] = ext;
  doc_["materials"].push_back(std::move(material));
  return int(doc_["materials"].size()) - 1;
}

void GltfBuilder::AddRegions() {
  const std::vector<RegionMesh> regions = internal::SplitByRegion(scene_.mesh);
  for (size_t r = 0; r < regions.size(); ++r) {
    if (regions[r].triangles.empty()) continue;
    const int material = AddMaterial(scene_.materials[r]);
    const int mesh = AddMesh(scene_.materials[r].name, regions[r], material);
    AddNode({{"name", scene_.materials[r].name}, {"mesh", mesh}});
  }
}
// The angle (radians) where the spot's relative intensity first falls below `fraction` of its
// axis value (at most 90°).
double SpotAngle(const recon::SpotProfile& profile, double fraction) {
  const double axis = profile.Relative(0, 0);
  for (double deg = 0.05; deg < 90; deg += 0.05) {
    if (profile.Relative(deg * render::kPi / 180, 0) < fraction * axis)
      return deg * render::kPi / 180;
  }
  return render::kPi / 2;
}

Json GltfBuilder::LightFor(const recon::Light& light) {
  Json out = {{"name", light.name}};
  const std::string item = "lights." + light.name;
  switch (light.type) {
    case recon::LightType::kPoint:
      out["type"] = "point";
      ColorIntensity(light.intensity, &out);
      break;
    case recon::LightType::kSpot: {
      ColorIntensity(light.intensity, &out);
      const recon::SpotProfile& p = light.profile;
      if (p.kind == recon::SpotProfile::Kind::kNone) {
        out["type"] = "point";
        break;
      }
      out["type"] = "spot";
      double inner = SpotAngle(p, 0.9), outer = SpotAngle(p, 0.1);
      if (p.kind == recon::SpotProfile::Kind::kCone) {
        inner = p.inner_deg * render::kPi / 180,
        outer = std::min(p.outer_deg, 90.0) * render::kPi / 180;
        report_->Add(item,
                     "cone falloff: glTF's smooth falloff between inner and outer angles "
                     "replaces the smoothstep");
      } else {
        report_->Add(item,
                     "spot profile as a glTF cone: inner/outer angles where it falls to "
                     "90%/10% of its axis value");
      }
      out["spot"] = {{"innerConeAngle", std::min(inner, outer - 1e-4)}, {"outerConeAngle", outer}};
      break;
    }
    case recon::LightType::kDirectional:
      out["type"] = "directional";
      ColorIntensity(light.irradiance, &out);
      break;
    case recon::LightType::kSphere:
      out["type"] = "point";
      ColorIntensity(light.radiance * render::kPi * light.radius * light.radius, &out);
      report_->Add(item,
                   "sphere light as a point light of intensity radiance*pi*r^2 (exact at "
                   "distances >> r; no visible sphere)");
      break;
    case recon::LightType::kArea:
    case recon::LightType::kAmbient:
      break;
  }
  return out;
}

void GltfBuilder::AddLights() {
  for (const recon::Light& light : scene_.lights) {
    if (light.type == recon::LightType::kArea) {
      recon::Material emitter;
      emitter.name = "light." + light.name;
      emitter.brdf = recon::BrdfModel::kEmitter;
      emitter.radiance = light.radiance;
      const int material = AddMaterial(emitter);
      const int mesh = AddMesh(emitter.name, internal::WholeMesh(light.mesh), material);
      AddNode({{"name", emitter.name}, {"mesh", mesh}});
      continue;
    }
    if (light.type == recon::LightType::kAmbient) {
      report_->Add("lights." + light.name, "ambient light left out: glTF has no such light");
      continue;
    }
    lights_.push_back(LightFor(light));
    Json node = {{"name", light.name}};
    node["extensions"]["KHR_lights_punctual"]["light"] = int(lights_.size()) - 1;
    const Eigen::Vector3d at =
        light.type == recon::LightType::kSphere ? light.center : light.position;
    if (light.type != recon::LightType::kDirectional) node["translation"] = Array3(at);
    if (light.type == recon::LightType::kSpot || light.type == recon::LightType::kDirectional) {
      // The light shines along its node's −z.
      const Eigen::Matrix3d frame = FrameFromAxis(-light.direction.normalized());
      node["rotation"] = Rotation(frame);
    }
    AddNode(std::move(node));
  }
  if (lights_.empty()) return;
  extensions_.insert("KHR_lights_punctual");
  report_->Add("lights",
               "radiometric values passed through 1:1 as glTF candela/lux (no luminous "
               "efficacy applied)");
}

void GltfBuilder::AddCameras() {
  for (const recon::Camera& camera : scene_.cameras) {
    const double yfov = 2 * std::atan(camera.height / (2 * camera.focal_y_px()));
    doc_["cameras"].push_back({{"name", camera.name},
                               {"type", "perspective"},
                               {"perspective",
                                {{"aspectRatio", double(camera.width) / camera.height},
                                 {"yfov", yfov},
                                 {"znear", 0.01}}}});
    const Eigen::Matrix3d world_from_cam =
        camera.cam_from_world.rotation.toRotationMatrix().transpose();
    // glTF cameras look along −z with +y up: COLMAP's axes with y and z negated.
    const Eigen::Matrix3d world_from_gltf =
        world_from_cam * Eigen::Vector3d(1, -1, -1).asDiagonal();
    AddNode({{"name", camera.name},
             {"camera", int(doc_["cameras"].size()) - 1},
             {"translation", Array3(camera.CenterInWorld())},
             {"rotation", Rotation(world_from_gltf)}});
    const bool centred = std::abs(camera.principal_x_px() - 0.5 * camera.width) < 1e-6 &&
                         std::abs(camera.principal_y_px() - 0.5 * camera.height) < 1e-6;
    const bool square =
        std::abs(camera.focal_x_px() - camera.focal_y_px()) < 1e-6 * camera.focal_x_px();
    if (!centred || !square || camera.model == recon::CameraModel::kOpenCv) {
      report_->Add("cameras." + camera.name,
                   "glTF perspective keeps yfov and aspect only: principal point offset, fx != fy "
                   "and lens distortion dropped");
    }
  }
}

void GltfBuilder::Write() {
  doc_["scenes"].push_back({{"name", "scene"}, {"nodes", roots_}});
  doc_["scene"] = 0;
  if (!lights_.empty()) doc_["extensions"]["KHR_lights_punctual"]["lights"] = lights_;
  Json lightings = Json::object();
  for (const recon::Lighting& lighting : scene_.lightings) {
    Json names = Json::array();
    for (int l : lighting.lights) names.push_back(scene_.lights[l].name);
    lightings[lighting.name] = names;
  }
  doc_["asset"]["extras"]["igi_lightings"] = lightings;
  doc_["extensionsUsed"] = Json(std::vector<std::string>(extensions_.begin(), extensions_.end()));
  for (const char* key : {"cameras", "images", "textures", "samplers"}) {
    if (doc_[key].empty()) doc_.erase(key);
  }
  doc_["buffers"] = Json::array({{{"uri", "scene.bin"}, {"byteLength", bin_.size()}}});
  WriteFileAtomic(dir_ / "scene.bin", bin_);
  report_->files.push_back("scene.bin");
  internal::WriteText(dir_, "scene.gltf", doc_.dump(1), report_);
}

}  // namespace

void WriteGltfExport(const recon::Scene& scene, const ExportOptions& /*options*/,
                     const std::filesystem::path& dir, ExportReport* report) {
  GltfBuilder builder(scene, dir, report);
  builder.AddRegions();
  builder.AddLights();
  builder.AddCameras();
  builder.Write();
}

}  // namespace igi::exporter
