#include "solver/synth/effects.h"

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <set>

#include "calib/vignetting.h"
#include "recon/scene.h"
#include "solver/render/sampling.h"
#include "tools/common/error.h"
#include "tools/common/strings.h"

namespace igi::synth {
namespace {

using Eigen::Vector3d;

Json Vec(const Vector3d& v) { return Json::array({v.x(), v.y(), v.z()}); }

// Reads the key=value parameters of one --effect, rejecting unknown keys and bad values.
class Params {
 public:
  explicit Params(const EffectSpec& spec) : spec_(spec) {}

  double Number(const std::string& key, double fallback, double lo, double hi) {
    used_.insert(key);
    auto it = spec_.params.find(key);
    if (it == spec_.params.end()) return fallback;
    auto v = ParseDouble(it->second);
    if (!v || *v < lo || *v > hi) {
      Fail(key, it->second, "must be a number in [" + Fmt(lo) + ", " + Fmt(hi) + "]");
    }
    return *v;
  }
  std::string Name(const std::string& key, const std::string& fallback,
                   const std::vector<std::string>& allowed) {
    used_.insert(key);
    auto it = spec_.params.find(key);
    if (it == spec_.params.end()) return fallback;
    for (const std::string& a : allowed) {
      if (a == it->second) return a;
    }
    Fail(key, it->second, "must be one of " + Join(allowed, ", "));
    return fallback;
  }
  std::vector<std::string> Names(const std::string& key, const std::vector<std::string>& fallback,
                                 const std::vector<std::string>& allowed) {
    used_.insert(key);
    auto it = spec_.params.find(key);
    if (it == spec_.params.end()) return fallback;
    std::vector<std::string> out = SplitTokens(it->second, "/");
    for (const std::string& n : out) {
      if (std::find(allowed.begin(), allowed.end(), n) == allowed.end()) {
        Fail(key, it->second,
             "each name must be one of " + Join(allowed, ", ") + " ('/'-separated)");
      }
    }
    return out;
  }
  std::optional<Vector3d> Direction(const std::string& key) {
    used_.insert(key);
    auto it = spec_.params.find(key);
    if (it == spec_.params.end()) return std::nullopt;
    const auto parts = SplitTokens(it->second, "/");
    Vector3d v;
    for (int i = 0; i < 3 && parts.size() == 3; ++i) {
      auto x = ParseDouble(parts[i]);
      if (!x) break;
      v[i] = *x;
      if (i == 2 && v.norm() > 1e-9) return v.normalized();
    }
    Fail(key, it->second, "must be a non-zero vector x/y/z");
    return std::nullopt;
  }
  // Rejects parameters no reader asked for.
  void Finish() const {
    for (const auto& [key, value] : spec_.params) {
      if (used_.count(key) == 0) {
        std::vector<std::string> known(used_.begin(), used_.end());
        Fail(key, value, "unknown parameter (known: " + Join(known, ", ") + ")");
      }
    }
  }
  [[noreturn]] void Fail(const std::string& key, const std::string& value,
                         const std::string& rule) const {
    throw InputError(DescribeProblem("--effect", spec_.name, key + "=" + value, rule));
  }

