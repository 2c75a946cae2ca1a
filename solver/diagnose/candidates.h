#pragma once
// A candidate: one effect (docs/diagnose-effects.md names) fitted to the residual of the current
// model on the fitted (not held-out) samples, with the residual it predicts on the held-out
// samples; and the ranking that decides which candidates a step refits
// (solver/diagnose/diagnose.cpp). The effects that make candidates: solver/diagnose/effect.h,
// solver/diagnose/effects/.

#include <array>
#include <string>
#include <vector>

#include "recon/scene.h"
#include "solver/diagnose/pixel_records.h"
#include "tools/common/json.h"

namespace igi::diagnose {

struct CandidateContext {
  const recon::Scene& model;  // the current (complete) model
  const Json& declared;       // the declared scene document (absolute paths)
  bool materials_solved;      // unknown materials are re-solved after each step
  double cell_m = 0.05;       // surface cell of regions with albedo maps (their free albedo)
  int block_px = 16;          // held-out block: the unit of the gain's standard error
  // The searches over a candidate's nonlinear parameters (an emission profile's axis, a source's
  // radius, an anisotropic lobe) run on a subsample of about this many fitted records; the
  // parameters they find are then fitted and scored on every record.
  int search_records = 30000;
  // The photos and the model's complete renders of them, for the effects that work on images
  // rather than on the records alone (pose_error's coarse-to-fine alignment); may be absent.
  const PhotoSet* photos = nullptr;
  const std::vector<Image>* sims = nullptr;
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
std::vector<std::string> PhotoFiles(const recon::Scene& model);

struct ResidualFit;
// Copies a fit's predicted squared-error sums and significance into a candidate.
void FillScores(const ResidualFit& fit, CandidateResult* out);

}  // namespace igi::diagnose
