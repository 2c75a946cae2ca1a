#include "recon/scene.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "tools/common/strings.h"

namespace igi::recon {
namespace {

// The names of a registry's lines that `keep` accepts, joined by `separator`.
template <typename Line, size_t N, typename Keep>
std::string JoinNames(const Line (&lines)[N], std::string_view separator, Keep keep) {
  std::vector<std::string> names;
  for (const Line& line : lines) {
    if (keep(line)) names.emplace_back(line.name);
  }
  return Join(names, separator);
}

template <typename T>
int FindByName(const std::vector<T>& items, std::string_view name) {
  for (size_t i = 0; i < items.size(); ++i) {
    if (items[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

}  // namespace

std::string_view BrdfModelName(BrdfModel model) { return Info(model).name; }

std::optional<BrdfModel> BrdfModelFromName(std::string_view name) {
  for (const BrdfModelInfo& b : kBrdfModels) {
    if (b.name == name) return b.model;
  }
  return std::nullopt;
}

std::string_view DiffuseShapeName(DiffuseShape shape) { return Info(shape).name; }

std::optional<DiffuseShape> DiffuseShapeFromName(std::string_view name) {
  for (const DiffuseShapeInfo& d : kDiffuseShapes) {
    if (d.name == name) return d.shape;
  }
  return std::nullopt;
}

std::string_view DiffuseShapeNames() {
  static const std::string names =
      JoinNames(kDiffuseShapes, ", ", [](const DiffuseShapeInfo&) { return true; });
  return names;
}

std::string_view DiffuseShapesWithSigma() {
  static const std::string names =
      JoinNames(kDiffuseShapes, " or ", [](const DiffuseShapeInfo& d) { return d.has_sigma; });
  return names;
}

std::string_view BrdfModelNames() {
  static const std::string names =
      JoinNames(kBrdfModels, ", ", [](const BrdfModelInfo&) { return true; });
  return names;
}

std::vector<std::string> Material::MissingForRendering() const {
  std::vector<std::string> missing;
  if (brdf == BrdfModel::kBlack) return missing;
  if (brdf == BrdfModel::kEmitter) {
    if (!radiance) missing.push_back("radiance");
    return missing;
  }
  if (!rho_d && !rho_d_map) missing.push_back("rho_d");
  if (HasSigma(diffuse) && !sigma) missing.push_back("sigma");
  if (!HasSpecularLobe(brdf)) return missing;
  if (!rho_s) missing.push_back("rho_s");
  if (IsAnisotropic(brdf)) {
    if (!alpha_x) missing.push_back("alpha_x");
    if (!alpha_y) missing.push_back("alpha_y");
    if (!tangent) missing.push_back("tangent");
  } else if (!alpha) {
    missing.push_back("alpha");
  }
  return missing;
}

std::string_view LightTypeName(LightType type) {
  switch (type) {
    case LightType::kPoint:
      return "point";
    case LightType::kSpot:
      return "spot";
    case LightType::kDirectional:
      return "directional";
    case LightType::kSphere:
      return "sphere";
    case LightType::kArea:
      return "area";
    case LightType::kAmbient:
      return "ambient";
  }
  return "unknown";
}

double Photo::LinearFromRecorded(double v) const {
  if (!HasResponse()) return v;
  const double mag =
      response_reference * std::pow(std::abs(v) / response_reference, 1.0 / response_exponent);
  return v < 0 ? -mag : mag;
}

double Photo::RecordedFromLinear(double u) const {
  if (!HasResponse()) return u;
  const double mag =
      response_reference * std::pow(std::abs(u) / response_reference, response_exponent);
  return u < 0 ? -mag : mag;
}

double SpotProfile::Relative(double theta, double phi) const {
  switch (kind) {
    case Kind::kNone:
      return 1.0;
    case Kind::kCosPower: {
      const double c = std::cos(theta);
      return c > 0 ? std::pow(c, cos_power) : 0.0;
    }
    case Kind::kCone: {
      const double deg = theta * 180.0 / M_PI;
      if (deg <= inner_deg) return 1.0;
      if (deg >= outer_deg) return 0.0;
      const double t = (outer_deg - deg) / (outer_deg - inner_deg);
      return t * t * (3 - 2 * t);
    }
    case Kind::kIes: {
      const double peak = ies->MaxCandela();
      if (!(peak > 0)) return 0.0;
      double phi_deg = phi * 180.0 / M_PI;
      if (phi_deg < 0) phi_deg += 360.0;
      return ies->Candela(theta * 180.0 / M_PI, phi_deg) / peak;
    }
  }
  return 0.0;
}

int Scene::FindMaterial(std::string_view name) const { return FindByName(materials, name); }
int Scene::FindLight(std::string_view name) const { return FindByName(lights, name); }
int Scene::FindLighting(std::string_view name) const { return FindByName(lightings, name); }
int Scene::FindCamera(std::string_view name) const { return FindByName(cameras, name); }

void ForEachScenePath(Json* doc, const std::function<std::string(const std::string&)>& fn) {
  auto key = [&](Json& j, const char* k) {
    if (j.is_object() && j.contains(k) && j[k].is_string()) j[k] = fn(j[k].get<std::string>());
  };
  if (doc->contains("geometry")) {
    for (Json& g : (*doc)["geometry"]) key(g, "file");
  }
  if (doc->contains("lights")) {
    for (auto& [n, l] : (*doc)["lights"].items()) {
      key(l, "file");
      if (l.contains("profile")) key(l["profile"], "ies");
    }
  }
  if (doc->contains("materials")) {
    for (auto& [n, m] : (*doc)["materials"].items()) key(m, "rho_d_map");
  }
  if (doc->contains("cameras")) key((*doc)["cameras"], "colmap");
  if (doc->contains("photos")) {
    for (Json& p : (*doc)["photos"]) {
      key(p, "file");
      key(p, "mask");
    }
  }
}

Json AbsoluteScenePaths(Json doc, const std::filesystem::path& dir) {
  ForEachScenePath(&doc, [&](const std::string& p) {
    const std::filesystem::path path(p);
    return (path.is_absolute() ? path : std::filesystem::absolute(dir / path))
        .lexically_normal()
        .string();
  });
  return doc;
}

Json RelativeScenePaths(Json doc, const std::filesystem::path& base) {
  namespace fs = std::filesystem;
  const fs::path b = fs::weakly_canonical(fs::absolute(base));
  ForEachScenePath(&doc, [&](const std::string& p) {
    const fs::path rel = fs::weakly_canonical(fs::path(p)).lexically_relative(b);
    return rel.empty() ? p : rel.generic_string();
  });
  return doc;
}

}  // namespace igi::recon