 private:
  static std::string Fmt(double v) {
    std::string s = std::to_string(v);
    while (s.size() > 1 && s.back() == '0') s.pop_back();
    if (s.back() == '.') s.pop_back();
    return s;
  }
  const EffectSpec& spec_;
  std::set<std::string> used_;
};

std::vector<std::string> LampNames(const SynthRoom& room) {
  std::vector<std::string> names;
  for (const SynthLamp& l : room.lamps) names.push_back(l.name);
  return names;
}

const SynthLamp& FindLamp(const SynthRoom& room, const std::string& name) {
  for (const SynthLamp& l : room.lamps) {
    if (l.name == name) return l;
  }
  return room.lamps.front();
}

Json Vignetting(Params& p, PhotoEffects* post) {
  const double k1 = p.Number("k1", -0.25, -1.0, 1.0);
  const double k2 = p.Number("k2", -0.05, -1.0, 1.0);
  p.Finish();
  if (1 + k1 + k2 < 0.05) p.Fail("k1", std::to_string(k1), "1 + k1 + k2 must be >= 0.05");
  post->vignetting = {k1, k2};
  return Json{{"k1", k1},
              {"k2", k2},
              {"model", "photo = radiance * (1 + k1 r^2 + k2 r^4)"},
              {"r", "distance to the principal point / half the image diagonal"},
              {"corner_factor", 1 + k1 + k2},
              {"applies_to", "every photo (and bracket); not the validation renders"}};
}

Json EmissionProfile(Params& p, const SynthRoom& room, SynthScenes* s) {
  const std::string light = p.Name("light", "lamp", LampNames(room));
  const double n = p.Number("cos_power", 2.0, 0.1, 100.0);
  const Vector3d axis = p.Direction("direction").value_or(-Vector3d::UnitZ());
  p.Finish();
  const SynthLamp& lamp = FindLamp(room, light);
  Json spot = {{"type", "spot"},
               {"position", Vec(lamp.position)},
               {"direction", Vec(axis)},
               {"intensity", Vec(Vector3d::Constant(lamp.intensity))},
               {"profile", {{"cos_power", n}}}};
  s->true_scene["lights"][light] = spot;
  return Json{{"light", light},
              {"cos_power", n},
              {"direction", Vec(axis)},
              {"true_light", spot},
              {"note", "peak intensity equals the declared light's intensity"}};
}

// "ward_gmd_fresnel" -> {"ward_gmd", "_fresnel"}; "ward" -> {"ward", ""}.
std::pair<std::string, std::string> SplitFresnel(const std::string& brdf) {
  const std::string suffix = "_fresnel";
  if (brdf.size() > suffix.size() && brdf.ends_with(suffix)) {
    return {brdf.substr(0, brdf.size() - suffix.size()), suffix};
  }
  return {brdf, ""};
}

// The anisotropic form of a glossy region's model (ggx -> ggx_aniso, ward_gmd_fresnel ->
// ward_gmd_aniso_fresnel).
std::string Anisotropic(const std::string& brdf) {
  return std::string(recon::BrdfModelName(recon::AnisotropicForm(*recon::BrdfModelFromName(brdf))));
}

Json Anisotropy(Params& p, const SynthRoom& room, SynthScenes* s) {
  const std::string region = p.Name("region", "glossy_box", room.glossy_regions);
  const double ax = p.Number("alpha_x", 0.03, 1e-3, 1.0);
  const double ay = p.Number("alpha_y", 0.15, 1e-3, 1.0);
  const double yaw = 25.0 * std::numbers::pi / 180.0;  // glossy_box's rotation
  const Vector3d fallback =
      region == "glossy_box" ? Vector3d(std::cos(yaw), std::sin(yaw), 0) : Vector3d::UnitX();
  const Vector3d tangent = p.Direction("tangent").value_or(fallback);
  p.Finish();
  Json& m = s->true_scene["materials"][region];
  m["brdf"] = Anisotropic(m["brdf"].get<std::string>());
  m.erase("alpha");
  m["alpha_x"] = ax;
  m["alpha_y"] = ay;
  m["tangent"] = Vec(tangent);
  return Json{
      {"region", region},        {"true_brdf", m["brdf"]},
      {"alpha_x", ax},           {"alpha_y", ay},
      {"tangent", Vec(tangent)}, {"declared_brdf", s->declared_scene["materials"][region]["brdf"]}};
}

Json SourceExtent(Params& p, const SynthRoom& room, SynthScenes* s) {
  const std::string light = p.Name("light", "lamp", LampNames(room));
  const double radius = p.Number("radius", 0.25, 0.01, 0.5);
  p.Finish();
  SynthLamp lamp = FindLamp(room, light);
  const double declared = lamp.radius;
  lamp.radius = radius;
  s->true_scene["lights"][light] = LampJson(lamp);
  return Json{{"light", light},
              {"true_radius_m", radius},
              {"declared_radius_m", declared},
              {"true_light", s->true_scene["lights"][light]},
              {"note", "same intensity (W/sr) as declared: radiance = intensity / (pi r^2)"}};
}

Json MissingGeometry(Params& p, SynthScenes* s) {
  const double cx = p.Number("x", 3.1, 0.3, 3.7);
  const double cy = p.Number("y", 1.0, 0.3, 3.7);
  const double size = p.Number("size", 0.35, 0.05, 0.6);
  const double height = p.Number("height", 0.45, 0.05, 2.0);
  const double rho = p.Number("rho_d", 0.6, 0.0, 1.0);
  p.Finish();
  SynthMesh mesh;
  mesh.AddBox({cx, cy}, 0.0, {size, size, height}, 10.0, "missing_object");
  const std::string file = "truth/geometry/missing_object.obj";
  s->extra_files[file] = mesh.ToObj("igi-synth: the object scene.json leaves out");
  s->true_scene["geometry"].push_back(Json{{"file", file}});
  s->true_scene["materials"]["missing_object"] =
      Json{{"brdf", "lambert"}, {"rho_d", Vec(Vector3d::Constant(rho))}};
  return Json{{"file", file},
              {"region", "missing_object"},
              {"center", Vec({cx, cy, 0.5 * height})},
              {"size_m", Vec({size, size, height})},
              {"yaw_deg", 10.0},
              {"rho_d", rho}};
}

Json Ambient(Params& p, const SynthRoom& room, SynthScenes* s) {
  const double radiance = p.Number("radiance", 0.4, 0.0, 1e6);
  const std::string kind = p.Name("kind", "uniform", {"uniform", "panel"});
  p.Finish();
  if (kind == "uniform") {  // scene.json's ambient light: the same radiance from everywhere
    s->true_scene["lights"]["ambient"] =
        Json{{"type", "ambient"}, {"radiance", Vec(Vector3d::Constant(radiance))}};
    for (auto& [name, list] : s->true_scene["lightings"].items()) list.push_back("ambient");
    return Json{
        {"light", s->true_scene["lights"]["ambient"]}, {"lightings", "all"}, {"kind", kind}};
  }
  const double x = room.size.x() - 0.002;
  SynthMesh mesh;
  mesh.AddQuad({x, 1.2, 0.9}, {x, 1.2, 2.1}, {x, 2.8, 2.1}, {x, 2.8, 0.9}, "ambient_panel");
  const std::string file = "truth/geometry/ambient_panel.obj";
  s->extra_files[file] = mesh.ToObj("igi-synth: undeclared stray-light panel (front faces -x)");
  s->true_scene["lights"]["ambient"] =
      Json{{"type", "area"}, {"file", file}, {"radiance", Vec(Vector3d::Constant(radiance))}};
  for (auto& [name, list] : s->true_scene["lightings"].items()) list.push_back("ambient");
  return Json{{"light", s->true_scene["lights"]["ambient"]},
              {"lightings", "all"},
              {"where", "1.6 x 1.2 m panel 2 mm in front of wall_x4, y 1.2..2.8, z 0.9..2.1"}};
}

Json ExposureScale(Params& p, const std::vector<std::string>& photos, PhotoEffects* post) {
  const std::string fallback = photos.size() > 1 ? photos[1] : photos[0];
  const std::string photo = p.Name("photo", fallback, photos);
  const double scale = p.Number("scale", 1.3, 0.01, 100.0);
  p.Finish();
  post->exposure_scale[photo] = scale;
  return Json{{"photo", photo}, {"scale", scale}};
}

Json Response(Params& p, PhotoEffects* post) {
  const double exponent = p.Number("exponent", 0.8, 0.1, 5.0);
  const double reference = p.Number("reference", 1.0, 1e-9, 1e9);
  p.Finish();
  post->response = {exponent, reference};
  return Json{{"exponent", exponent},
              {"reference", reference},
              {"model", "photo = reference * (radiance / reference)^exponent (sign kept)"},
              {"applies_to", "every photo of scene.json (not brackets or validation renders)"}};
}

Json PoseError(Params& p, const std::vector<recon::Camera>& cameras, uint64_t seed,
               SynthScenes* s) {
  std::vector<std::string> names;
  for (const recon::Camera& c : cameras) names.push_back(c.name);
  const std::string name = p.Name("camera", names.front(), names);
  const double angle_deg = p.Number("rotation_deg", 1.0, 0.0, 45.0);
  const double shift_m = p.Number("translation_m", 0.02, 0.0, 1.0);
  render::Pcg32 rng(seed, 0x9053);
  const Vector3d axis = p.Direction("axis").value_or(render::SampleUniformSphere(rng.Uniform2D()));
  const Vector3d dir =
      p.Direction("direction").value_or(render::SampleUniformSphere(rng.Uniform2D()));
  p.Finish();
  recon::Camera cam;
  for (const recon::Camera& c : cameras) {
    if (c.name == name) cam = c;
  }
  const Vector3d center = cam.CenterInWorld() + shift_m * dir;
  const Eigen::Quaterniond delta(Eigen::AngleAxisd(angle_deg * render::kPi / 180.0, axis));
  recon::Camera declared = cam;
  declared.cam_from_world.rotation = (delta * cam.cam_from_world.rotation).normalized();
  declared.cam_from_world.translation = -(declared.cam_from_world.rotation * center);
  s->declared_scene["cameras"][name] = recon::CameraJson(declared);
  return Json{{"camera", name},
              {"rotation_deg", angle_deg},
              {"axis_cam", Vec(axis)},
              {"translation_m", shift_m},
              {"direction_world", Vec(dir)},
              {"model",
               "declared R = AngleAxis(rotation_deg, axis_cam) * true R; declared "
               "centre = true centre + translation_m * direction_world"},
              {"true", recon::CameraJson(cam)},
              {"declared", recon::CameraJson(declared)}};
}

Json LobeShape(Params& p, const SynthRoom& room, SynthScenes* s) {
  const auto regions = p.Names("regions", room.glossy_regions, room.glossy_regions);
  const std::string to = p.Name("to", "", {"ward", "ward_gmd", "beckmann", "ggx"});
  p.Finish();
  Json changes = Json::object();
  for (const std::string& region : regions) {
    Json& m = s->true_scene["materials"][region];
    const std::string brdf = m["brdf"].get<std::string>();
    static const std::map<std::string, std::string> kSwap = {{"ward", "ward_gmd"},
                                                             {"ward_gmd", "ward"},
                                                             {"ward_aniso", "ward_gmd_aniso"},
                                                             {"ward_gmd_aniso", "ward_aniso"}};
    const auto [base, fresnel] = SplitFresnel(brdf);
    if (to.empty()) {
      m["brdf"] = kSwap.at(base) + fresnel;
    } else {
      // The named lobe, anisotropic where the region is; a microfacet lobe carries its own
      // Fresnel factor (F0 = rho_s), so a *_fresnel region's ior goes with its weight.
      recon::BrdfModel model = *recon::BrdfModelFromName(to);
      if (recon::IsAnisotropic(*recon::BrdfModelFromName(base))) {
        model = recon::AnisotropicForm(model);
      }
      if (!fresnel.empty() && recon::IsMicrofacet(model)) m.erase("ior");
      m["brdf"] =
          std::string(recon::BrdfModelName(model)) + (recon::IsMicrofacet(model) ? "" : fresnel);
    }
    changes[region] = Json{{"true_brdf", m["brdf"]},
                           {"declared_brdf", s->declared_scene["materials"][region]["brdf"]}};
  }
  return Json{{"regions", changes}, {"note", "same rho_d, rho_s and alpha values"}};
}

Json DiffuseShapeEffect(Params& p, const SynthRoom& room, SynthScenes* s) {
  std::vector<std::string> lambert;  // the regions without a lobe
  for (auto it = room.materials.begin(); it != room.materials.end(); ++it) {
    if (it.value().value("brdf", "") == "lambert") lambert.push_back(it.key());
  }
  std::vector<std::string> reflective = lambert;
  reflective.insert(reflective.end(), room.glossy_regions.begin(), room.glossy_regions.end());
  const auto regions = p.Names("regions", lambert, reflective);
  const std::string to = p.Name("to", "oren_nayar", {"oren_nayar", "coated"});
  const double sigma = p.Number("sigma", 0.4, 0.0, 1.0);
  p.Finish();
  for (const std::string& region : regions) {
    Json& m = s->true_scene["materials"][region];
    m["diffuse"] = to;
    if (to == "oren_nayar") m["sigma"] = sigma;
  }
  if (to == "coated") {
    return Json{{"regions", regions},
                {"to", to},
                {"model", "diffuse rho_d/pi T(cos theta_i) T(cos theta_o), T(c) = 1 - (1 - c)^5"},
                {"note", "same rho_d (and lobe) values"}};
  }
  return Json{{"regions", regions},
              {"to", to},
              {"sigma", sigma},
              {"model",
               "diffuse rho_d/pi (A + B max(0, cos(phi_i - phi_o)) sin(max theta) tan(min theta)), "
               "A = 1 - sigma^2/(2 (sigma^2 + 0.33)), B = 0.45 sigma^2/(sigma^2 + 0.09)"},
              {"note", "same rho_d (and lobe) values"}};
}

Json Intensity(Params& p, const SynthRoom& room, SynthScenes* s) {
  const std::string light = p.Name("light", "lamp", LampNames(room));
  const double factor = p.Number("factor", 1.25, 0.01, 100.0);
  p.Finish();
  Json& j = s->true_scene["lights"][light];
  for (const char* key : {"intensity", "radiance"}) {
    if (!j.contains(key)) continue;
    for (auto& v : j[key]) v = v.get<double>() * factor;
  }
  return Json{{"light", light}, {"factor", factor}, {"true_light", j}};
}

Json Fresnel(Params& p, const SynthRoom& room, SynthScenes* s) {
  const auto regions = p.Names("regions", room.glossy_regions, room.glossy_regions);
  const double ior = p.Number("ior", 1.5, 1.01, 5.0);
  p.Finish();
  const double f0 = std::pow((ior - 1) / (ior + 1), 2);
  Json changes = Json::object();
  for (const std::string& region : regions) {
    Json& m = s->true_scene["materials"][region];
    const std::string brdf = m["brdf"].get<std::string>();
    if (SplitFresnel(brdf).second.empty()) m["brdf"] = brdf + "_fresnel";
    m["ior"] = ior;
    changes[region] = Json{{"true_brdf", m["brdf"]},
                           {"declared_brdf", s->declared_scene["materials"][region]["brdf"]}};
  }
  return Json{
      {"regions", changes},
      {"ior", ior},
      {"f0", f0},
      {"model",
       "specular term x F(c)/F0, F = F0 + (1 - F0)(1 - c)^5 (Schlick), F0 = ((ior - 1)/(ior "
       "+ 1))^2, c = |wi + wo|/2; equal to the declared model at c = 1 (wi = wo)"},
      {"note", "same rho_d, rho_s and alpha values"}};
}

Json SpecularAsDiffuse(Params& p, const SynthRoom& room, SynthScenes* s) {
  const std::string region = p.Name("region", "wall_y4", room.glossy_regions);
  p.Finish();
  Json& m = s->declared_scene["materials"][region];
  m["brdf"] = "lambert";
  for (const char* key : {"rho_s", "alpha", "alpha_x", "alpha_y", "tangent"}) m.erase(key);
  return Json{{"region", region},
              {"declared_brdf", "lambert"},
              {"true_brdf", s->true_scene["materials"][region]["brdf"]}};
}

}  // namespace

double PhotoEffects::VignettingFactor(const recon::Camera& camera, double x, double y) const {
  if (!vignetting) return 1.0;
  return calib::Vignetting{vignetting->first, vignetting->second}.Factor(calib::VignettingRadius2(
      x, y, camera.principal_x_px(), camera.principal_y_px(), camera.width, camera.height));
}

void PhotoEffects::ApplyBeforeSensor(const std::string& photo_file, const recon::Camera& camera,
                                     Image* image) const {
  const auto scale_it = exposure_scale.find(photo_file);
  const double scale = scale_it == exposure_scale.end() ? 1.0 : scale_it->second;
  if (!vignetting && scale == 1.0) return;
  // The photo may be rendered at the camera's size only (RenderOptions width/height 0).
  for (int y = 0; y < image->height; ++y) {
    for (int x = 0; x < image->width; ++x) {
      const double f = scale * VignettingFactor(camera, x + 0.5, y + 0.5);
      for (int c = 0; c < image->channels; ++c) image->at(x, y, c) *= float(f);
    }
  }
}

void PhotoEffects::ApplyAfterSensor(Image* image) const {
  if (!response) return;
  const auto [exponent, reference] = *response;
  for (float& v : image->pixels) {
    const double mag = reference * std::pow(std::abs(v) / reference, exponent);
    v = float(v < 0 ? -mag : mag);
  }
}

namespace {

// The effects that change the photos after they were made, or a declared value only: params of
// `spec`'s effect, or nullopt when it changes what is rendered.
std::optional<Json> PhotoEffect(const EffectSpec& spec, Params& p,
                                const std::vector<recon::Camera>& cameras,
                                const std::vector<std::string>& photo_files, uint64_t seed,
                                SynthScenes* s, PhotoEffects* post) {
  const std::string& n = spec.name;
  if (n == "vignetting") return Vignetting(p, post);
  if (n == "exposure_scale") return ExposureScale(p, photo_files, post);
  if (n == "camera_response") return Response(p, post);
  if (n == "pose_error") return PoseError(p, cameras, seed, s);
  return std::nullopt;
}

// The effects that change what is rendered: params of `spec`'s effect.
Json SceneEffect(const EffectSpec& spec, Params& p, const SynthRoom& room, SynthScenes* s) {
  const std::string& n = spec.name;
  if (n == "light_emission_profile") return EmissionProfile(p, room, s);
  if (n == "anisotropic_reflection") return Anisotropy(p, room, s);
  if (n == "light_source_extent") return SourceExtent(p, room, s);
  if (n == "missing_geometry") return MissingGeometry(p, s);
  if (n == "ambient_light") return Ambient(p, room, s);
  if (n == "specular_lobe_shape") return LobeShape(p, room, s);
  if (n == "light_intensity") return Intensity(p, room, s);
  if (n == "specular_reflection") return SpecularAsDiffuse(p, room, s);
  if (n == "fresnel") return Fresnel(p, room, s);
  if (n == "diffuse_shape") return DiffuseShapeEffect(p, room, s);
  p.Fail("", "", "unknown effect");
}

}  // namespace

Json ApplyEffects(const std::vector<EffectSpec>& specs, const SynthRoom& room,
                  const std::vector<PlacedCamera>& cameras,
                  const std::vector<std::string>& photo_files, uint64_t seed, SynthScenes* s,
                  PhotoEffects* post) {
  std::vector<recon::Camera> plain;
  for (const PlacedCamera& c : cameras) plain.push_back(c.camera);
  Json list = Json::array();
  for (const EffectSpec& spec : specs) {
    Params p(spec);
    std::optional<Json> params = PhotoEffect(spec, p, plain, photo_files, seed, s, post);
    if (!params) params = SceneEffect(spec, p, room, s);
    list.push_back(Json{{"effect", spec.name}, {"params", *params}});
  }
  return list;
}

Json ApplyPhotoEffects(const std::vector<EffectSpec>& specs,
                       const std::vector<recon::Camera>& cameras,
                       const std::vector<std::string>& photo_files, uint64_t seed, SynthScenes* s,
                       PhotoEffects* post) {
  Json list = Json::array();
  for (const EffectSpec& spec : specs) {
    Params p(spec);
    const std::optional<Json> params = PhotoEffect(spec, p, cameras, photo_files, seed, s, post);
    if (!params) {
      p.Fail("", "",
             "changes what is rendered: only a capture igi-synth renders can hide it (with "
             "--from: vignetting, exposure_scale, camera_response, pose_error)");
    }
    list.push_back(Json{{"effect", spec.name}, {"params", *params}});
  }
  return list;
}

}  // namespace igi::synth
