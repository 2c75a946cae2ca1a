#pragma once
// Candidate effects (CONTRACT.md §6 names): each studies the residual of the current model in
// the frame where its physics shows itself, fits a model of it on the fitted (not held-out)
// samples, and predicts the residual it would leave on the held-out samples. The best candidate
// is then applied to the scene and the whole scene refitted (solver/diagnose/diagnose.cpp).
//
// Each candidate's fit is linear in its amplitudes (nonlinear parameters — a response exponent,
// an emission axis, a lobe width — are searched on a grid), with the global scale free as a
// nuisance where the materials are solved (it is absorbed by the albedos when refitted).

#include <array>
#include <functional>
#include <string>
#include <vector>

#include "recon/scene.h"
#include "solver/diagnose/pixel_records.h"
#include "tools/common/json.h"

namespace igi {

struct CandidateContext {
  const Scene& model;     // the current (complete) model
  const Json& declared;   // the declared scene document (absolute paths)
  bool materials_solved;  // unknown materials are re-solved after each step
  double cell_m = 0.05;   // surface cell of regions with albedo maps (their free albedo)
  int block_px = 16;      // held-out block: the unit of the gain's standard error
  // The searches over a candidate's nonlinear parameters (an emission profile's axis, a source's
  // radius, an anisotropic lobe) run on a subsample of about this many fitted records; the
  // parameters they find are then fitted and scored on every record.
  int search_records = 30000;
};

struct CandidateResult {
  std::string effect;
  std::string evidence;
  Json where = Json::object();
  Json params = Json::object();
  int num_params = 0;
  // Predicted squared-error sums on the records (before: the current model).
  double train_before = 0, train_after = 0, held_before = 0, held_after = 0;
  double held_photo = 0;  // Σ photo² of the held-out records
  double z = 0;           // held-out gain over its standard error (across blocks)
  bool valid = false;
  std::string note;  // why a candidate could not be fitted (e.g. degenerate)
  // For an effect that changes the photos only in places (a source's extent: its penumbrae and
  // highlight edges), the held-out blocks (photo, block x, block y) where its change shows. The
  // step's significance then counts these blocks (its gain is still over every held-out block):
  // the others hold only the refit's small albedo changes and their noise. Empty: every block.
  std::vector<std::array<int, 3>> support_blocks;
  // Writes the fitted model into the declared scene document.
  std::function<void(Json* declared)> apply;

  double Gain() const { return held_before > 0 ? 1 - held_after / held_before : 0; }
  // The effect and what it applies to ("specular_lobe_shape:glossy_box"): a step is taken once
  // per key.
  std::string Key() const;
};

// The candidates a step refits, in the order it tries them: the valid ones whose predicted
// held-out gain reaches `min_gain` and whose z reaches `min_z`, best predicted first, except that
// when the two best are of one effect the best of another effect moves up to second. A step
// refits the first two and keeps the better; the rest only while none passes. Two of one effect
// are rival fits of one explanation (two lights' intensities standing in for the lightings'
// balance); the best other explanation is the real alternative.
std::vector<CandidateResult*> RankForTrials(std::vector<CandidateResult>& candidates,
                                            double min_gain, double min_z);

// The photos' file names (a candidate's "where" for effects of every photo).
std::vector<std::string> PhotoFiles(const Scene& model);

struct ResidualFit;
// Copies a fit's predicted squared-error sums and significance into a candidate.
void FillScores(const ResidualFit& fit, CandidateResult* out);

class ResidualFitter;
class RecordSubset;
// specular_reflection for `region` (declared diffuse): a Ward lobe whose ρs and α best explain
// the residual. Its apply() writes brdf "ward", with the fitted ρs and α where the region's
// albedo is declared (nothing is solved then), without them otherwise (igi-solve fits them).
CandidateResult SpecularReflection(const CandidateContext& context, const ResidualFitter& fitter,
                                   int region);

// camera_response: the photos follow the model's value through a power about a reference,
// ref·(v/ref)^e (photo_model.h). The exponent is searched on the residual with a fit corrected
// for the renders' noise in the model's value (ResidualFitter::FitNoisyBasis).
CandidateResult Response(const CandidateContext& context, const ResidualFitter& fitter);

// light_emission_profile for light `light` (index into model.lights): the light's direct term
// becomes cos^n of the angle from an axis (a "spot" with a cos_power profile). The axis and n are
// searched with a camera response as a nuisance (so that a response the photos also hide does not
// bend them) and scored without it. The search runs on `search`'s records when given (a subsample
// of the fitter's), the final fit and its scores on the fitter's.
CandidateResult EmissionProfile(const CandidateContext& context, const ResidualFitter& fitter,
                                int light, const RecordSubset* search = nullptr);

// specular_lobe_shape (ward <-> ward_gmd) and fresnel (plain -> *_fresnel) on glossy region
// `region`: the change of its specular term. With the materials given (the refit keeps ρs and α)
// the alternative lobe less the current one at the same values, with an amplitude that must stay
// near 1; with them solved (the refit re-solves ρs and α) the current lobe is replaced by the
// alternative at a searched α' with a free ρs scale, and credited only with what it explains
// beyond the current model re-fitted the same way. fresnel also searches the index.
CandidateResult LobeChange(const CandidateContext& context, const ResidualFitter& fitter,
                           int region, bool fresnel);

// Every candidate that applies to this scene, fitted on `records`, except those whose Key() is in
// `excluded` (they are not fitted at all).
std::vector<CandidateResult> EvaluateCandidates(const CandidateContext& context,
                                                const std::vector<PixelRecord>& records,
                                                const std::vector<std::string>& excluded);

}  // namespace igi
