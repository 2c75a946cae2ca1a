// specular_lobe_shape (docs/diagnose-effects.md): a glossy region whose highlight falls off away
// from its peak as the other Ward lobe does (ward <-> ward_gmd). The fit: LobeChange
// (lobe_change.cpp).

#include <memory>
#include <string>
#include <vector>

#include "solver/diagnose/effects/effects.h"

namespace igi::diagnose {
namespace {

class SpecularLobeShapeEffect final : public Effect {
 public:
  std::string Name() const override { return "specular_lobe_shape"; }
  // Every plain ward / ward_gmd region with complete values (the others are left out).
  void AddFits(const CandidateContext& cx, const RecordFits& in, const KeyFilter& allowed,
               std::vector<CandidateTask>* tasks) const override {
    for (int g = 0; g < int(cx.model.materials.size()); ++g) {
      if (!allowed(Name() + ":" + cx.model.materials[g].name)) continue;
      tasks->push_back({[&cx, &f = in.fitter, g] { return LobeChange(cx, f, g, false); }, true});
    }
  }
  HeldOutScope Scope(const CandidateResult& c, const DiagnosisModel& m) const override {
    return RegionScope(c, m);
  }
  // The region's model becomes the other lobe; its rho_s and alpha stay (or are solved).
  void Write(const CandidateResult& c, recon::SceneDocument* doc) const override {
    doc->SetMaterialBrdf(c.params.at("region").get<std::string>(),
                         recon::BrdfModelFromName(c.params.at("to").get<std::string>()).value());
  }
};

}  // namespace

std::unique_ptr<Effect> MakeSpecularLobeShape() {
  return std::make_unique<SpecularLobeShapeEffect>();
}

}  // namespace igi::diagnose
