#pragma once
// Options of igi-synth: a synthetic capture with known truth (truth.json: docs/file-formats.md).
//
// A cubical room (metres, z up) with Lambertian and glossy regions, a textured floor, a small
// lamp (lighting L0) and a second lamp (lighting L1, for relighting checks), rendered by the
// forward model from cameras placed so that each glossy region shows the lamp's highlight.
// Effects (docs/diagnose-effects.md names) make the photos differ from what scene.json declares;
// each is listed with its parameters in truth.json.

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "recon/brdf_model.h"

namespace igi::synth {

// One --effect switch: NAME or NAME:key=value,key=value (values are numbers, names or
// number lists separated by '/', e.g. tangent=1/0/0).
struct EffectSpec {
  std::string name;
  std::map<std::string, std::string> params;
};

// Parses the text of one --effect flag. Throws InputError "--effect: TEXT: RULE".
EffectSpec ParseEffectSpec(const std::string& text);

// The effects igi-synth can put into the photos (docs/diagnose-effects.md names).
const std::vector<std::string>& SupportedEffects();

enum class NoiseModel { kNone, kRealistic };
enum class ResponseKind { kGamma, kSigmoid, kFile };

// The image file format of the LDR brackets: PNG or TIFF.
enum class BracketFormat { kPng, kTif };
// "png", "tif" (the --bracket-format flag's spelling and the files' extension).
std::string_view BracketFormatName(BracketFormat format);
std::optional<BracketFormat> BracketFormatFromName(std::string_view name);

// The photographed lamps: a sphere of radius 4 cm or a point light.
enum class LampShape { kSphere, kPoint };
// "sphere", "point" (the --lamp flag's spelling).
std::string_view LampShapeName(LampShape shape);
std::optional<LampShape> LampShapeFromName(std::string_view name);

// The floor's albedo texture (SynthOptions::floor_texture): kTiles or kSmooth.
enum class FloorTexture { kTiles, kSmooth };
// "tiles", "smooth" (the --floor-texture flag's spelling and truth.json's "floor_texture").
std::string_view FloorTextureName(FloorTexture texture);
std::optional<FloorTexture> FloorTextureFromName(std::string_view name);

// The choice options as igi-synth's flags spell them, before they are parsed (SynthOptions::
// SetChoices); each default is the name of the option's default.
struct SynthChoiceFlags {
  std::string glossy_brdf = "ward";
  std::string lamp = "sphere";
  std::string floor_texture = "tiles";
  std::string bracket_format = "png";
};

// The camera sensor of --noise realistic and of the LDR brackets. Signal in electrons:
//   e = radiance · electrons_per_radiance_s · exposure_s, shot noise Poisson(e), read noise
//   N(0, read_noise_e²), clipped at full_well_e, quantised by an ADC of adc_bits bits with a
//   black level; photos are converted back to radiance units (unbiased below saturation).
struct SensorOptions {
  double full_well_e = 20000;              // electrons at saturation, > 0
  double read_noise_e = 4;                 // rms read noise in electrons, >= 0
  int adc_bits = 14;                       // raw quantisation, 8..16
  int black_level_dn = 64;                 // ADC offset (keeps read noise below 0 unbiased)
  double electrons_per_radiance_s = 1000;  // sensitivity: e⁻ per (W·sr⁻¹·m⁻² · s), > 0
  double exposure_s = 0;                   // 0 = auto: the photo's 99th percentile at 80% well
  void Validate() const;                   // throws InputError naming the flag
};

// LDR exposure brackets for the HDR stage: each photo's radiance seen through `response`.
struct BracketOptions {
  int count = 0;       // brackets per photo; 0 = none
  double stops = 2.0;  // EV between neighbouring brackets, > 0
  // How a bracket's levels follow x = e/full_well: kGamma, kSigmoid or kFile (below).
  ResponseKind response = ResponseKind::kGamma;
  double gamma = 2.2;             // kGamma: level = x^(1/gamma) for x = e/full_well
  double sigmoid_contrast = 1.6;  // kSigmoid: x^c/(x^c + m^c), normalised to 1 at x = 1
  // kSigmoid: m, the x at which the curve before normalisation is ½, in (0, 1).
  double sigmoid_mid = 0.18;
  std::filesystem::path response_file;         // kFile: an igi-response JSON (docs/file-formats.md)
  int bits = 8;                                // 8 or 16
  BracketFormat format = BracketFormat::kPng;  // kPng (default) or kTif
  void Validate() const;
};

struct SynthOptions {
  std::filesystem::path out;  // scene folder to write (must be empty or absent)
  bool overwrite = false;     // allow a non-empty `out` (files of the same name are replaced)
  int cameras = 5;            // >= 1; the first ones target the glossy regions' highlights
  // The last N of the overview cameras look up across the room so that the ceiling is seen
  // (the default views look down at the floor and never see it).
  int ceiling_cameras = 0;
  int width = 160;  // photo size, pixels
  int height = 120;
  double fov_deg = 60;  // horizontal field of view
  int spp = 64;         // render samples per pixel
  uint64_t seed = 1;    // same seed, same options -> same files
  // The glossy regions' true model: BrdfModel::kWard (default), kWardGmd, kGgx or kBeckmann.
  recon::BrdfModel glossy_brdf = recon::BrdfModel::kWard;
  LampShape lamp = LampShape::kSphere;  // kSphere (default; r = 4 cm) or kPoint
  // The photographed lamp's centre (default (2.3, 1.7, 2.4), below the ceiling; inside the room).
  std::optional<Eigen::Vector3d> lamp_position;
  // Extra cameras, after the others, that see the floor's highlight at grazing incidence
  // (60–80° from the normal, mirror view): where a Fresnel-weighted lobe differs most from a
  // plain one. Under the default lamp the room has no such view (it needs a lamp below about
  // 0.8 m, --lamp-position).
  int grazing_cameras = 0;
  // Material keys left out of scene.json (unknowns for the solver), for every reflective
  // region: any of rho_d (also removes rho_d_map), rho_s, alpha (also alpha_x/alpha_y/tangent).
  std::vector<std::string> unknowns = {"rho_d", "rho_s", "alpha"};
  std::vector<std::string> photo_lightings = {"L0"};       // photographed (in scene.json)
  std::vector<std::string> validation_lightings = {"L1"};  // truth.json "validation"
  // kNone: the photos are the rendered radiance; kRealistic: seen through `sensor` (noise,
  // clipping, quantisation), clipped pixels masked.
  NoiseModel noise = NoiseModel::kNone;
  // The sensor of kRealistic noise and of the brackets.
  SensorOptions sensor;
  // LDR exposure brackets of every photo, under brackets/ (count 0: none).
  BracketOptions brackets;
  // The --effect switches: what the photos show that scene.json does not declare.
  std::vector<EffectSpec> effects;
  int num_threads = 0;  // 0 = process default
  // Every region (walls, ceiling, floor, boxes, sphere) gets a high-frequency albedo texture
  // (rho_d_map; value noise over several octaves times the region's colour), so that
  // structure-from-motion finds features everywhere (registration tests). Off: only the floor
  // is textured.
  bool textured_walls = false;
  // The floor's albedo texture: kTiles (default; 4 × 4 tiles, one-texel grout lines and a
  // per-texel grain: detail finer than the photos' pixel footprint), or kSmooth: the same tiles
  // and grout without the grain, low-pass filtered (Gaussian, σ = 2 texels = 6.25 cm) so that the
  // photos resolve it (albedo-map accuracy tests: the truth is then recoverable from the pixels).
  FloorTexture floor_texture = FloorTexture::kTiles;
  // The matte box is a satin finish instead of Lambertian: a faint, broad lobe of the glossy
  // model (ρd 0.6/0.6/0.55, ρs 0.03, α 0.25), whose "highlight" covers most of what a camera
  // sees of it; it joins the glossy regions (last in placement order).
  bool satin = false;
  // A striped poster (region "poster", Lambertian, 1.2 m × 0.9 m, 5 mm in front of wall_x4):
  // vertical stripes of 10 cm in four colours whose channels differ (rho_d_map), for the albedo
  // map's per-channel balance.
  bool poster = false;
  // scene.json declares no "cameras" and no "photos" (an unposed capture: the poses must be
  // recovered, e.g. by igi-register); truth/scene.json keeps the true cameras.
  bool unposed = false;
  // An existing capture's scene.json whose photos get the effects instead of a rendered room
  // (vignetting, exposure_scale, camera_response, pose_error: the effects that need no render).
  std::filesystem::path from;

  // Every problem as one InputError (flag name, value, rule; a choice outside its enum: by its
  // name or number).
  void Validate() const;
  // Sets the choice options from their flags' text, then validates as Validate does: one
  // InputError with every problem, a text that names no choice as "--FLAG: TEXT: must be ..." in
  // its place among them.
  void SetChoices(const SynthChoiceFlags& flags);
};

}  // namespace igi::synth
