#pragma once
// An effect of docs/diagnose-effects.md as igi-diagnose models it, as one object: what it targets,
// how its candidates are fitted to the residual (or located in the photos), how a candidate's trial
// is set up and judged, and how the candidate is written into the scene document. The driver
// (diagnose.cpp) runs every effect of MakeEffects() through the same loop and names none of them;
// each effect is one file under solver/diagnose/effects/ (the list: effects/effects.h).

#include <cstddef>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "recon/scene.h"
#include "recon/scene_document.h"
#include "solver/diagnose/candidates.h"
#include "solver/diagnose/diagnose_options.h"
#include "solver/diagnose/pixel_records.h"
#include "solver/inverse/photo_model.h"
#include "solver/inverse/solve_options.h"
#include "tools/common/image.h"
#include "tools/common/json.h"

namespace igi::diagnose {

class ResidualFitter;
class RecordSubset;

// The solver's albedo maps for a fit (SolveOptions::albedo_maps): AlbedoMaps::kNone (default),
// or kAuto (where the albedo varies), optionally only for the regions in `only`.
struct MapMode {
  solver::AlbedoMaps maps = solver::AlbedoMaps::kNone;
  std::vector<std::string> only;  // empty: every region
  bool Full() const { return maps == solver::AlbedoMaps::kAuto && only.empty(); }
};

// The diagnosis's current model as the effects see it: the kept model, its complete renders and
// residual samples, and what the diagnosis was asked.
struct DiagnosisModel {
  const recon::Scene& scene;                // the capture as declared
  const recon::Scene& model;                // complete materials
  const Json& declared;                     // the declared document it was fitted from
  const PhotoSet& photos;                   // the photos and their valid pixels
  const std::vector<Image>& sims;           // the model's renders of them
  const std::vector<PixelRecord>& records;  // its residual samples
  const solver::PixelHoldout& holdout;
  const DiagnoseOptions& options;
  const MapMode& maps;            // the albedo maps the model was fitted with
  bool materials_solved;          // unknown materials are re-solved at every refit
  double cell_m;                  // surface cell of the albedo nuisance
  std::filesystem::path out_dir;  // the diagnosis's output folder
};

// The residual records a round's candidates are fitted on: the fitter over every record and, when
// the records are many, a subsample for the searches over nonlinear parameters.
struct RecordFits {
  const ResidualFitter& fitter;
  const RecordSubset* search = nullptr;
};

// One candidate's fit. A result with `drop_empty` is left out of the round when it is neither
// valid nor explained by a note (a target the effect does not apply to).
struct CandidateTask {
  std::function<CandidateResult()> run;
  bool drop_empty = false;
};

// Whether a candidate key (CandidateResult::Key) may be fitted this round: keys kept or rejected
// earlier are not.
using KeyFilter = std::function<bool(const std::string& key)>;

// A candidate's trial: the document the scene is refitted from, the albedo maps of the refit, and
// the photos' valid pixels when the step changes them.
struct TrialPlan {
  Json document;
  MapMode maps;
  std::optional<PhotoSet> photos;
};

// The held-out blocks (photo, block x, block y) a step's significance counts.
using BlockFilter = std::function<bool(size_t photo, int bx, int by)>;

// Where a trial's held-out gain is tested: its gain is over every held-out block; its z over the
// blocks of `blocks` (null: every block), with their pixels as the units when `pixel_units`.
struct HeldOutScope {
  BlockFilter blocks;
  bool pixel_units = false;
  std::string units = "the held-out blocks";  // for the verdict
};

// A trial's refit measured on the held-out pixels: the gain over every held-out block and the z
// in its scope.
struct HeldOutOutcome {
  double gain = 0, z = 0;
};

// The decision on a trial: kept or not, the gain it is ranked by among the kept ones, its z, and
// the sentence the report gives.
struct Judgement {
  bool kept = false;
  double gain = 0, z = 0;
  std::string verdict;
};

// A second fit of a candidate on its refit's own residual (camera_response): the document to
// refit from, and the candidate as revised, adopted when that refit succeeds.
struct Refinement {
  Json document;
  CandidateResult candidate;
};

class Effect {
 public:
  virtual ~Effect() = default;

