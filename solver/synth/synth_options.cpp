#include "solver/synth/synth_options.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <string_view>

#include "tools/common/error.h"
#include "tools/common/strings.h"

namespace igi {
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

}  // namespace

const std::vector<std::string>& SupportedEffects() {
  static const std::vector<std::string> kEffects = {
      "vignetting",       "light_emission_profile", "anisotropic_reflection", "light_source_extent",
      "missing_geometry", "ambient_light",          "exposure_scale",         "camera_response",
      "pose_error",       "specular_lobe_shape",    "light_intensity",        "specular_reflection",
      "fresnel"};
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

void BracketOptions::Validate() const {
  ProblemList p;
  if (count < 0 || count > 16) p.Add("--brackets", "", std::to_string(count), "must be 0..16");
  if (!(stops > 0) || stops > 8) p.Add("--stops", "", Str(stops), "must be in (0, 8]");
  if (!(gamma > 0.1) || gamma > 10) p.Add("--gamma", "", Str(gamma), "must be in (0.1, 10]");
  if (!(sigmoid_contrast > 0.2) || sigmoid_contrast > 10) {
    p.Add("--sigmoid-contrast", "", Str(sigmoid_contrast), "must be in (0.2, 10]");
  }
  if (!(sigmoid_mid > 0) || sigmoid_mid >= 1) {
    p.Add("--sigmoid-mid", "", Str(sigmoid_mid), "must be in (0, 1)");
  }
  if (response == ResponseKind::kFile && response_file.empty()) {
    p.Add("--response-file", "", "", "required with --response file");
  }
  if (bits != 8 && bits != 16) p.Add("--bracket-bits", "", std::to_string(bits), "must be 8 or 16");
  if (format != "png" && format != "tif")
    p.Add("--bracket-format", "", format, "must be png or tif");
  p.ThrowIfAny();
}

void SynthOptions::Validate() const {
  ProblemList p;
  if (out.empty()) p.Add("--out", "", "", "required");
  if (cameras < 1 || cameras > 64) p.Add("--cameras", "", std::to_string(cameras), "must be 1..64");
  if (ceiling_cameras < 0 || ceiling_cameras > cameras) {
    p.Add("--ceiling-cameras", "", std::to_string(ceiling_cameras), "must be 0..--cameras");
  }
  if (width < 8 || width > 8192) p.Add("--width", "", std::to_string(width), "must be 8..8192");
  if (height < 8 || height > 8192) {
    p.Add("--height", "", std::to_string(height), "must be 8..8192");
  }
  if (!(fov_deg >= 10) || fov_deg > 140) p.Add("--fov", "", Str(fov_deg), "must be in [10, 140]");
  if (spp < 1 || spp > 1 << 20) p.Add("--spp", "", std::to_string(spp), "must be >= 1");
  if (glossy_brdf != "ward" && glossy_brdf != "ward_gmd") {
    p.Add("--glossy-brdf", "", glossy_brdf, "must be ward or ward_gmd");
  }
  if (lamp != "sphere" && lamp != "point") p.Add("--lamp", "", lamp, "must be sphere or point");
  if (lamp_position) {
    const Eigen::Vector3d& q = *lamp_position;
    // The room spans [0, 4] × [0, 4] × [0, 3] m (room_builder.h).
    if (!(q.x() >= 0.1 && q.x() <= 3.9 && q.y() >= 0.1 && q.y() <= 3.9 && q.z() >= 0.1 &&
          q.z() <= 2.9)) {
      p.Add("--lamp-position", "", fmt::format("{},{},{}", q.x(), q.y(), q.z()),
            "must lie inside the room, 0.1 m from its walls (x, y in [0.1, 3.9], z in [0.1, 2.9])");
    }
  }
  if (grazing_cameras < 0 || grazing_cameras > 8) {
    p.Add("--grazing-cameras", "", std::to_string(grazing_cameras), "must be 0..8");
  }
  if (floor_texture != "tiles" && floor_texture != "smooth") {
    p.Add("--floor-texture", "", floor_texture, "must be tiles or smooth");
  }
  for (const std::string& u : unknowns) {
    if (u != "rho_d" && u != "rho_s" && u != "alpha") {
      p.Add("--unknowns", "", u, "must be a list of rho_d, rho_s, alpha (or none)");
    }
  }
  auto check_lightings = [&](const char* flag, const std::vector<std::string>& list) {
    for (const std::string& l : list) {
      if (l != "L0" && l != "L1") p.Add(flag, "", l, "must be a list of L0, L1");
    }
  };
  check_lightings("--photo-lightings", photo_lightings);
  check_lightings("--validation-lightings", validation_lightings);
  if (photo_lightings.empty()) p.Add("--photo-lightings", "", "", "must name a lighting");
  std::vector<std::string> seen;
  for (const EffectSpec& e : effects) {
    if (Contains(seen, e.name)) p.Add("--effect", "", e.name, "effect given twice");
    seen.push_back(e.name);
  }
  if (!from.empty() && (brackets.count > 0 || unposed || noise != NoiseModel::kNone)) {
    p.Add("--from", "", from.string(),
          "takes the capture's photos as they are: no --brackets, "
          "--unposed or --noise");
  }
  if (num_threads < 0) p.Add("--threads", "", std::to_string(num_threads), "must be >= 0");
  try {
    sensor.Validate();
  } catch (const Error& e) {
    p.Append(e);
  }
  try {
    brackets.Validate();
  } catch (const Error& e) {
    p.Append(e);
  }
  p.ThrowIfAny();
}

}  // namespace igi
