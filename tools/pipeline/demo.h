#pragma once
// igi-run --demo: a synthetic capture (igi-synth: a textured room, LDR brackets through a gamma
// response, unposed cameras) run through the whole chain, and the recovered parameters compared
// with the truth (DIR/demo_summary.json).
//
// The capture's PHOTOS_DIR is DIR/00-capture/synth/brackets (one NAME_L0 folder per photo), with
// camera.json (the true intrinsics, as igi-calib intrinsics would give) and markers.json (the
// room's corners and surveyed targets at their pixels plus marker_noise_px of noise, as a target
// detector finds them). HDR maps from a recovered
// response are radiance up to one constant (Debevec–Malik's g has a free offset), so the
// comparison states that constant k (median over regions of recovered/true ρd) and each
// region's ρd and ρs errors after dividing by k; α does not depend on it.

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "tools/common/json.h"
#include "tools/pipeline/pipeline.h"

namespace igi::pipeline {

// How the demo gives the HDR maps their absolute scale (DemoOptions::calibration): kReference,
// kMeasured or kNone.
enum class DemoCalibration { kReference, kMeasured, kNone };
// "reference", "measured", "none" (the --demo-calibration flag's spelling and
// demo_summary.json's "calibration").
std::string_view DemoCalibrationName(DemoCalibration calibration);
std::optional<DemoCalibration> DemoCalibrationFromName(std::string_view name);

// The choice options as igi-run's --demo flags spell them, before they are parsed
// (DemoOptions::SetChoices); each default is the name of the option's default.
struct DemoChoiceFlags {
  std::string calibration = "reference";
};

struct DemoOptions {
  // DIR (required): 00-capture (igi-synth's capture) and igi-run's stages under it.
  std::filesystem::path out;
  std::filesystem::path bin_dir;  // empty = igi-run's folder
  int cameras = 16;  // overview cameras, >= 3; COLMAP must match enough features between them
  // Photo size, pixels (at least 64 × 48); smaller photos give COLMAP fewer features to match.
  int width = 480;
  int height = 360;
  // igi-synth's render samples per pixel, >= 1.
  int spp = 8;
  // LDR exposures per photo (igi-synth --brackets) and the EV between neighbouring ones.
  int brackets = 3;
  double stops = 2;
  // Leave out 05-diagnose (igi-run --skip-diagnose).
  bool skip_diagnose = false;
  // --threads given to igi-synth and every stage (0 = all cores).
  int num_threads = 0;
  // Cameras that look up at the ceiling, on top of `cameras` (igi-synth gets cameras +
  // ceiling_cameras, --ceiling-cameras ceiling_cameras: its last overview cameras look up). A
  // ceiling no photo sees keeps a placeholder albedo, which removes light the rest of the room
  // receives. COLMAP matches no feature of theirs with the downward views; igi-register poses
  // them from the surveyed targets on the ceiling and upper walls (markers.json, see demo.cpp
  // SurveyedTargets). >= 0; more of them see more of the ceiling and upper walls, whose unseen
  // parts otherwise take their seen parts' albedo (measured: docs/run.md).
  int ceiling_cameras = 4;
  // The HDR maps' absolute scale (without it the albedos come out in the maps' arbitrary scale,
  // which weakens every bounce):
  //  - kReference: the capture holds a reference of known reflectance (reference_region, its
  //    material given in scene.json as if measured with a spectrophotometer) and igi-solve
  //    solves the photos' scale from it (--photo-scale solve);
  //  - kMeasured: the camera calibrated absolutely (igi-run --radiance-scale), as a lab camera
  //    measured against a radiance standard (simulated with igi-synth's noise-free radiance);
  //  - kNone.
  // kReference by default: it is what a user without a lab does (a grey card, a measured
  // wall) and needs no truth. Measured: docs/run.md.
  DemoCalibration calibration = DemoCalibration::kReference;
  // With kReference: the region whose true material is given (and left out of the comparison).
  std::string reference_region = "matte_box";
  // The control points' pixels are their true projections plus Gaussian noise of this standard
  // deviation (pixels, per axis, in [0, 10]; fixed seed), as a detector of printed targets
  // finds them (sub-pixel corners); 0 = exact projections. More noise: the photos posed from
  // markers alone (the ceiling cameras) come out further off (measured: docs/run.md).
  double marker_noise_px = 0.1;
  // Passed to igi-register: the control points weighed by the default marker noise, 0.1 px (its
  // own default, 1 px, is for hand-clicked points), and at most 1024 SIFT keypoints per photo
  // (COLMAP's default 8192), which shortens COLMAP's exhaustive matching.
  std::vector<std::string> register_args = {"--marker-sigma", "0.1", "--max-features", "1024"};
  // Passed to igi-solve (igi-run --solve-arg replaces them): the paper's stage only, from every
  // third pixel (fewer observations than igi-solve's default stride 2, a shorter solve).
  std::vector<std::string> solve_args = {"--refine-iterations", "0", "--pixel-stride", "3"};
  // Passed to igi-diagnose, the slowest stage (igi-run --diagnose-arg replaces them): residuals
  // at every fourth pixel, 16 paths per pixel (fixed), its solves from every fourth pixel
  // without refinement, at most two steps.
  std::vector<std::string> diagnose_args = {
      "--pixel-stride", "4", "--max-steps",         "2", "--spp",          "16",
      "--spp-max",      "0", "--refine-iterations", "0", "--solve-stride", "4"};
  // Samples per pixel of the report's renders (RunOptions::report_spp), >= 1.
  int report_spp = 16;
  // Throws InputError naming the flag and the rule (a choice outside its enum: by its number).
  void Validate() const;
  // Sets the choice options from their flags' text, then validates as Validate does: one
  // InputError with every problem, a text that names no choice as "--FLAG: TEXT: must be ..." in
  // its place among them.
  void SetChoices(const DemoChoiceFlags& flags);
};

struct DemoSummary {
  RunSummary run;
  Json summary;                    // DIR/demo_summary.json
  std::vector<std::string> table;  // lines: region, parameter, truth, recovered, error
};

DemoSummary RunDemo(const DemoOptions& options);

// The camera's absolute calibration, as a lab measures it against a known radiance: the median
// ratio of the HDR maps (hdr_dir/NAME.exr) to igi-synth's noise-free radiance of the same
// brackets (truth.json "brackets"), over every 7th pixel value.
double MeasureRadianceScale(const std::filesystem::path& hdr_dir,
                            const std::filesystem::path& synth_dir);

// The true albedo textures' mean over the surface some photo sees, per region with a texture
// (truth/scene.json's rho_d_map): `samples` points uniform by area on the textured regions,
// kept where a true camera sees them (in its frame, unoccluded), each texture read bilinearly
// at their UVs. The photos show part of each surface and the solver recovers that part: a
// texture's mean over its whole UV square is not what it can be compared with (measured on the
// demo: wall_x4's photos see 48 % of it, whose mean is 5.2 % below the whole's).
std::map<std::string, Eigen::Vector3d> SeenTrueAlbedo(const std::filesystem::path& truth_scene,
                                                      int samples = 200000, uint64_t seed = 1);

// The true albedo textures' mean over the texels of the solved albedo maps that observations
// cover (igi-solve's REGION_seen.png beside each map), per region with a true texture and a
// solved map on the mesh's own UVs: exactly the surface the solver recovered. The cameras'
// geometric view (SeenTrueAlbedo) also counts what no valid pixel shows: measured on the demo,
// wall_x4's truth there 0.2752, over its solved map's seen texels 0.2669 (its map
// against the true texture texel by texel: 1.037 = k, whatever the row band).
std::map<std::string, Eigen::Vector3d> TrueAlbedoOverSolvedTexels(
    const std::filesystem::path& solved_scene, const std::filesystem::path& truth_json);

// Compares a solved scene with truth.json: per region and parameter (see demo.h's note on k).
// Regions in `given` (their material was given to the solver, e.g. the reference) are left out.
// A textured region's true rho_d is TrueAlbedoOverSolvedTexels' when the solve wrote its map's
// seen mask, else SeenTrueAlbedo's when truth/scene.json lies beside truth.json, else the
// texture's mean (truth.json's rho_d).
Json CompareWithTruth(const std::filesystem::path& solved_scene,
                      const std::filesystem::path& truth_json,
                      const std::vector<std::string>& given = {});

// Compares the registered cameras (03-register/scene.json: one camera per photo, named after it)
// with the true ones (truth/scene.json: camN for photo camN_LIGHTING): per photo the rotation
// error (degrees) and the position error (metres), whether the true camera looks up (at the
// ceiling), and how many photos were registered ("registered"; RunDemo adds "photos", the
// capture's count).
Json ComparePoses(const std::filesystem::path& registered_scene,
                  const std::filesystem::path& truth_scene);

}  // namespace igi::pipeline
