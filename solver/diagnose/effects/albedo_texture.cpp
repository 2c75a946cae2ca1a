// albedo_texture (docs/diagnose-effects.md): regions whose albedo varies over the surface. Its step
// is a change of the solver's albedo maps, not of the document: the refit solves maps for the
// regions it names (or, as a last resort, wherever the solver finds the albedo varies).
//
// Textured regions are tested first: on them the texture is most of a constant-albedo model's
// residual, and a smooth candidate correlated with it by chance would earn a false gain
// (texture_evidence.h). A texture the first test missed, because a larger effect the model lacked
// hid it, is tested again on every model a kept step leaves until it is found: otherwise its maps
// came only as the last resort, for every region whose albedo varies, where the untextured
// regions' maps add noise.

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "solver/diagnose/effects/effects.h"
#include "solver/diagnose/texture_evidence.h"

namespace igi::diagnose {
namespace {

// The albedo_texture step for the solved regions whose records show a texture
// (FindTexturedRegions); invalid when none does.
CandidateResult TextureTest(const DiagnosisModel& m) {
  std::vector<bool> solved(m.model.materials.size(), false);
  for (size_t r = 0; r < solved.size(); ++r) {
    const int d = m.scene.FindMaterial(m.model.materials[r].name);
    solved[r] = d >= 0 && !m.scene.materials[size_t(d)].rho_d.has_value();
  }
  TextureEvidenceOptions to;
  to.cell_m = m.cell_m;
  CandidateResult c;
  c.effect = "albedo_texture";
  c.num_params = -1;
  Json regions = Json::array(), tests = Json::array();
  std::string shown;
  for (const TextureEvidence& e : FindTexturedRegions(m.model, m.records, solved, to)) {
    tests.push_back({{"region", e.region},
                     {"cells", e.cells},
                     {"cell_m", e.cell_m},
                     {"sign_agreement", e.agreement},
                     {"rank_correlation", e.rank_correlation},
                     {"z", e.z},
                     {"amplitude", e.amplitude},
                     {"textured", e.textured}});
    spdlog::info(
        "igi-diagnose: texture test of {}: {} cells of {:.0f} cm, rank correlation {:.2f} (z "
        "{:.1f}), signs agree in {:.0f}% (z {:.1f}), amplitude {:.1f}%{}",
        e.region, e.cells, 100 * e.cell_m, e.rank_correlation, e.z, 100 * e.agreement, e.sign_z,
        100 * e.amplitude, e.textured ? ": textured" : "");
    if (!e.textured) continue;
    regions.push_back(e.region);
    shown +=
        fmt::format("{}{} (rank correlation {:.2f}, {:.0f}% of {} cells of {:.0f} cm, {:.0f}%)",
                    shown.empty() ? "" : ", ", e.region, e.rank_correlation, 100 * e.agreement,
                    e.cells, 100 * e.cell_m, 100 * e.amplitude);
  }
  c.valid = !regions.empty();
  c.params = {{"regions", regions}};
  c.where = {{"regions", regions}, {"frame", "position on the surfaces"}, {"texture_tests", tests}};
  c.evidence = fmt::format(
      "the photos' ratio to the constant-albedo model changes from one surface cell to the "
      "next, alike in the even and the odd photos (region: the two sets' rank correlation over "
      "the cells, share of cells whose high-pass signs agree, cells, reproducible amplitude): "
      "{}. A texture: fitted before any other candidate is judged, so that no smooth effect can "
      "pass for it",
      shown);
  return c;
}

class AlbedoTextureEffect final : public Effect {
 public:
  std::string Name() const override { return "albedo_texture"; }

  // With the materials solved, the texture test on every model until it names textured regions
  // (when it does, it has judged the others too).
  std::optional<CandidateResult> TryFirst(const DiagnosisModel& m, int) override {
    if (!m.materials_solved || judged_) return std::nullopt;
    CandidateResult c = TextureTest(m);
    judged_ = c.valid;
    if (!c.valid) return std::nullopt;
    return c;
  }

  // Maps wherever the solver finds the albedo varies, when the texture test never named regions
  // and the model has no maps for every region yet.
  std::optional<CandidateResult> TryLast(const DiagnosisModel& m) override {
    if (m.maps.Full() || judged_) return std::nullopt;
    CandidateResult c;
    c.effect = Name();
    c.valid = true;
    c.num_params = -1;  // one albedo per texel of the regions that get a map
    c.evidence = "albedo maps where the solver finds the albedo varies";
    return c;
  }

  // The refit's maps: the named regions', or every region's where the albedo varies.
  TrialPlan PlanTrial(CandidateResult* c, const DiagnosisModel& m) override {
    MapMode maps{solver::AlbedoMaps::kAuto, {}};
    if (c->params.contains("regions")) {
      maps.only = c->params["regions"].get<std::vector<std::string>>();
    }
    return {m.declared, maps, std::nullopt};
  }

  // A last-resort step names the regions the refit gave maps.
  void DescribeKept(CandidateResult* c, const recon::Scene& refit) const override {
    if (c->params.contains("regions")) return;
    Json regions = Json::array();
    for (const recon::Material& m : refit.materials) {
      if (m.rho_d_map) regions.push_back(m.name);
    }
    c->params = {{"regions", regions}};
    c->where = {{"regions", regions}, {"frame", "position on the surfaces"}};
    c->evidence = "the residual follows position on the surfaces of " + regions.dump() +
                  " (the same texture in every photo that sees them): their albedo varies";
  }

  // Nothing: the maps are the refit's (PlanTrial), written by the solver into its scene.
  void Write(const CandidateResult&, recon::SceneDocument*) const override {}

 private:
  bool judged_ = false;  // the texture test has named textured regions
};

}  // namespace

std::unique_ptr<Effect> MakeAlbedoTexture() { return std::make_unique<AlbedoTextureEffect>(); }

}  // namespace igi::diagnose
