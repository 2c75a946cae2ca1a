#pragma once
// Options of igi-run (docs/run.md): the end-to-end chain from a folder of photos.

#include <filesystem>
#include <string>
#include <vector>

namespace igi::pipeline {

struct RunOptions {
  std::filesystem::path photos_dir;  // PHOTOS_DIR (layout: tools/pipeline/photo_layout.h); may be
                                     // empty with hdr_photos
  std::filesystem::path scene;       // scene.json: geometry, materials, lights, lightings
  std::filesystem::path out;         // DIR: 01-response ... 06-report, report.html
  std::filesystem::path bin_dir;     // where igi-calib, igi-hdr, ... live (empty = igi-run's)
  // camera.json (igi-calib intrinsics and/or vignetting); empty = PHOTOS_DIR/camera.json if any.
  // Its intrinsics go to igi-register, its vignetting to igi-hdr (divided out of every photo).
  std::filesystem::path camera;
  // colour.json (igi-calib colour); empty = PHOTOS_DIR/colour.json if any. Applied by igi-hdr.
  std::filesystem::path colour;
  // lights.json (igi-calib lights); empty = PHOTOS_DIR/lights.json if any. Its lights replace the
  // scene's entries of the same names in the scene igi-solve and igi-diagnose get.
  std::filesystem::path lights;
  // The photos are radiance maps already and the scene has its cameras and photos: the
  // response, HDR and registration stages are skipped and the scene is solved as it is.
  bool hdr_photos = false;
  bool skip_diagnose = false;  // the diagnosis stage is skipped (e.g. igi-diagnose not built)
  std::vector<std::string> solve_args;     // passed to igi-solve as they are
  std::vector<std::string> register_args;  // passed to igi-register as they are
  int diagnose_spp = 0;                    // --spp of igi-diagnose (0 = its default)
  std::vector<std::string> diagnose_args;  // passed to igi-diagnose as they are
  // Absolute calibration: the HDR maps are this many times the radiance in the scene's units
  // (W sr^-1 m^-2 for the declared light intensities), e.g. measured against a radiance
  // standard or a grey card. Written as every photo's "exposure_scale" in the scene igi-solve
  // gets (04-solve/input/scene.json). 1 = the maps are absolute already. It matters beyond a
  // scale: light bounces between surfaces in proportion to their absolute albedo.
  double radiance_scale = 1.0;
  std::string stop_after;    // a stage name: stop after it (empty = run every stage)
  int report_spp = 32;       // samples per pixel of the report's renders, >= 1
  int report_photos = 4;     // photos shown with their re-render and residual, >= 1
  int report_lightings = 6;  // lightings of the relit renders, >= 1
  // The report's renders and its photos' figures at most this many megapixels: each camera
  // rendered at its size divided by ReductionFactor, each photo shown as the means of its blocks
  // of that size (0 = the photos' size).
  double report_megapixels = 0.5;
  int num_threads = 0;  // --threads given to every stage (0 = all cores)

  void Validate() const;  // InputError naming the flag
};

}  // namespace igi::pipeline
