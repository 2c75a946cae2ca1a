// igi-solve on igi-synth rooms whose glossy regions are microfacet lobes (ggx, beckmann: Smith's
// masking-shadowing and Schlick's Fresnel with F0 = ρs), every value unknown: the solver fits
// them as it fits Ward's lobes (solver/inverse/region_fit.h), the part of the lobe that ρs does
// not scale (Schlick's grazing rise) included.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include "recon/scene.h"
#include "solver/inverse/solve.h"
#include "solver/synth/synthesize.h"
#include "tests/temp_dir.h"
#include "tools/common/json.h"

namespace igi::solver {
namespace {
namespace fs = std::filesystem;

double RelErr(double a, double b) { return std::abs(a - b) / std::abs(b); }

class SolveMicrofacet : public ::testing::TestWithParam<recon::BrdfModel> {};

// The room's glossy regions (truth: ρs 0.04-0.1 = F0 of dielectrics, α 0.05-0.15) from 256-path
// photos, the paper's stage and one refinement round. The accuracy targets: ρs and α within 5 %
// of the truth, ρd within 2 % (the textured floor: its lobe only, its albedo is a texture; the
// glossy sphere 3 %, as the Ward room's sphere from 256-path photos: solve_truth_test). Measured
// (ggx): ρs / α the floor −3.0 / −4.1 %, wall_y4 +0.4 / +1.7 %, the glossy box −0.4 / +0.1 %,
// the sphere +3.5 / +4.3 %; ρd within 1.75 %, the sphere's −0.8 / −1.6 / −2.0 %.
TEST_P(SolveMicrofacet, RecoversTheGlossyRegionsLobes) {
  const std::string model(recon::BrdfModelName(GetParam()));
  const fs::path tmp = test::UniqueTempDir("solve_" + model);
  synth::SynthOptions so;
  so.out = tmp / "capture";
  so.spp = 256;
  so.glossy_brdf = GetParam();
  synth::Synthesize(so);
  const recon::Scene scene = recon::LoadScene(so.out / "scene.json");
  for (const recon::Material& m : scene.materials) {
    if (m.name == "floor" || m.name == "glossy_box") {
      EXPECT_EQ(m.brdf, GetParam()) << m.name;
    }
  }
  SolveOptions o;
  o.refine_iterations = 1;
  const SolveSummary s = Solve(scene, o, tmp / "out");
  const Json truth = ReadJsonFile(so.out / "truth.json")["materials"];
  int lobes = 0;
  for (const RegionSolution& r : s.regions) {
    const Json& t = truth[r.name];
    const RegionFitResult& f = r.stage2.fitted ? r.stage2 : r.stage1;
    if (!t.contains("rho_s")) continue;
    ++lobes;
    std::printf("%s %s: rho_s %+.2f %%, alpha %+.2f %%", model.c_str(), r.name.c_str(),
                100 * (f.rho_s.mean() / t["rho_s"].get<double>() - 1),
                100 * (f.alpha / t["alpha"].get<double>() - 1));
    if (t.contains("rho_d") && !t.contains("rho_d_map")) {
      std::printf(", rho_d %+.2f %+.2f %+.2f %%",
                  100 * (r.final_params.rho_d[0] / t["rho_d"][0].get<double>() - 1),
                  100 * (r.final_params.rho_d[1] / t["rho_d"][1].get<double>() - 1),
                  100 * (r.final_params.rho_d[2] / t["rho_d"][2].get<double>() - 1));
      for (int c = 0; c < 3; ++c) {
        const double bar = r.name == "glossy_sphere" ? 0.03 : 0.02;
        EXPECT_LT(RelErr(r.final_params.rho_d[c], t["rho_d"][c].get<double>()), bar)
            << r.name << " rho_d[" << c << "]";
      }
    }
    std::printf("\n");
    EXPECT_LT(RelErr(f.rho_s.mean(), t["rho_s"].get<double>()), 0.05) << r.name;
    EXPECT_LT(RelErr(f.alpha, t["alpha"].get<double>()), 0.05) << r.name;
  }
  EXPECT_EQ(lobes, 4);  // the floor, wall_y4, the glossy box and sphere
}

// The anisotropic form: the glossy box's lobe made anisotropic in the photos (igi-synth's
// anisotropic_reflection: αx 0.03 along the box's long side, αy 0.15) and declared so in
// scene.json (the model and the tangent; ρd, ρs, αx and αy unknown), from 64-path photos. The
// solver fits both roughnesses from the box's highlights: ρs, αx and αy within 5 % of the truth.
// Measured: ggx_aniso ρs +0.9 %, αx +2.0 %, αy +0.4 %; beckmann_aniso +0.0 %, +1.3 %, −0.7 %
// (from 256-path photos: within 1.2 %).
TEST_P(SolveMicrofacet, RecoversAnAnisotropicLobe) {
  const std::string model(recon::BrdfModelName(GetParam()));
  const fs::path tmp = test::UniqueTempDir("solve_aniso_" + model);
  synth::SynthOptions so;
  so.out = tmp / "capture";
  so.spp = 64;
  so.glossy_brdf = GetParam();
  so.effects = {synth::ParseEffectSpec("anisotropic_reflection")};
  synth::Synthesize(so);
  const Json truth = ReadJsonFile(so.out / "truth.json")["materials"]["glossy_box"];
  const std::string aniso(recon::BrdfModelName(recon::AnisotropicForm(GetParam())));
  ASSERT_EQ(truth["brdf"], aniso);
  Json declared = ReadJsonFile(so.out / "scene.json");
  declared["materials"]["glossy_box"]["brdf"] = aniso;
  declared["materials"]["glossy_box"]["tangent"] = truth["tangent"];
  WriteJsonFile(so.out / "scene.json", declared);

  SolveOptions o;
  o.refine_iterations = 1;
  const SolveSummary s = Solve(recon::LoadScene(so.out / "scene.json"), o, tmp / "out");
  const RegionSolution* box = nullptr;
  for (const RegionSolution& r : s.regions) {
    if (r.name == "glossy_box") box = &r;
  }
  ASSERT_NE(box, nullptr);
  const render::BrdfParams& m = box->final_params;
  ASSERT_EQ(m.model, recon::AnisotropicForm(GetParam()));
  const double ax = truth["alpha_x"].get<double>(), ay = truth["alpha_y"].get<double>();
  std::printf("%s glossy box: rho_s %+.2f %%, alpha_x %.4f (%+.2f %%), alpha_y %.4f (%+.2f %%)\n",
              aniso.c_str(), 100 * (m.rho_s.mean() / truth["rho_s"].get<double>() - 1), m.alpha_x,
              100 * (m.alpha_x / ax - 1), m.alpha_y, 100 * (m.alpha_y / ay - 1));
  EXPECT_LT(RelErr(m.rho_s.mean(), truth["rho_s"].get<double>()), 0.05);
  EXPECT_LT(RelErr(m.alpha_x, ax), 0.05);
  EXPECT_LT(RelErr(m.alpha_y, ay), 0.05);
}

INSTANTIATE_TEST_SUITE_P(Models, SolveMicrofacet,
                         ::testing::Values(recon::BrdfModel::kGgx, recon::BrdfModel::kBeckmann),
                         [](const testing::TestParamInfo<recon::BrdfModel>& model) {
                           return std::string(recon::BrdfModelName(model.param));
                         });

}  // namespace
}  // namespace igi::solver
