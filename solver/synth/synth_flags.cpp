#include "solver/synth/synth_flags.h"

#include <optional>

#include "tools/common/error.h"
#include "tools/common/strings.h"

namespace igi::synth {
namespace {

// A comma-separated list; "none" is the empty list.
std::vector<std::string> List(const std::string& text) {
  if (text == "none") return {};
  return SplitTokens(text, ",");
}

}  // namespace

void AddSynthFlags(CLI::App& app, SynthFlags* flags) {
  SynthFlags& f = *flags;
  SynthOptions& o = f.options;
  app.add_option("--out", o.out, "Scene folder to write (empty or absent)")->required();
  app.add_option("--from", o.from,
                 "An existing capture's scene.json: hide the --effect(s) in its photos instead of "
                 "rendering a room (vignetting, exposure_scale, camera_response, pose_error)");
  app.add_flag("--overwrite", o.overwrite, "Allow a non-empty --out folder");
  app.add_flag("--textured-walls", o.textured_walls,
               "Give every region a high-frequency albedo texture (for registration tests)");
  app.add_flag("--satin", o.satin,
               "Make the matte box a satin finish: a faint broad lobe (rho_s 0.03, alpha 0.25) of "
               "--glossy-brdf's model");
  app.add_flag("--poster", o.poster,
               "Hang a striped poster (region poster, four colours, a rho_d_map) on wall_x4");
  app.add_flag("--unposed", o.unposed,
               "scene.json without cameras and photos (poses to be recovered); truth keeps them");
  app.add_option("--cameras", o.cameras, "Number of cameras (first ones see the highlights)");
  app.add_option("--ceiling-cameras", o.ceiling_cameras,
                 "How many of the last overview cameras look up so that the ceiling is seen");
  app.add_option("--width", o.width, "Photo width, pixels");
  app.add_option("--height", o.height, "Photo height, pixels");
  app.add_option("--fov", o.fov_deg, "Horizontal field of view, degrees");
  app.add_option("--spp", o.spp, "Render samples per pixel");
  app.add_option("--seed", o.seed, "Random seed (same seed, same files)");
  app.add_option("--glossy-brdf", f.choices.glossy_brdf,
                 "True model of the glossy regions: ward|ward_gmd|ggx|beckmann");
  app.add_option("--lamp", f.choices.lamp, "Lamp type: sphere (r = 4 cm) or point");
  app.add_option("--lamp-position", f.lamp_position,
                 "Centre of the photographed lamp, x,y,z in metres (default 2.3,1.7,2.4)");
  app.add_option("--grazing-cameras", o.grazing_cameras,
                 "Extra cameras seeing the floor's highlight at 60-80 deg incidence (Fresnel; "
                 "needs a low lamp, e.g. --lamp-position 2,2,0.6)");
  app.add_option("--floor-texture", f.choices.floor_texture,
                 "Floor albedo: tiles (grout lines and grain finer than a pixel) or smooth (the "
                 "tiles low-pass filtered, sigma 6 cm, resolved by the photos)");
  app.add_option("--unknowns", f.unknowns,
                 "Material keys left out of scene.json: list of rho_d,rho_s,alpha or none");
  app.add_option("--photo-lightings", f.photo_lightings, "Lightings photographed: L0[,L1]");
  app.add_option("--validation-lightings", f.validation_lightings,
                 "Lightings rendered for validation only: L1[,L0] or none");
  app.add_option("--noise", f.noise, "Sensor noise: none|realistic");
  app.add_option("--exposure", o.sensor.exposure_s, "Exposure time, s (0 = auto)");
  app.add_option("--full-well", o.sensor.full_well_e, "Full-well capacity, electrons");
  app.add_option("--read-noise", o.sensor.read_noise_e, "Read noise, electrons rms");
  app.add_option("--adc-bits", o.sensor.adc_bits, "ADC bits of the raw signal");
  app.add_option("--black-level", o.sensor.black_level_dn, "ADC black level, DN");
  app.add_option("--sensitivity", o.sensor.electrons_per_radiance_s,
                 "Electrons per (W sr^-1 m^-2 s)");
  app.add_option(
      "--brackets", o.brackets.count,
      "LDR brackets per photo (0 = none); their noise-free radiance goes to truth/radiance/");
  app.add_option("--stops", o.brackets.stops, "EV between brackets");
  app.add_option("--response", f.response, "Bracket camera response: gamma|sigmoid|file");
  app.add_option("--response-file", o.brackets.response_file,
                 "igi-response JSON for --response file");
  app.add_option("--gamma", o.brackets.gamma, "Gamma of --response gamma");
  app.add_option("--sigmoid-contrast", o.brackets.sigmoid_contrast,
                 "Contrast of --response sigmoid");
  app.add_option("--sigmoid-mid", o.brackets.sigmoid_mid, "Mid exposure of --response sigmoid");
  app.add_option("--bracket-bits", o.brackets.bits, "8 or 16");
  app.add_option("--bracket-format", f.choices.bracket_format, "png or tif");
  app.add_option("--effect", f.effects,
                 "Effect in the photos, not in scene.json: NAME[:key=value,...] (repeatable)");
}

SynthOptions FinishSynthFlags(const SynthFlags& f, int threads) {
  SynthOptions o = f.options;
  ProblemList problems;
  if (f.noise == "none")
    o.noise = NoiseModel::kNone;
  else if (f.noise == "realistic")
    o.noise = NoiseModel::kRealistic;
  else
    problems.Add("--noise", "", f.noise, "must be none or realistic");
  if (f.response == "gamma")
    o.brackets.response = ResponseKind::kGamma;
  else if (f.response == "sigmoid")
    o.brackets.response = ResponseKind::kSigmoid;
  else if (f.response == "file")
    o.brackets.response = ResponseKind::kFile;
  else
    problems.Add("--response", "", f.response, "must be gamma, sigmoid or file");
  if (!f.lamp_position.empty()) {
    const std::vector<std::string> parts = SplitTokens(f.lamp_position, ",");
    std::vector<double> v;
    for (const std::string& s : parts) {
      if (const std::optional<double> d = ParseDouble(s)) v.push_back(*d);
    }
    if (v.size() == 3 && parts.size() == 3) {
      o.lamp_position = Eigen::Vector3d(v[0], v[1], v[2]);
    } else {
      problems.Add("--lamp-position", "", f.lamp_position, "must be three numbers x,y,z");
    }
  }
  o.unknowns = List(f.unknowns);
  o.photo_lightings = List(f.photo_lightings);
  o.validation_lightings = List(f.validation_lightings);
  for (const std::string& e : f.effects) {
    try {
      o.effects.push_back(ParseEffectSpec(e));
    } catch (const Error& err) {
      problems.Append(err);
    }
  }
  problems.ThrowIfAny();
  o.num_threads = threads;
  o.SetChoices(f.choices);
  return o;
}

}  // namespace igi::synth
