#pragma once
// The capture igi-diagnose analyses. Its tests are statistics over pixel blocks and its
// re-renders cost paths per pixel, so photos of many megapixels are analysed at a reduced size:
// each camera whose photos exceed `max_megapixels` gets the smallest integer factor f that brings
// them within it, and each of its photos is replaced by the means of its f × f pixel blocks (the
// radiance a camera with f× larger pixels records, docs/scene-format.md), with the camera's width,
// height and focal lengths and principal point divided by f (continuous coordinates scale by 1/f;
// the distortion terms are in normalised coordinates and stay). A block is valid only when every
// pixel in it is (finite, under the photo's clip level, inside its mask); the others are masked.
// A photo with a declared response is linearised before the mean and re-encoded after it.
//
// The reduced photos and their 8-bit masks are written, one photo in memory at a time, under
// `dir`, with a scene.json that differs from the declared one only in its cameras' intrinsics
// and its photos' files and masks.

#include <filesystem>
#include <map>
#include <string>

#include "recon/scene.h"
#include "tools/common/json.h"

namespace igi::diagnose {

struct AnalysisCapture {
  bool reduced = false;              // some camera's photos were reduced
  std::filesystem::path scene_file;  // the analysis scene.json (when reduced)
  // Per reduced camera: the factor and the reduced size.
  struct Reduction {
    int factor = 1;
    int width = 0, height = 0;
  };
  std::map<std::string, Reduction> cameras;
};

// Writes the reduced capture of `scene` under `dir` (nothing when no camera needs reducing);
// `declared` is its document with absolute paths.
AnalysisCapture ReduceCapture(const recon::Scene& scene, const Json& declared,
                              double max_megapixels, const std::filesystem::path& dir,
                              bool show_progress = false);

// A scene document of the analysis capture (absolute paths) with the declared cameras'
// intrinsics and the declared photos' files and masks put back; everything fitted (poses,
// vignetting, materials, lights, per-photo scales) is kept.
Json AtDeclaredSize(Json doc, const recon::Scene& declared);

// The analysis capture's description for diagnosis.json.
Json AnalysisCaptureJson(const AnalysisCapture& capture, double max_megapixels);

}  // namespace igi::diagnose
