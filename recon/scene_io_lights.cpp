// LoadScene, part 2: lights (every type of docs/scene-format.md, spot profiles with IES files)
// and lightings.
#include <set>

#include "recon/scene_loader.h"

namespace igi::recon {
namespace {

namespace fs = std::filesystem;

void ReadSpotProfile(const SceneLoader& ld, const JsonCursor& c, SpotProfile* profile) {
  if (!c.ExpectObject({"ies", "cos_power", "cone"})) return;
  const int given = int(c["ies"].present()) + int(c["cos_power"].present()) +
                    int(c["cone"].present());
  if (given != 1) {
    c.Problem("must have exactly one of ies, cos_power, cone");
    return;
  }
  if (c["cos_power"].present()) {
    profile->kind = SpotProfile::Kind::kCosPower;
    profile->cos_power = c["cos_power"].Number(NumberRule::NonNegative()).value_or(0);
  } else if (c["cone"].present()) {
    const JsonCursor cone = c["cone"];
    profile->kind = SpotProfile::Kind::kCone;
    if (!cone.ExpectObject({"inner_deg", "outer_deg"})) return;
    auto inner = cone["inner_deg"].Number(NumberRule::Between(0, 180));
    auto outer = cone["outer_deg"].Number(NumberRule{0.0, 180.0, true, false});
    if (inner && outer && *inner > *outer) cone["inner_deg"].Problem("must be <= outer_deg");
    profile->inner_deg = inner.value_or(0);
    profile->outer_deg = outer.value_or(0);
  } else {
    profile->kind = SpotProfile::Kind::kIes;
    auto file = ld.File(c["ies"]);
    if (!file) return;
    profile->ies_file = *file;
    try {
      profile->ies = std::make_shared<const IesProfile>(ReadIesProfile(*file));
      if (!(profile->ies->MaxCandela() > 0)) c["ies"].Problem("the IES profile emits no light");
    } catch (const Error& e) {
      ld.Nested(c["ies"], e);
    }
  }
}

std::vector<std::string_view> LightKeys(LightType type) {
  switch (type) {
    case LightType::kPoint: return {"type", "position", "intensity"};
    case LightType::kSpot: return {"type", "position", "direction", "intensity", "profile"};
    case LightType::kDirectional: return {"type", "direction", "irradiance"};
    case LightType::kSphere: return {"type", "center", "radius", "radiance"};
    case LightType::kArea: return {"type", "file", "radiance"};
    case LightType::kAmbient: return {"type", "radiance"};
  }
  return {"type"};
}

std::optional<LightType> LightTypeFromName(const std::string& name) {
  for (LightType t : {LightType::kPoint, LightType::kSpot, LightType::kDirectional,
                      LightType::kSphere, LightType::kArea, LightType::kAmbient}) {
    if (LightTypeName(t) == name) return t;
  }
  return std::nullopt;
}

Light ReadLight(const SceneLoader& ld, const JsonCursor& c, const std::string& name) {
  Light light;
  light.name = name;
  if (!c.IsObject()) {
    c.Problem("must be an object");
    return light;
  }
  auto type_name = c["type"].Enum({"point", "spot", "directional", "sphere", "area", "ambient"});
  if (!type_name) return light;
  light.type = *LightTypeFromName(*type_name);
  c.ExpectObject(LightKeys(light.type));
  const NumberRule non_negative = NumberRule::NonNegative();
  const Eigen::Vector3d zero = Eigen::Vector3d::Zero();
  switch (light.type) {
    case LightType::kPoint:
    case LightType::kSpot:
      light.position = c["position"].Vec3().value_or(zero);
      light.intensity = c["intensity"].Rgb(non_negative).value_or(zero);
      if (light.type == LightType::kSpot) {
        light.direction = c["direction"].Direction().value_or(Eigen::Vector3d::UnitZ());
        if (c["profile"].present()) ReadSpotProfile(ld, c["profile"], &light.profile);
      }
      break;
    case LightType::kDirectional:
      light.direction = c["direction"].Direction().value_or(Eigen::Vector3d::UnitZ());
      light.irradiance = c["irradiance"].Rgb(non_negative).value_or(zero);
      break;
    case LightType::kSphere:
      light.center = c["center"].Vec3().value_or(zero);
      light.radius = c["radius"].Number(NumberRule::Positive()).value_or(0);
      light.radiance = c["radiance"].Rgb(non_negative).value_or(zero);
      break;
    case LightType::kAmbient:
      light.radiance = c["radiance"].Rgb(non_negative).value_or(zero);
      break;
    case LightType::kArea:
      light.radiance = c["radiance"].Rgb(non_negative).value_or(zero);
      if (auto file = ld.File(c["file"])) {
        light.file = *file;
        if (ld.options.load_geometry) {
          ProblemList mesh_problems;
          light.mesh = LoadMesh(*file, &mesh_problems);
          for (const std::string& p : mesh_problems.problems()) {
            ld.problems->Add(ld.file, c["file"].path(), "", p);
          }
        }
      }
      break;
  }
  return light;
}

}  // namespace

void ReadLightsAndLightings(const SceneLoader& ld, const JsonCursor& root, Scene* scene) {
  if (root["lights"].present()) {
    const JsonCursor lights = root["lights"];
    for (const std::string& name : lights.ObjectKeys()) {
      scene->lights.push_back(ReadLight(ld, lights[name], name));
    }
  }
  if (!root["lightings"].present()) return;
  const JsonCursor lightings = root["lightings"];
  for (const std::string& name : lightings.ObjectKeys()) {
    Lighting lighting;
    lighting.name = name;
    const JsonCursor list = lightings[name];
    const size_t n = list.ArraySize();
    std::set<std::string> seen;
    for (size_t i = 0; i < n; ++i) {
      auto light_name = list[i].String();
      if (!light_name) continue;
      const int index = scene->FindLight(*light_name);
      if (index < 0) {
        list[i].Problem("no light of that name in lights");
      } else if (!seen.insert(*light_name).second) {
        list[i].Problem("light listed twice in the same lighting");
      } else {
        lighting.lights.push_back(index);
      }
    }
    scene->lightings.push_back(std::move(lighting));
  }
}

}  // namespace igi::recon
