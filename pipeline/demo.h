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
#include <string>
#include <vector>

#include "pipeline/pipeline.h"
#include "tools/common/json.h"

namespace igi {

struct DemoOptions {
  std::filesystem::path out;
  std::filesystem::path bin_dir;  // empty = igi-run's folder
  int cameras = 16;  // 12 at 320x240 registered nothing (measured); 16 at 480x360 as in tests/recon
  int width = 480;
  int height = 360;
  int spp = 8;
  int brackets = 3;
  double stops = 2;
  bool skip_diagnose = false;
  int num_threads = 0;
  // Cameras that look up at the ceiling, on top of `cameras` (igi-synth gets cameras +
  // ceiling_cameras, --ceiling-cameras ceiling_cameras: its last overview cameras look up). A
  // ceiling no photo sees keeps a placeholder albedo, which removes light the rest of the room
  // receives (measured without them: the walls' rho_d -7.5..+14.4 %). COLMAP matches no feature
  // of theirs with the downward views; igi-register poses them from the surveyed targets on the
  // ceiling and upper walls (markers.json, see demo.cpp SurveyedTargets). Four, not two: with two, the upper half of wall_x4 and most of the ceiling went unseen and took
  // their seen parts' albedo, and the light they bounce left wall_y4 +1.2 % (the solver's own on
  // that capture: +1.4 % from the true radiance); with four every ρd came within 0.8 % after k,
  // the poses within 0.071 deg / 2.5 mm (two runs; with two 0.087 deg / 5.5 mm), for 12 s more
  // (bench/RESULTS.md, End to end).
  int ceiling_cameras = 4;
  // The HDR maps' absolute scale (without it the albedos come out in the maps' arbitrary scale,
  // which weakens every bounce; measured: rho_s/k -27..-29 %):
  //  - "reference": the capture holds a reference of known reflectance (the matte box, its
  //    material given in scene.json as if measured with a spectrophotometer) and igi-solve
  //    solves the photos' scale from it (--photo-scale solve);
  //  - "measured": the camera calibrated absolutely (igi-run --radiance-scale), as a lab camera
  //    measured against a radiance standard (simulated with igi-synth's noise-free radiance);
  //  - "none".
  // "reference" by default: it is what a user without a lab does (a grey card, a measured
  // wall) and needs no truth. Measured with the ceiling seen (2 cameras looking up):
  // the scale solved -3.1 % (0.2208 against 0.2278), the regions' absolute errors as with
  // "measured" (rho_d -6.7..+7.8 % against -7.6..+6.6 %). Before the ceiling was seen it was
  // -13.3 %: the ceiling's placeholder albedo removed light that reaches the matte box (54 %
  // of its light is indirect).
  std::string calibration = "reference";
  std::string reference_region = "matte_box";
  // The control points' pixels are their true projections plus Gaussian noise of this standard
  // deviation (pixels, per axis; fixed seed), as a detector of printed targets finds them
  // (sub-pixel corners); 0 = exact projections. Measured with 0.3 px (careful
  // clicks): the photos posed from markers alone (the ceiling cameras) 0.11-0.12 deg off, one
  // COLMAP photo 0.156 deg / 9.8 mm (exact markers: every photo within 0.02 deg / 1.1 mm).
  double marker_noise_px = 0.1;
  // igi-register weighs the control points by the same sigma (its default, 1 px, is for
  // hand-clicked points). At most 1024 SIFT keypoints per photo (COLMAP's default 8192): the
  // exhaustive matching of the 18 photos (2 ceiling cameras then) 51.9 s -> 22.0 s, the poses as
  // accurate (measured: every photo registered, worst 0.089 deg / 5.7 mm either way).
  std::vector<std::string> register_args = {"--marker-sigma", "0.1", "--max-features", "1024"};
  // Every third pixel: 344 k observations, 92 s of CPU with the scale solved (every second
  // pixel: 773 k, 358 s; the same errors within the run-to-run spread).
  std::vector<std::string> solve_args = {"--refine-iterations", "0", "--pixel-stride", "3"};
  // The demo's diagnosis: coarser samples, its solves from every fourth pixel, at most two steps
  // (it is the slowest stage: 580 s of CPU with --solve-stride 4, 1146 s with igi-solve's
  // default stride 2, the same steps kept and rejected).
  std::vector<std::string> diagnose_args = {"--pixel-stride", "4",  "--max-steps",         "2",
                                            "--spp",          "16", "--refine-iterations", "0",
                                            "--solve-stride", "4"};
  int report_spp = 16;
  void Validate() const;
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

}  // namespace igi