  // The effect's name (docs/diagnose-effects.md).
  virtual std::string Name() const = 0;

  // Adds the fits of its candidates on the round's records: one per target it applies to (a
  // light, a region, a camera, or the capture as a whole) whose key `allowed` passes. The fits
  // read only the records and the model; the driver runs them in parallel.
  virtual void AddFits(const CandidateContext& cx, const RecordFits& records,
                       const KeyFilter& allowed, std::vector<CandidateTask>* tasks) const;

  // A candidate found by searching the model's photos rather than fitted on its records, added
  // to the round's candidates; none when the effect has no such search or is not allowed.
  virtual std::optional<CandidateResult> Locate(const DiagnosisModel& m, const KeyFilter& allowed);

  // A candidate tried alone before round `round`'s candidates are fitted (a missing object before
  // any albedo map; a texture before any smooth effect), or none.
  virtual std::optional<CandidateResult> TryFirst(const DiagnosisModel& m, int round);

  // A candidate tried alone when no candidate of a round was kept, or none.
  virtual std::optional<CandidateResult> TryLast(const DiagnosisModel& m);

  // The trial of candidate `c`: by default the declared document with `c` written into it
  // (Write), the maps and photos unchanged. An effect may fit `c` further on re-renders here and
  // revise it.
  virtual TrialPlan PlanTrial(CandidateResult* c, const DiagnosisModel& m);

  // After the trial's refit (`refit`, rendered where the held-out test reads, from `document`):
  // a second fit on the refit's own residual, or none.
  virtual std::optional<Refinement> Refine(const CandidateResult& c, const Json& document,
                                           const recon::Scene& refit, const Simulation& refit_sim,
                                           const DiagnosisModel& m) const;

  // Where the trial's held-out gain is tested. By default the candidate's support blocks
  // (CandidateResult::support_blocks) when it has them, every block otherwise.
  virtual HeldOutScope Scope(const CandidateResult& c, const DiagnosisModel& m) const;

  // Keeps the trial when its held-out gain reaches min_gain at min_z standard errors (the
  // default), or by the effect's own rule.
  virtual Judgement Judge(const CandidateResult& c, const HeldOutOutcome& outcome,
                          const HeldOutScope& scope, const DiagnoseOptions& o) const;

  // Completes a kept candidate's description from its refitted model (nothing by default).
  virtual void DescribeKept(CandidateResult* c, const recon::Scene& refit) const;

  // Writes candidate `c` (its params) into the scene document `doc`.
  virtual void Write(const CandidateResult& c, recon::SceneDocument* doc) const = 0;
};

// Every effect igi-diagnose models, in the order the driver consults them (effects/effects.cpp).
// Each diagnosis makes its own: an effect may carry what it found from one call to the next
// (a located object's masks, whether the texture test has named regions).
std::vector<std::unique_ptr<Effect>> MakeEffects();

// The effect of `name` among `effects`, or null.
Effect* FindEffect(const std::vector<std::unique_ptr<Effect>>& effects, const std::string& name);

// Every candidate `effects` fit on `records` (AddFits), except those whose key is in `excluded`
// (they are not fitted at all); the fits run in parallel and come out in the effects' order.
std::vector<CandidateResult> EvaluateCandidates(const std::vector<std::unique_ptr<Effect>>& effects,
                                                const CandidateContext& context,
                                                const std::vector<PixelRecord>& records,
                                                const std::vector<std::string>& excluded);

// Scopes shared by several effects.
// The held-out blocks of the candidate's support (at least two), or none (every block).
HeldOutScope SupportScope(const CandidateResult& c);
// The held-out blocks where the records see the candidate's region (params "region"): where a
// change of one region's material shows. Its refit also changes the path tracer's random paths in
// every block whose paths meet the region (their light bounced off it changes little; their noise
// changes entirely), and those blocks would only add noise to the significance. The support
// blocks instead when the candidate has them.
HeldOutScope RegionScope(const CandidateResult& c, const DiagnosisModel& m);

}  // namespace igi::diagnose
