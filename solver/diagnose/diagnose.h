#pragma once
// igi-diagnose (docs/diagnose.md): when the simulation and the photos differ, locate the
// mismatch, name the physics left out, model it, refit the whole scene, and keep the step only
// when the residual on held-out pixels improves; repeat until nothing significant is left.
//
// 1. The model: the scene as given, or — when material values are unknown — solved by igi-solve
//    with the held-out pixels (square blocks) left out.
// 2. Every photo is re-rendered (same seed each time, so differences between models are not
//    Monte Carlo noise) and compared with the photo at its valid pixels.
// 3. Each candidate effect (solver/diagnose/candidates.h) is fitted to the residual in its own
//    frame on the fitted pixels and scored on the held-out ones; the one that predicts the
//    largest significant held-out gain is written into the scene, the scene is refitted
//    (re-solved), re-rendered, and the step is kept when the held-out residual falls by at least
//    min_gain and min_z standard errors (blocks as the unit). Otherwise the next candidate is
//    tried.
// 4. What remains is reported per photo and region against an estimate of the noise floor.

#include <filesystem>
#include <string>
#include <vector>

#include "recon/scene.h"
#include "solver/diagnose/candidates.h"
#include "solver/diagnose/diagnose_options.h"
#include "tools/common/image.h"
#include "tools/common/json.h"

namespace igi::diagnose {

struct DiagnosisStep {
  CandidateResult candidate;  // what was fitted and predicted
  double residual_before = 0, residual_after = 0;  // all valid fitted pixels, refitted scene
  // Empty: the residuals are over every valid fitted pixel. A step not applied is rendered only
  // where its held-out test reads, and its fitted pixels' residual (before and after) is over a
  // regular subsample of them, named here ("every 8th pixel").
  std::string residual_pixels;
  double held_out_before = 0, held_out_after = 0;
  double z = 0;  // held-out gain over its standard error
  bool kept = false;
  std::string verdict;
  std::filesystem::path model_dir;  // the refitted scene of this step
  Image residual_before_image, residual_after_image;  // of the photo where the step helps most
  std::string image_photo;
};

struct DiagnosisSummary {
  double baseline_residual = 0, baseline_held_out = 0;
  double final_residual = 0, final_held_out = 0;
  double noise_floor = 0;  // estimate: white part of the residual (neighbour differences)
  std::vector<DiagnosisStep> steps;  // kept and rejected, in order
  std::vector<CandidateResult> last_candidates;  // candidates of the last round (none kept)
  Json unexplained = Json::array();
  bool solved = false;     // materials were unknown and solved
  std::filesystem::path final_model_dir;
  Json final_scene;        // the improved scene.json (paths relative to the output folder)
  std::vector<std::pair<Image, std::string>> final_images;  // photo, render, residual (first photo)
  Json analysis;  // the reduced capture analysed (AnalysisCaptureJson), null at full size
  Json memory;    // the memory plan and the peak (DiagnoseMemoryJson)
  Json render_noise;  // the photos' and renders' noise and the paths chosen (RenderNoiseJson)
  double seconds = 0;
};

// Diagnoses `scene` (loaded with geometry). Intermediate models go under out_dir/steps/.
DiagnosisSummary Diagnose(const recon::Scene& scene, const DiagnoseOptions& options,
                          const std::filesystem::path& out_dir);

// diagnosis.json (docs/file-formats.md), with igi's additions (noise floor, rejected steps).
Json DiagnosisJson(const DiagnosisSummary& summary, const DiagnoseOptions& options);

// Writes out_dir/diagnosis.json, out_dir/report.html and out_dir/scene.json (last), atomically.
void WriteDiagnosisOutputs(const DiagnosisSummary& summary, const DiagnoseOptions& options,
                           const std::filesystem::path& out_dir);

}  // namespace igi::diagnose
