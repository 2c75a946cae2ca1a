// igi-synth: writes a synthetic capture with known truth (docs/file-formats.md, truth.json): a
// room scene folder (scene.json, geometry, photos, optional LDR brackets) plus truth.json, with
// optional effects that the photos show and scene.json does not declare.
#include <cstdio>
#include <optional>

#include "solver/synth/synthesize.h"
#include "tools/common/cli.h"
#include "tools/common/error.h"
#include "tools/common/strings.h"

namespace {

std::vector<std::string> List(const std::string& text) {
  if (text == "none") return {};
  return igi::SplitTokens(text, ",");
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Write a synthetic room capture with known truth (scene.json, photos, truth.json)",
               "igi-synth"};
  igi::CommonFlags flags;
  igi::AddCommonFlags(app, &flags, /*computes=*/true);
  igi::synth::SynthOptions o;
  // The choice flags as typed; SetChoices parses them into `o` and validates every option.
  igi::synth::SynthChoiceFlags choices;
  std::string noise = "none", response = "gamma", unknowns = "rho_d,rho_s,alpha";
  std::string photo_lightings = "L0", validation_lightings = "L1", lamp_position;
  std::vector<std::string> effects;
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
  app.add_option("--glossy-brdf", choices.glossy_brdf,
                 "True model of the glossy regions: ward|ward_gmd|ggx|beckmann");
  app.add_option("--lamp", choices.lamp, "Lamp type: sphere (r = 4 cm) or point");
  app.add_option("--lamp-position", lamp_position,
                 "Centre of the photographed lamp, x,y,z in metres (default 2.3,1.7,2.4)");
  app.add_option("--grazing-cameras", o.grazing_cameras,
                 "Extra cameras seeing the floor's highlight at 60-80 deg incidence (Fresnel; "
                 "needs a low lamp, e.g. --lamp-position 2,2,0.6)");
  app.add_option("--floor-texture", choices.floor_texture,
                 "Floor albedo: tiles (grout lines and grain finer than a pixel) or smooth (the "
                 "tiles low-pass filtered, sigma 6 cm, resolved by the photos)");
  app.add_option("--unknowns", unknowns,
                 "Material keys left out of scene.json: list of rho_d,rho_s,alpha or none");
  app.add_option("--photo-lightings", photo_lightings, "Lightings photographed: L0[,L1]");
  app.add_option("--validation-lightings", validation_lightings,
                 "Lightings rendered for validation only: L1[,L0] or none");
  app.add_option("--noise", noise, "Sensor noise: none|realistic");
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
  app.add_option("--response", response, "Bracket camera response: gamma|sigmoid|file");
  app.add_option("--response-file", o.brackets.response_file,
                 "igi-response JSON for --response file");
  app.add_option("--gamma", o.brackets.gamma, "Gamma of --response gamma");
  app.add_option("--sigmoid-contrast", o.brackets.sigmoid_contrast,
                 "Contrast of --response sigmoid");
  app.add_option("--sigmoid-mid", o.brackets.sigmoid_mid, "Mid exposure of --response sigmoid");
  app.add_option("--bracket-bits", o.brackets.bits, "8 or 16");
  app.add_option("--bracket-format", choices.bracket_format, "png or tif");
  app.add_option("--effect", effects,
                 "Effect in the photos, not in scene.json: NAME[:key=value,...] (repeatable)");
  return igi::RunMain(app, flags, argc, argv, [&] {
    igi::ProblemList problems;
    if (noise == "none")
      o.noise = igi::synth::NoiseModel::kNone;
    else if (noise == "realistic")
      o.noise = igi::synth::NoiseModel::kRealistic;
    else
      problems.Add("--noise", "", noise, "must be none or realistic");
    if (response == "gamma")
      o.brackets.response = igi::synth::ResponseKind::kGamma;
    else if (response == "sigmoid")
      o.brackets.response = igi::synth::ResponseKind::kSigmoid;
    else if (response == "file")
      o.brackets.response = igi::synth::ResponseKind::kFile;
    else
      problems.Add("--response", "", response, "must be gamma, sigmoid or file");
    if (!lamp_position.empty()) {
      const std::vector<std::string> parts = igi::SplitTokens(lamp_position, ",");
      std::vector<double> v;
      for (const std::string& s : parts) {
        if (const std::optional<double> d = igi::ParseDouble(s)) v.push_back(*d);
      }
      if (v.size() == 3 && parts.size() == 3) {
        o.lamp_position = Eigen::Vector3d(v[0], v[1], v[2]);
      } else {
        problems.Add("--lamp-position", "", lamp_position, "must be three numbers x,y,z");
      }
    }
    o.unknowns = List(unknowns);
    o.photo_lightings = List(photo_lightings);
    o.validation_lightings = List(validation_lightings);
    for (const std::string& e : effects) {
      try {
        o.effects.push_back(igi::synth::ParseEffectSpec(e));
      } catch (const igi::Error& err) {
        problems.Append(err);
      }
    }
    problems.ThrowIfAny();
    o.num_threads = flags.threads;
    o.SetChoices(choices);
    const igi::synth::SynthSummary s = igi::synth::Synthesize(o);
    std::printf("wrote %s: %zu photos, %zu validation renders, %lld saturated pixels, %.1f s\n",
                o.out.c_str(), s.photos.size(), s.validation.size(),
                static_cast<long long>(s.saturated_pixels), s.seconds);
    return 0;
  });
}
