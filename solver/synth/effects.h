#pragma once
// The effects igi-synth puts into the photos while scene.json stays silent about them
// (docs/diagnose-effects.md names). Each effect changes the TRUE scene (what is rendered) or the
// photos after rendering, never the DECLARED scene — except pose_error and specular_reflection,
// whose declared value is the wrong one. Each returns its truth.json entry
// {"effect": NAME, "params": {...}} with every number needed to undo it.
//
//   vignetting              photo × (1 + k1 r² + k2 r⁴), r = distance to the principal point
//                           over half the image diagonal (k1=-0.25, k2=-0.05)
//   light_emission_profile  the lamp is truly a spot with profile cos^n (n=2, axis -z), same
//                           peak intensity; declared isotropic (light=lamp, cos_power, direction)
//   anisotropic_reflection  a region is truly ward_aniso (region=glossy_box, alpha_x=0.03,
//                           alpha_y=0.15, tangent = the box's x axis); declared isotropic
//   light_source_extent     the lamp is truly a sphere of radius 0.25 m with the same intensity
//   missing_geometry        a box (0.35×0.35×0.45 m, lambert 0.6) stands on the floor
//   ambient_light           an undeclared "ambient" light (radiance 0.4: the same from every
//                           direction, never occluded; docs/scene-format.md's ambient light),
//                           on in every lighting; kind=panel: a dim 1.6×1.2 m area emitter of that
//                           radiance 2 mm in front of wall_x4 instead (stray light from a
//                           source, which also shades the wall from the lamp)
//   exposure_scale          one photo (photo=second photo) is scaled by `scale` (1.3)
//   camera_response         photo = reference·(L/reference)^exponent (0.8, 1.0)
//   pose_error              a camera's declared pose is off by rotation_deg (1°) about a random
//                           axis and translation_m (2 cm) in a random direction
//   specular_lobe_shape     the glossy regions are truly ward_gmd when declared ward, or the
//                           reverse (regions=a/b/c); to=ward|ward_gmd|beckmann|ggx: truly that
//                           lobe instead (its anisotropic form on an anisotropic region)
//   light_intensity         the lamp is truly `factor` (1.25) times brighter
//   specular_reflection     a glossy region (region=wall_y4) is declared lambert
//   fresnel                 the glossy regions (regions=a/b/c) are truly Fresnel-weighted
//                           (ward -> ward_fresnel, … : specular × F(c)/F0, Schlick, ior=1.5);
//                           declared without Fresnel (solver/render/brdf.h defines the models)
//   diffuse_shape           regions (regions=a/b/c; default: every region without a lobe) are
//                           truly Oren–Nayar surfaces of slope deviation sigma (0.4), same ρd;
//                           declared Lambertian

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "solver/synth/camera_placement.h"
#include "solver/synth/room_builder.h"
#include "solver/synth/synth_options.h"
#include "tools/common/image.h"
#include "tools/common/json.h"

namespace igi::synth {

// The two scene documents (igi-scene JSON, paths relative to the scene folder) and the extra
// files the true one needs (relative path -> OBJ text).
struct SynthScenes {
  Json true_scene;
  Json declared_scene;
  std::map<std::string, std::string> extra_files;
};

// Changes of the photos after rendering (linear radiance in, before or after the sensor).
struct PhotoEffects {
  std::optional<std::pair<double, double>> vignetting;  // k1, k2
  std::map<std::string, double> exposure_scale;         // photo file -> factor
  std::optional<std::pair<double, double>> response;    // exponent, reference

  // Optical and exposure effects, applied to the true radiance before the sensor.
  void ApplyBeforeSensor(const std::string& photo_file, const recon::Camera& camera,
                         Image* image) const;
  // The camera response, applied to the photo as written.
  void ApplyAfterSensor(Image* image) const;
  // The vignetting factor at continuous pixel (x, y) of `camera` (1 without vignetting).
  double VignettingFactor(const recon::Camera& camera, double x, double y) const;
};

// Applies `specs` in order. `photo_files` are the photos of scene.json ("photos/cam0_L0.exr").
// Throws InputError "--effect: NAME: KEY=VALUE: RULE" for a bad or unknown parameter.
Json ApplyEffects(const std::vector<EffectSpec>& specs, const SynthRoom& room,
                  const std::vector<PlacedCamera>& cameras,
                  const std::vector<std::string>& photo_files, uint64_t seed, SynthScenes* scenes,
                  PhotoEffects* photo_effects);

// The effects of `specs` that change a capture's photos after they were made (any renderer's or
// camera's), or a declared value only: vignetting, exposure_scale, camera_response, pose_error.
// `cameras` are the capture's. Throws InputError "--effect: NAME: ...: RULE" for any other.
Json ApplyPhotoEffects(const std::vector<EffectSpec>& specs,
                       const std::vector<recon::Camera>& cameras,
                       const std::vector<std::string>& photo_files, uint64_t seed, SynthScenes* s,
                       PhotoEffects* post);

}  // namespace igi::synth
