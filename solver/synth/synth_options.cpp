#include "solver/synth/synth_options.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <string_view>

#include "tools/common/enum_names.h"
#include "tools/common/error.h"
#include "tools/common/strings.h"

namespace igi::synth {
namespace {

std::string Str(double v) {
  std::string s = std::to_string(v);
  while (s.size() > 1 && s.back() == '0') s.pop_back();
  if (!s.empty() && s.back() == '.') s.pop_back();
  return s;
}

bool Contains(const std::vector<std::string>& list, const std::string& name) {
  return std::find(list.begin(), list.end(), name) != list.end();
}

// The text a choice's problem names: the flag's text when `typed`, else the value's name, or its
// number where that name is "?" (a value outside the enum).
template <typename E>
std::string ChoiceText(E value, std::string_view (*name)(E), const std::string* typed) {
  if (typed) return *typed;
  const std::string_view n = name(value);
  return n == "?" ? std::to_string(int(value)) : std::string(n);
}

ProblemList BracketProblems(const BracketOptions& b, const std::string* typed_format) {
  ProblemList p;
  if (b.count < 0 || b.count > 16)
    p.Add("--brackets", "", std::to_string(b.count), "must be 0..16");
  if (!(b.stops > 0) || b.stops > 8) p.Add("--stops", "", Str(b.stops), "must be in (0, 8]");
  if (!(b.gamma > 0.1) || b.gamma > 10) p.Add("--gamma", "", Str(b.gamma), "must be in (0.1, 10]");
  if (!(b.sigmoid_contrast > 0.2) || b.sigmoid_contrast > 10) {
    p.Add("--sigmoid-contrast", "", Str(b.sigmoid_contrast), "must be in (0.2, 10]");
  }
  if (!(b.sigmoid_mid > 0) || b.sigmoid_mid >= 1) {
    p.Add("--sigmoid-mid", "", Str(b.sigmoid_mid), "must be in (0, 1)");
  }
  if (b.response == ResponseKind::kFile && b.response_file.empty()) {
    p.Add("--response-file", "", "", "required with --response file");
  }
  if (b.bits != 8 && b.bits != 16) {
    p.Add("--bracket-bits", "", std::to_string(b.bits), "must be 8 or 16");
  }
  if (typed_format ? !BracketFormatFromName(*typed_format)
                   : !BracketFormatFromName(BracketFormatName(b.format))) {
    p.Add("--bracket-format", "", ChoiceText(b.format, BracketFormatName, typed_format),
          "must be png or tif");
  }
  return p;
}

// Every problem of `o`; with `typed`, each choice is judged by its flag's text.
ProblemList SynthProblems(const SynthOptions& o, const SynthChoiceFlags* typed) {
  ProblemList p;
  if (o.out.empty()) p.Add("--out", "", "", "required");
  if (o.cameras < 1 || o.cameras > 64) {
    p.Add("--cameras", "", std::to_string(o.cameras), "must be 1..64");
  }
  if (o.ceiling_cameras < 0 || o.ceiling_cameras > o.cameras) {
    p.Add("--ceiling-cameras", "", std::to_string(o.ceiling_cameras), "must be 0..--cameras");
  }
  if (o.width < 8 || o.width > 8192) {
    p.Add("--width", "", std::to_string(o.width), "must be 8..8192");
  }
  if (o.height < 8 || o.height > 8192) {
    p.Add("--height", "", std::to_string(o.height), "must be 8..8192");
  }
  if (!(o.fov_deg >= 10) || o.fov_deg > 140) {
    p.Add("--fov", "", Str(o.fov_deg), "must be in [10, 140]");
  }
  if (o.spp < 1 || o.spp > 1 << 20) p.Add("--spp", "", std::to_string(o.spp), "must be >= 1");
  // Any BrdfModel has a name; only the isotropic lobes without an ior are the glossy regions'
  // choices.
  const std::optional<recon::BrdfModel> glossy =
      typed ? recon::BrdfModelFromName(typed->glossy_brdf)
            : std::optional<recon::BrdfModel>(o.glossy_brdf);
  if (!glossy || !recon::HasSpecularLobe(*glossy) || recon::IsAnisotropic(*glossy) ||
      recon::HasFresnel(*glossy)) {
    p.Add("--glossy-brdf", "",
          ChoiceText(o.glossy_brdf, recon::BrdfModelName, typed ? &typed->glossy_brdf : nullptr),
          "must be ward, ward_gmd, ggx or beckmann");
  }
  if (typed ? !LampShapeFromName(typed->lamp) : !LampShapeFromName(LampShapeName(o.lamp))) {
    p.Add("--lamp", "", ChoiceText(o.lamp, LampShapeName, typed ? &typed->lamp : nullptr),
          "must be sphere or point");
  }
  if (o.lamp_position) {
    const Eigen::Vector3d& q = *o.lamp_position;
    // The room spans [0, 4] × [0, 4] × [0, 3] m (room_builder.h).
    if (!(q.x() >= 0.1 && q.x() <= 3.9 && q.y() >= 0.1 && q.y() <= 3.9 && q.z() >= 0.1 &&
          q.z() <= 2.9)) {
      p.Add("--lamp-position", "", fmt::format("{},{},{}", q.x(), q.y(), q.z()),
            "must lie inside the room, 0.1 m from its walls (x, y in [0.1, 3.9], z in [0.1, 2.9])");
    }
  }
  if (o.grazing_cameras < 0 || o.grazing_cameras > 8) {
    p.Add("--grazing-cameras", "", std::to_string(o.grazing_cameras), "must be 0..8");
  }
  if (typed ? !FloorTextureFromName(typed->floor_texture)
            : !FloorTextureFromName(FloorTextureName(o.floor_texture))) {
    p.Add("--floor-texture", "",
          ChoiceText(o.floor_texture, FloorTextureName, typed ? &typed->floor_texture : nullptr),
          "must be tiles or smooth");
  }
  for (const std::string& u : o.unknowns) {
    if (u != "rho_d" && u != "rho_s" && u != "alpha") {
      p.Add("--unknowns", "", u, "must be a list of rho_d, rho_s, alpha (or none)");
    }
  }
  auto check_lightings = [&](const char* flag, const std::vector<std::string>& list) {
    for (const std::string& l : list) {
      if (l != "L0" && l != "L1") p.Add(flag, "", l, "must be a list of L0, L1");
    }
  };
  check_lightings("--photo-lightings", o.photo_lightings);
  check_lightings("--validation-lightings", o.validation_lightings);
  if (o.photo_lightings.empty()) p.Add("--photo-lightings", "", "", "must name a lighting");
  std::vector<std::string> seen;
  for (const EffectSpec& e : o.effects) {
    if (Contains(seen, e.name)) p.Add("--effect", "", e.name, "effect given twice");
    seen.push_back(e.name);
  }
  if (!o.from.empty() && (o.brackets.count > 0 || o.unposed || o.noise != NoiseModel::kNone)) {
    p.Add("--from", "", o.from.string(),
          "takes the capture's photos as they are: no --brackets, "
          "--unposed or --noise");
  }
  if (o.num_threads < 0) p.Add("--threads", "", std::to_string(o.num_threads), "must be >= 0");
  try {
    o.sensor.Validate();
  } catch (const Error& e) {
    p.Append(e);
  }
  const ProblemList bracket_problems =
      BracketProblems(o.brackets, typed ? &typed->bracket_format : nullptr);
  for (const std::string& line : bracket_problems.problems()) p.Add(line);
  return p;
}

}  // namespace

constexpr EnumNames<BracketFormat, 2> kBracketFormatNames{
    {{BracketFormat::kPng, "png"}, {BracketFormat::kTif, "tif"}}};

std::string_view BracketFormatName(BracketFormat format) {
  return kBracketFormatNames.Name(format);
}
std::optional<BracketFormat> BracketFormatFromName(std::string_view name) {
  return kBracketFormatNames.FromName(name);
}

constexpr EnumNames<LampShape, 2> kLampShapeNames{
    {{LampShape::kSphere, "sphere"}, {LampShape::kPoint, "point"}}};

std::string_view LampShapeName(LampShape shape) { return kLampShapeNames.Name(shape); }
std::optional<LampShape> LampShapeFromName(std::string_view name) {
  return kLampShapeNames.FromName(name);
}

constexpr EnumNames<FloorTexture, 2> kFloorTextureNames{
    {{FloorTexture::kTiles, "tiles"}, {FloorTexture::kSmooth, "smooth"}}};

std::string_view FloorTextureName(FloorTexture texture) { return kFloorTextureNames.Name(texture); }
std::optional<FloorTexture> FloorTextureFromName(std::string_view name) {
  return kFloorTextureNames.FromName(name);
}

const std::vector<std::string>& SupportedEffects() {
  static const std::vector<std::string> kEffects = {
      "vignetting",       "light_emission_profile", "anisotropic_reflection", "light_source_extent",
      "missing_geometry", "ambient_light",          "exposure_scale",         "camera_response",
      "pose_error",       "specular_lobe_shape",    "light_intensity",        "specular_reflection",
      "fresnel",          "diffuse_shape"};
  return kEffects;
}

EffectSpec ParseEffectSpec(const std::string& text) {
  EffectSpec spec;
  const size_t colon = text.find(':');
  spec.name = std::string(Trim(text.substr(0, colon)));
  auto fail = [&](const std::string& rule) {
    throw InputError(DescribeProblem("--effect", "", text, rule));
  };
  if (spec.name == "indirect_illumination") {
    fail("effect not available: indirect illumination is always in the photos");
  }
  if (!Contains(SupportedEffects(), spec.name)) {
    fail("unknown effect (known: " + Join(SupportedEffects(), ", ") + ")");
  }
  if (colon == std::string::npos) return spec;
  for (const std::string& item : SplitTokens(text.substr(colon + 1), ",")) {
    const size_t eq = item.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == item.size()) {
      fail("parameters must be key=value separated by commas");
    }
    const std::string key(Trim(item.substr(0, eq)));
    if (spec.params.count(key) != 0) fail("parameter " + key + " given twice");
    spec.params[key] = std::string(Trim(item.substr(eq + 1)));
  }
  return spec;
}

