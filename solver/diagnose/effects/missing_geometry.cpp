// missing_geometry (docs/diagnose-effects.md): an object in the photos that the geometry lacks.
// Located, not fitted: the residual's blobs carved from every photo (missing_geometry.h); the step
// excludes the object and its shadow from the photos (masks) and refits without them.

#include "solver/diagnose/missing_geometry.h"

#include <fmt/format.h>

#include <memory>
#include <optional>
#include <string>

#include "solver/diagnose/effects/effects.h"

namespace igi::diagnose {
namespace {

class MissingGeometryEffect final : public Effect {
 public:
  std::string Name() const override { return "missing_geometry"; }

  std::optional<CandidateResult> Locate(const DiagnosisModel& m,
                                        const KeyFilter& allowed) override {
    if (!allowed(Name())) return std::nullopt;
    located_ =
        LocateMissingGeometry(m.model, m.photos, m.sims, m.records, m.holdout, m.out_dir / "masks");
    return located_.candidate;
  }

  // An object the model lacks is located before the albedo maps: fitted with the object's pixels
  // in them, the maps of the surfaces around and under it take up part of its image and its
  // shadow, and its blobs fall below the locator's tests. A texture's blobs are not taken for an
  // object (the surface-behind test, missing_geometry.h).
  std::optional<CandidateResult> TryFirst(const DiagnosisModel& m, int round) override {
    if (round != 0 || !m.materials_solved) return std::nullopt;
    const std::optional<CandidateResult> c = Locate(m, [](const std::string&) { return true; });
    if (!c->valid || c->Gain() < m.options.missing_geometry_min_gain ||
        c->z < m.options.candidate_min_z) {
      return std::nullopt;
    }
    return c;
  }

  // The refit and its comparison use the pixels outside the located object's masks.
  TrialPlan PlanTrial(CandidateResult* c, const DiagnosisModel& m) override {
    recon::SceneDocument doc(m.declared);
    Write(*c, &doc);
    return {std::move(doc).json(), m.maps, MaskedPhotoSet(m.photos, located_.excluded)};
  }

  // Excluding pixels cannot be scored by the residual it removes alone. The masks come from the
  // fitted pixels only, so they predict where the held-out residual lies: the step is kept when
  // they hold >= min_gain of the held-out residual², at a per-pixel level higher than outside
  // them by >= min_z standard errors (held-out blocks as units), and the refit does not make the
  // held-out residual outside them (compared before/after on the same pixels) worse by min_gain.
  Judgement Judge(const CandidateResult& c, const HeldOutOutcome& outcome, const HeldOutScope&,
                  const DiagnoseOptions& o) const override {
    Judgement j;
    j.gain = c.Gain();
    j.z = c.z;
    j.kept = c.Gain() >= o.min_gain && c.z >= o.min_z && outcome.gain >= -o.min_gain;
    j.verdict = fmt::format(
        "{}: the masks (fitted on the fitted pixels) hold {:.1f}% of the held-out residual², "
        "above the level outside them by {:.1f} standard errors; outside the masks the refit "
        "changed the held-out residual² by {:.1f}% (same pixels before and after)",
        j.kept ? "kept" : "rejected", 100 * c.Gain(), c.z, -100 * outcome.gain);
    return j;
  }

  // Each photo with pixels of the object gets the mask that excludes them.
  void Write(const CandidateResult& c, recon::SceneDocument* doc) const override {
    for (const Json& m : c.params.at("mask_files")) {
      doc->SetPhotoMask(m.at("photo").get<size_t>(),
                        std::filesystem::path(m.at("file").get<std::string>()));
    }
  }

 private:
  MissingGeometryResult located_;  // the last object located, whose masks a trial applies
};

}  // namespace

std::unique_ptr<Effect> MakeMissingGeometry() { return std::make_unique<MissingGeometryEffect>(); }

}  // namespace igi::diagnose
