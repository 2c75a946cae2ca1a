#include "recon/scene_document.h"

#include <system_error>
#include <utility>

#include "recon/scene_loader.h"

namespace igi::recon {
namespace fs = std::filesystem;
namespace {

// Multiplies a number, or each number of an array, by `factor`.
void Scale(Json* value, double factor) {
  if (value->is_number()) {
    *value = value->get<double>() * factor;
    return;
  }
  for (Json& v : *value) v = v.get<double>() * factor;
}

// `path` (relative to `from`) relative to `to`, through symlinks resolved; the absolute path
// when it has no relative form; an absolute `path` as it is.
std::string Rebase(const std::string& path, const fs::path& from, const fs::path& to) {
  const fs::path p(path);
  if (p.is_absolute()) return path;
  std::error_code ec;
  const fs::path abs = fs::weakly_canonical(fs::absolute(from / p), ec);
  const fs::path base = fs::weakly_canonical(fs::absolute(to), ec);
  const fs::path rel = abs.lexically_relative(base);
  return rel.empty() ? abs.string() : rel.generic_string();
}

}  // namespace

SceneDocument::SceneDocument(Json document) : doc_(std::move(document)) {}

void SceneDocument::Validate(const fs::path& dir, const SceneLoadOptions& options) const {
  LoadSceneFromDocument(doc_, dir / "scene.json", options);
}

void SceneDocument::RebasePaths(const fs::path& from_dir, const fs::path& to_dir) {
  ForEachScenePath(&doc_, [&](const std::string& p) { return Rebase(p, from_dir, to_dir); });
}

void SceneDocument::AbsolutePaths(const fs::path& dir) {
  doc_ = AbsoluteScenePaths(std::move(doc_), dir);
}

void SceneDocument::RelativePaths(const fs::path& base) {
  doc_ = RelativeScenePaths(std::move(doc_), base);
}

void SceneDocument::SetGeometryFiles(const std::vector<fs::path>& files) {
  Json geometry = Json::array();
  for (const fs::path& f : files) geometry.push_back(Json{{"file", f.string()}});
  doc_["geometry"] = std::move(geometry);
}

const Json& SceneDocument::Material(const std::string& region) const {
  static const Json kNone;
  const auto materials = doc_.find("materials");
  if (materials == doc_.end() || !materials->is_object()) return kNone;
  const auto m = materials->find(region);
  return m == materials->end() ? kNone : *m;
}

void SceneDocument::SetMaterial(const std::string& region, Json entry) {
  doc_["materials"][region] = std::move(entry);
}

void SceneDocument::SetMaterialValue(const std::string& region, const std::string& key,
                                     Json value) {
  doc_["materials"][region][key] = std::move(value);
}

void SceneDocument::EraseMaterialValue(const std::string& region, const std::string& key) {
  Json& m = doc_["materials"][region];
  if (m.is_object()) m.erase(key);
}

void SceneDocument::SetMaterialBrdf(const std::string& region, BrdfModel brdf) {
  SetMaterialValue(region, "brdf", std::string(BrdfModelName(brdf)));
}

void SceneDocument::ScaleMaterialValue(const std::string& region, const std::string& key,
                                       double factor) {
  Json& m = doc_["materials"][region];
  if (m.contains(key)) Scale(&m[key], factor);
}

void SceneDocument::SetLight(const std::string& name, Json light) {
  doc_["lights"][name] = std::move(light);
}

std::string SceneDocument::AddLightToEveryLighting(const std::string& name_hint, Json light) {
  std::string name = name_hint;
  while (doc_["lights"].contains(name)) name += "_";
  doc_["lights"][name] = std::move(light);
  for (auto& [lighting, list] : doc_["lightings"].items()) list.push_back(name);
  return name;
}

void SceneDocument::ScaleLightEmission(const std::string& name, double factor) {
  Json& light = doc_["lights"][name];
  for (const char* key : {"intensity", "radiance", "irradiance"}) {
    if (light.contains(key)) Scale(&light[key], factor);
  }
}

std::vector<std::string> SceneDocument::CameraNames() const {
  std::vector<std::string> names;
  if (!doc_.contains("cameras") || !doc_["cameras"].is_object()) return names;
  for (const auto& [name, camera] : doc_["cameras"].items()) names.push_back(name);
  return names;
}

bool SceneDocument::HasCamera(const std::string& name) const {
  return doc_.contains("cameras") && doc_["cameras"].contains(name);
}

void SceneDocument::SetCameras(Json cameras) { doc_["cameras"] = std::move(cameras); }

void SceneDocument::SetCamera(const std::string& name, const Camera& camera) {
  doc_["cameras"][name] = CameraJson(camera);
}

void SceneDocument::SetCameraIntrinsics(const std::string& name, const Camera& camera) {
  Json& j = doc_["cameras"][name];
  const Json full = CameraJson(camera);
  for (const char* key : {"model", "width", "height", "params"}) j[key] = full[key];
}

Rigid3d SceneDocument::CameraPose(const std::string& name) const {
  const Json& j = doc_.at("cameras").at(name);
  const std::vector<double> q = j.at("qvec").get<std::vector<double>>();
  const std::vector<double> t = j.at("tvec").get<std::vector<double>>();
  return Rigid3d(Eigen::Quaterniond(q.at(0), q.at(1), q.at(2), q.at(3)).normalized(),
                 Eigen::Vector3d(t.at(0), t.at(1), t.at(2)));
}

void SceneDocument::SetCameraPose(const std::string& name, const Rigid3d& cam_from_world) {
  const Eigen::Quaterniond& r = cam_from_world.rotation;
  const Eigen::Vector3d& t = cam_from_world.translation;
  Json& j = doc_["cameras"][name];
  j["qvec"] = {r.w(), r.x(), r.y(), r.z()};
  j["tvec"] = {t.x(), t.y(), t.z()};
}

Eigen::Vector2d SceneDocument::CameraVignetting(const std::string& name) const {
  if (!HasCamera(name)) return Eigen::Vector2d::Zero();
  const Json& camera = doc_["cameras"][name];
  if (!camera.contains("vignetting")) return Eigen::Vector2d::Zero();
  const Json& v = camera["vignetting"];
  return Eigen::Vector2d(v.value("k1", 0.0), v.value("k2", 0.0));
}

void SceneDocument::SetCameraVignetting(const std::string& name, double k1, double k2) {
  doc_["cameras"][name]["vignetting"] = {{"k1", k1}, {"k2", k2}};
}

size_t SceneDocument::NumPhotos() const {
  return doc_.contains("photos") && doc_["photos"].is_array() ? doc_["photos"].size() : 0;
}

void SceneDocument::SetPhotos(const std::vector<ScenePhotoEntry>& photos) {
  Json list = Json::array();
  for (const ScenePhotoEntry& p : photos) {
    Json photo = {{"file", p.file}, {"camera", p.camera}, {"lighting", p.lighting}};
    if (p.mask) photo["mask"] = *p.mask;
    list.push_back(std::move(photo));
  }
  doc_["photos"] = std::move(list);
}

std::string SceneDocument::PhotoFile(size_t index) const {
  return doc_.at("photos").at(index).value("file", "");
}

void SceneDocument::SetPhotoFile(size_t index, const fs::path& file) {
  doc_.at("photos").at(index)["file"] = file.string();
}

void SceneDocument::SetPhotoCamera(size_t index, const std::string& camera) {
  doc_.at("photos").at(index)["camera"] = camera;
}

void SceneDocument::SetPhotoMask(size_t index, const std::optional<fs::path>& mask) {
  Json& photo = doc_.at("photos").at(index);
  if (mask) {
    photo["mask"] = mask->string();
  } else {
    photo.erase("mask");
  }
}

std::optional<double> SceneDocument::PhotoExposure(size_t index) const {
  const Json& photo = doc_.at("photos").at(index);
  if (!photo.contains("exposure_scale")) return std::nullopt;
  return photo["exposure_scale"].get<double>();
}

void SceneDocument::SetPhotoExposure(size_t index, double scale) {
  doc_.at("photos").at(index)["exposure_scale"] = scale;
}

std::optional<double> SceneDocument::PhotoResponseExponent(size_t index) const {
  const Json& photo = doc_.at("photos").at(index);
  if (!photo.contains("response") || !photo["response"].contains("exponent")) return std::nullopt;
  const Json& e = photo["response"]["exponent"];
  if (!e.is_number()) return std::nullopt;
  return e.get<double>();
}

void SceneDocument::SetPhotoResponse(size_t index, double exponent, double reference) {
  doc_.at("photos").at(index)["response"] = {{"exponent", exponent}, {"reference", reference}};
}

}  // namespace igi::recon