void SensorOptions::Validate() const {
  ProblemList p;
  if (!(full_well_e > 0) || !std::isfinite(full_well_e)) {
    p.Add("--full-well", "", Str(full_well_e), "must be > 0");
  }
  if (!(read_noise_e >= 0) || !std::isfinite(read_noise_e)) {
    p.Add("--read-noise", "", Str(read_noise_e), "must be >= 0");
  }
  if (adc_bits < 8 || adc_bits > 16)
    p.Add("--adc-bits", "", std::to_string(adc_bits), "must be in [8, 16]");
  if (black_level_dn < 0 || black_level_dn >= (1 << std::clamp(adc_bits, 8, 16)) / 4) {
    p.Add("--black-level", "", std::to_string(black_level_dn),
          "must be >= 0 and below a quarter of the ADC range");
  }
  if (!(electrons_per_radiance_s > 0) || !std::isfinite(electrons_per_radiance_s)) {
    p.Add("--sensitivity", "", Str(electrons_per_radiance_s), "must be > 0");
  }
  if (!(exposure_s >= 0) || !std::isfinite(exposure_s)) {
    p.Add("--exposure", "", Str(exposure_s), "must be >= 0 (0 = auto)");
  }
  p.ThrowIfAny();
}

void BracketOptions::Validate() const { BracketProblems(*this, nullptr).ThrowIfAny(); }

void SynthOptions::Validate() const { SynthProblems(*this, nullptr).ThrowIfAny(); }

void SynthOptions::SetChoices(const SynthChoiceFlags& flags) {
  if (const auto g = recon::BrdfModelFromName(flags.glossy_brdf)) glossy_brdf = *g;
  if (const auto l = LampShapeFromName(flags.lamp)) lamp = *l;
  if (const auto t = FloorTextureFromName(flags.floor_texture)) floor_texture = *t;
  if (const auto f = BracketFormatFromName(flags.bracket_format)) brackets.format = *f;
  SynthProblems(*this, &flags).ThrowIfAny();
}

}  // namespace igi::synth
