// fresnel (docs/diagnose-effects.md): a glossy region whose highlights grow toward grazing angles
// as Schlick's Fresnel weight (plain -> *_fresnel). The fit: LobeChange (lobe_change.cpp).

#include <memory>
#include <string>
#include <vector>

#include "solver/diagnose/effects/effects.h"

namespace igi::diagnose {
namespace {

class FresnelEffect final : public Effect {
 public:
  std::string Name() const override { return "fresnel"; }
  // Every plain ward / ward_gmd region with complete values (the others are left out).
  void AddFits(const CandidateContext& cx, const RecordFits& in, const KeyFilter& allowed,
               std::vector<CandidateTask>* tasks) const override {
    for (int g = 0; g < int(cx.model.materials.size()); ++g) {
      if (!allowed(Name() + ":" + cx.model.materials[g].name)) continue;
      tasks->push_back({[&cx, &f = in.fitter, g] { return LobeChange(cx, f, g, true); }, true});
    }
  }
  HeldOutScope Scope(const CandidateResult& c, const DiagnosisModel& m) const override {
    return RegionScope(c, m);
  }
  // The region's model becomes its *_fresnel form with the fitted index.
  void Write(const CandidateResult& c, recon::SceneDocument* doc) const override {
    const std::string region = c.params.at("region").get<std::string>();
    doc->SetMaterialBrdf(region,
                         recon::BrdfModelFromName(c.params.at("to").get<std::string>()).value());
    doc->SetMaterialValue(region, "ior", c.params.at("ior"));
  }
};

}  // namespace

std::unique_ptr<Effect> MakeFresnel() { return std::make_unique<FresnelEffect>(); }

}  // namespace igi::diagnose
