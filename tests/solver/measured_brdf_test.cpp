// igi's reflectance models fitted to real measured BRDFs (Cornell gonioreflectometer data,
// ../shared/data/real/measured_brdf) by the solver's region fit: the table of each model's error
// per material, near normal and at grazing angles, and which model the fit's residual picks.
#include "solver/inverse/measured_brdf.h"

#include <gtest/gtest.h>

#include <fstream>
#include <map>

#include "tests/temp_dir.h"
#include "tools/common/error.h"

namespace igi::solver {
namespace {

std::filesystem::path MeasuredDir() {
  return std::filesystem::path(IGI_SHARED_DATA_DIR) / "real" / "measured_brdf";
}

constexpr recon::BrdfModel kModels[] = {
    recon::BrdfModel::kLambert,        recon::BrdfModel::kWard,     recon::BrdfModel::kWardGmd,
    recon::BrdfModel::kWardGmdFresnel, recon::BrdfModel::kBeckmann, recon::BrdfModel::kGgx};

TEST(MeasuredBrdf, ReadsTheCornellFiles) {
  const MeasuredBrdf acryl = ReadCornellBrdf(MeasuredDir() / "acryl_blue.brdf");
  EXPECT_EQ(acryl.wavelengths_nm.size(), 31u);
  EXPECT_EQ(acryl.samples.size(), 1439u);
  // The first row: θi 0.872665, φi 0, θs 0.573513, φs 0; its blue band is the mean of the
  // 400..490 nm values.
  const MeasuredBrdfSample& s = acryl.samples[0];
  EXPECT_NEAR(s.wi.z(), std::cos(0.872665), 1e-12);
  EXPECT_NEAR(s.wo.x(), std::sin(0.573513), 1e-12);
  const double blue = (0.014369 + 0.018226 + 0.021071 + 0.025607 + 0.033963 + 0.035622 + 0.032200 +
                       0.026240 + 0.018363 + 0.011235) /
                      10;
  EXPECT_NEAR(s.f[2], blue, 1e-12);
}

TEST(MeasuredBrdf, MalformedRowsNameTheLine) {
  const auto dir = test::UniqueTempDir("igi_measured_brdf");
  std::ofstream(dir / "bad.brdf") << "# a comment\n3\n450 550 650\n0.1 0 0.2 3.1 0.1 0.2 0.3\n"
                                  << "0.1 0 0.2 3.1 0.1 -0.2 0.3\n";
  try {
    ReadCornellBrdf(dir / "bad.brdf");
    FAIL() << "a negative BRDF value was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.brdf: line 5: -0.2: BRDF values must be >= 0"),
              std::string::npos)
        << e.what();
  }
  std::ofstream(dir / "short.brdf") << "3\n450 550 650\n0.1 0 0.2 3.1 0.1 0.2\n";  // 6 of 7
  EXPECT_THROW(ReadCornellBrdf(dir / "short.brdf"), InputError);
}

// The table (docs/solve.md, "Models against measured materials"). What the assertions hold:
// - the model with the smallest fit residual (the weighted residual the solver's and
//   igi-diagnose's comparisons of models minimise) also fits best by the plain relative error of
//   f·cosθi·cosθo over all rows, or is within 2 % of the model that does;
// - that pick per material, and its error below a bound 10 % above today's figure, so that a
//   change to the fit or to a model that moves these real-data results shows here;
// - every material has a lobe: Lambert's error is at least twice the pick's.
// Measured: acryl_blue ward (fit 0.212, all rows 0.321); cayman beckmann (0.118, 0.247; ggx
// 0.118, 0.246); krylon_blue ggx (0.228, 0.242). The microfacet lobes' Fresnel factor rises to 1
// at grazing whatever ρs: the acrylic's measured grazing peaks stay far below that (ggx's fit
// then broadens to α 0.18), where Ward's lobe, without a Fresnel term, fits them.
struct Expected {
  const char* material;
  recon::BrdfModel pick;
  double fit_rms, error_all;
};
constexpr Expected kExpected[] = {
    {"acryl_blue", recon::BrdfModel::kWard, 0.212, 0.321},
    {"cayman", recon::BrdfModel::kBeckmann, 0.118, 0.247},
    {"krylon_blue", recon::BrdfModel::kGgx, 0.228, 0.242},
};

TEST(MeasuredBrdf, ModelsFittedToMeasuredMaterials) {
  std::printf("%-12s %-18s %8s %8s %8s %8s %9s %9s %9s\n", "material", "model", "rho_d.g", "rho_s",
              "alpha", "fit_rms", "err_all", "err<60", "err>=60");
  for (const Expected& expected : kExpected) {
    const char* name = expected.material;
    const MeasuredBrdf m = ReadCornellBrdf(MeasuredDir() / (std::string(name) + ".brdf"));
    std::map<recon::BrdfModel, MeasuredFit> fits;
    for (recon::BrdfModel model : kModels) {
      const MeasuredFit f = FitMeasuredBrdf(m, model);
      std::printf("%-12s %-18s %8.4f %8.4f %8.4f %8.4f %9.4f %9.4f %9.4f\n", name,
                  std::string(recon::BrdfModelName(model)).c_str(), f.fit.rho_d.y(),
                  f.fit.rho_s.mean(), f.fit.alpha, f.fit.relative_rms, f.error_all, f.error_near,
                  f.error_grazing);
      fits[model] = f;
    }
    const MeasuredFit* pick = &fits.begin()->second;
    const MeasuredFit* best_plain = pick;
    for (const auto& [model, f] : fits) {
      if (f.fit.relative_rms < pick->fit.relative_rms) pick = &f;
      if (f.error_all < best_plain->error_all) best_plain = &f;
    }
    EXPECT_EQ(pick->model, expected.pick) << name;
    EXPECT_LE(pick->error_all, 1.02 * best_plain->error_all) << name;
    EXPECT_LT(pick->fit.relative_rms, 1.1 * expected.fit_rms) << name;
    EXPECT_LT(pick->error_all, 1.1 * expected.error_all) << name;
    EXPECT_GT(fits.at(recon::BrdfModel::kLambert).error_all, 2 * pick->error_all) << name;
    EXPECT_EQ(pick->rows_near + pick->rows_grazing, 1439);
  }
}

}  // namespace
}  // namespace igi::solver
