#include "solver/render/brdf.h"

#include <ceres/jet.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "chi_square.h"
#include "recon/scene.h"
#include "solver/render/sampling.h"

namespace igi::render {
namespace {

using test::IntegrateSphere;
using test::SidakLevel;
using test::SphereHistogram;
using test::TestDirections;

constexpr recon::BrdfModel kAllModels[] = {recon::BrdfModel::kLambert,
                                           recon::BrdfModel::kWard,
                                           recon::BrdfModel::kWardGmd,
                                           recon::BrdfModel::kWardAniso,
                                           recon::BrdfModel::kWardGmdAniso,
                                           recon::BrdfModel::kWardFresnel,
                                           recon::BrdfModel::kWardGmdFresnel,
                                           recon::BrdfModel::kWardAnisoFresnel,
                                           recon::BrdfModel::kWardGmdAnisoFresnel};
constexpr recon::BrdfModel kMicrofacetModels[] = {
    recon::BrdfModel::kGgx, recon::BrdfModel::kGgxAniso, recon::BrdfModel::kBeckmann,
    recon::BrdfModel::kBeckmannAniso};
// kAllModels (lambert and Ward's lobes) and the microfacet models.
std::vector<recon::BrdfModel> EveryModel() {
  std::vector<recon::BrdfModel> models(std::begin(kAllModels), std::end(kAllModels));
  models.insert(models.end(), std::begin(kMicrofacetModels), std::end(kMicrofacetModels));
  return models;
}
constexpr recon::BrdfModel kFresnelModels[] = {
    recon::BrdfModel::kWardFresnel, recon::BrdfModel::kWardGmdFresnel,
    recon::BrdfModel::kWardAnisoFresnel, recon::BrdfModel::kWardGmdAnisoFresnel};

Eigen::Vector3d Dir(double theta_deg, double phi_deg) {
  const double t = theta_deg * kPi / 180.0;
  const double p = phi_deg * kPi / 180.0;
  return {std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t)};
}

BrdfParams Make(recon::BrdfModel model, const Eigen::Vector3d& rho_d, const Eigen::Vector3d& rho_s,
                double alpha_x, double alpha_y) {
  BrdfParams p;
  p.model = model;
  p.rho_d = rho_d;
  p.rho_s = rho_s;
  p.alpha = alpha_x;
  p.alpha_x = alpha_x;
  p.alpha_y = alpha_y;
  return p;
}

BrdfParams Grey(recon::BrdfModel model, double rho_d, double rho_s, double alpha_x,
                double alpha_y) {
  return Make(model, Eigen::Vector3d::Constant(rho_d), Eigen::Vector3d::Constant(rho_s), alpha_x,
              alpha_y);
}

// The specular part of docs/scene-format.md written a second way: through the angles θh, φh of the
// normalised half vector, and for Ward-GMD through (h·h)/(h·n)⁴ = 1/(4 (wi·ĥ)² cos⁴θh). For a
// *_fresnel model: the plain model's (the Fresnel weight is ReferenceFresnelWeight).
double ReferenceSpecular(recon::BrdfModel model, double ax, double ay, const Eigen::Vector3d& wo,
                         const Eigen::Vector3d& wi) {
  const Eigen::Vector3d h_hat = (wo + wi).normalized();
  const double theta_h = std::acos(h_hat.z());
  const double phi_h = std::atan2(h_hat.y(), h_hat.x());
  const double tan2 = std::pow(std::tan(theta_h), 2);
  const double c2 = std::pow(std::cos(phi_h), 2);
  const double lobe = std::exp(-tan2 * (c2 / (ax * ax) + (1.0 - c2) / (ay * ay)));
  if (recon::IsGmd(model)) {
    return lobe / (4.0 * kPi * ax * ay * std::pow(wi.dot(h_hat), 2) * std::pow(h_hat.z(), 4));
  }
  return lobe / (4.0 * kPi * ax * ay * std::sqrt(wi.z() * wo.z()));
}

// Schlick's F(θd) = F0 + (1 - F0)(1 - cosθd)⁵ over F0, θd the angle between wo and the
// normalised half vector (written with wo, where the code uses |wo + wi|/2); 1 without Fresnel.
double ReferenceFresnelWeight(recon::BrdfModel model, double ior, const Eigen::Vector3d& wo,
                              const Eigen::Vector3d& wi) {
  if (!recon::HasFresnel(model)) return 1.0;
  const double f0 = std::pow((ior - 1.0) / (ior + 1.0), 2);
  const double cos_d = wo.dot((wo + wi).normalized());
  return (f0 + (1.0 - f0) * std::pow(1.0 - cos_d, 5)) / f0;
}

// ---- names and parameters -------------------------------------------------------------------

TEST(BrdfModelTest, NamesRoundTrip) {
  for (recon::BrdfModel m : EveryModel())
    EXPECT_EQ(recon::BrdfModelFromName(recon::BrdfModelName(m)), m);
  EXPECT_EQ(recon::BrdfModelName(recon::BrdfModel::kWardGmdAniso), "ward_gmd_aniso");
  EXPECT_FALSE(recon::IsReflective(*recon::BrdfModelFromName("emitter")));
  EXPECT_FALSE(recon::IsReflective(*recon::BrdfModelFromName("black")));
  EXPECT_FALSE(recon::BrdfModelFromName("Ward").has_value());
  EXPECT_EQ(recon::BrdfModelName(recon::BrdfModel::kWardFresnel), "ward_fresnel");
  EXPECT_EQ(recon::BrdfModelName(recon::BrdfModel::kWardGmdFresnel), "ward_gmd_fresnel");
  EXPECT_EQ(recon::BrdfModelName(recon::BrdfModel::kWardAnisoFresnel), "ward_aniso_fresnel");
  EXPECT_EQ(recon::BrdfModelName(recon::BrdfModel::kWardGmdAnisoFresnel), "ward_gmd_aniso_fresnel");
  for (recon::BrdfModel m : kFresnelModels) {
    EXPECT_TRUE(recon::HasSpecularLobe(m) && recon::IsReflective(m) && recon::HasFresnel(m));
    EXPECT_FALSE(recon::HasFresnel(recon::WithoutFresnel(m)));
    EXPECT_EQ(recon::IsGmd(m), recon::IsGmd(recon::WithoutFresnel(m)));
    EXPECT_EQ(recon::IsAnisotropic(m), recon::IsAnisotropic(recon::WithoutFresnel(m)));
  }
  EXPECT_TRUE(recon::IsGmd(recon::BrdfModel::kWardGmdAnisoFresnel) &&
              recon::IsAnisotropic(recon::BrdfModel::kWardGmdAnisoFresnel));
  EXPECT_EQ(recon::WithoutFresnel(recon::BrdfModel::kWardGmd), recon::BrdfModel::kWardGmd);
  // Each registry line is one model with one name.
  for (const recon::BrdfModelInfo& a : recon::kBrdfModels) {
    EXPECT_EQ(&recon::Info(a.model), &a);
    for (const recon::BrdfModelInfo& b : recon::kBrdfModels) {
      if (&a != &b) {
        EXPECT_NE(a.name, b.name);
      }
    }
  }
  EXPECT_EQ(recon::BrdfModelName(recon::BrdfModel::kGgxAniso), "ggx_aniso");
  EXPECT_EQ(recon::BrdfModelName(recon::BrdfModel::kBeckmann), "beckmann");
  EXPECT_EQ(recon::AnisotropicForm(recon::BrdfModel::kGgx), recon::BrdfModel::kGgxAniso);
  EXPECT_EQ(recon::AnisotropicForm(recon::BrdfModel::kWardGmdFresnel),
            recon::BrdfModel::kWardGmdAnisoFresnel);
  EXPECT_EQ(recon::AnisotropicForm(recon::BrdfModel::kLambert), recon::BrdfModel::kLambert);
  for (recon::BrdfModel m : kMicrofacetModels) {
    EXPECT_TRUE(recon::IsMicrofacet(m) && recon::HasSpecularLobe(m) && !recon::HasFresnel(m));
    EXPECT_FALSE(recon::IsWardLobe(m) || recon::IsGmd(m));
  }
}

// The diffuse terms' registry: each line one term with one name, and a term with a roughness is
// the one whose σ the scene needs and the parameter check reads.
TEST(BrdfModelTest, DiffuseShapesRoundTripAndTheirSigmaIsRead) {
  for (const recon::DiffuseShapeInfo& a : recon::kDiffuseShapes) {
    EXPECT_EQ(&recon::Info(a.shape), &a);
    EXPECT_EQ(recon::DiffuseShapeFromName(a.name), a.shape);
    EXPECT_EQ(recon::DiffuseShapeName(a.shape), a.name);
    for (const recon::DiffuseShapeInfo& b : recon::kDiffuseShapes) {
      if (&a != &b) {
        EXPECT_NE(a.name, b.name);
      }
    }
    recon::Material m;
    m.brdf = recon::BrdfModel::kLambert;
    m.rho_d = Eigen::Vector3d::Constant(0.5);
    m.diffuse = a.shape;
    const std::vector<std::string> missing = m.MissingForRendering();
    EXPECT_EQ(std::find(missing.begin(), missing.end(), "sigma") != missing.end(), a.has_sigma)
        << a.name;
    BrdfParams p = Grey(recon::BrdfModel::kLambert, 0.5, 0, 0, 0);
    p.diffuse = a.shape;
    p.sigma = -1;
    EXPECT_EQ(CheckBrdfParams(p).size(), a.has_sigma ? 1u : 0u) << a.name;
  }
  EXPECT_EQ(recon::DiffuseShapeNames(), "lambert, oren_nayar, coated");
  EXPECT_EQ(recon::DiffuseShapesWithSigma(), "oren_nayar");
  EXPECT_FALSE(recon::DiffuseShapeFromName("rough"));
}

TEST(BrdfParamsTest, CheckNamesEachBadValueTheModelReads) {
  EXPECT_TRUE(CheckBrdfParams(Grey(recon::BrdfModel::kWard, 0.5, 0.1, 0.2, 0.2)).empty());
  BrdfParams p = Grey(recon::BrdfModel::kWard, 0.5, 0.1, 0.0, 0.2);
  p.rho_d[1] = -0.1;
  p.alpha_y = -1.0;  // ignored by an isotropic model
  auto problems = CheckBrdfParams(p);
  ASSERT_EQ(problems.size(), 2u);
  EXPECT_EQ(problems[0].key, "rho_d[1]");
  EXPECT_EQ(problems[0].value, -0.1);
  EXPECT_EQ(problems[1].key, "alpha");
  p.model = recon::BrdfModel::kWardAniso;
  p.rho_d[1] = 0.1;
  p.alpha = -5.0;  // ignored by an anisotropic model
  problems = CheckBrdfParams(p);
  ASSERT_EQ(problems.size(), 2u);
  EXPECT_EQ(problems[0].key, "alpha_x");
  EXPECT_EQ(problems[1].key, "alpha_y");
  p.model = recon::BrdfModel::kLambert;  // reads rho_d only
  p.rho_s[2] = NAN;
  EXPECT_TRUE(CheckBrdfParams(p).empty());
  p.rho_d[2] = INFINITY;
  EXPECT_EQ(CheckBrdfParams(p).size(), 1u);
  // ior: read by the *_fresnel models only, must be > 1 (F0 > 0).
  BrdfParams f = Grey(recon::BrdfModel::kWard, 0.5, 0.1, 0.2, 0.2);
  f.ior = 1.0;
  EXPECT_TRUE(CheckBrdfParams(f).empty());
  f.model = recon::BrdfModel::kWardGmdFresnel;
  problems = CheckBrdfParams(f);
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_EQ(problems[0].key, "ior");
  f.ior = NAN;
  EXPECT_EQ(CheckBrdfParams(f).size(), 1u);
  f.ior = 1.0001;
  EXPECT_TRUE(CheckBrdfParams(f).empty());
  // A microfacet model's ρs is F0: at most 1 (Ward's ρs may exceed it).
  BrdfParams g = Grey(recon::BrdfModel::kGgx, 0.5, 1.0, 0.2, 0.2);
  EXPECT_TRUE(CheckBrdfParams(g).empty());
  g.rho_s[2] = 1.2;
  problems = CheckBrdfParams(g);
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_EQ(problems[0].key, "rho_s[2]");
  g.model = recon::BrdfModel::kWard;
  EXPECT_TRUE(CheckBrdfParams(g).empty());
}

TEST(BrdfParamsTest, SpecularLobeProbabilityFollowsMeanAlbedos) {
  const Eigen::Vector3d wo = Dir(30, 0);
  EXPECT_DOUBLE_EQ(SpecularLobeProbability(Grey(recon::BrdfModel::kWard, 0.4, 0.2, 0.1, 0.1), wo),
                   1.0 / 3);
  EXPECT_EQ(SpecularLobeProbability(Grey(recon::BrdfModel::kLambert, 0.4, 0.2, 0.1, 0.1), wo), 0.0);
  EXPECT_EQ(SpecularLobeProbability(Grey(recon::BrdfModel::kWardGmd, 0.0, 0.0, 0.1, 0.1), wo), 0.0);
  EXPECT_EQ(SpecularLobeProbability(Grey(recon::BrdfModel::kWardAniso, 0.0, 0.3, 0.1, 0.2), wo),
            1.0);
  // A microfacet lobe's reflectance is Schlick's F at cosθo: ρs at the normal, rising to 1 at
  // grazing (even with ρs = 0).
  const BrdfParams g = Grey(recon::BrdfModel::kGgx, 0.4, 0.2, 0.1, 0.1);
  EXPECT_DOUBLE_EQ(SpecularLobeProbability(g, Eigen::Vector3d::UnitZ()), 1.0 / 3);
  const double m = std::pow(1.0 - std::cos(80 * kPi / 180), 5);
  const double s = 0.2 + 0.8 * m;
  EXPECT_DOUBLE_EQ(SpecularLobeProbability(g, Dir(80, 0)), s / (0.4 + s));
}

// ---- values ---------------------------------------------------------------------------------

TEST(BrdfEvalTest, MatchesLiteralValuesFromTheContractFormulas) {
  // Printed by tests/render/brdf_reference_values.py (Python, math module only: the models
  // transcribed with θh = acos(ĥ·n), φh = atan2(ĥ·b, ĥ·t)): rho_d = (0.5, 0.4, 0.3), rho_s = (0.05,
  // 0.1, 0.2), α = 0.2, (αx, αy) = (0.15, 0.3). Tolerance 1e-13 relative: double rounding of ~30
  // operations.
  struct Case {
    double theta_o, phi_o, theta_i, phi_i;
    recon::BrdfModel model;
    double f[3];
  };
  // clang-format off
  const Case cases[] = {
      {30, 20, 40, 215, recon::BrdfModel::kWard,
       {0.24127054747066087, 0.29155516323104735, 0.42395538337019933}},
      {30, 20, 40, 215, recon::BrdfModel::kWardGmd,
       {0.26118817015925311, 0.33139040860823177, 0.50362587412456816}},
      {30, 20, 40, 215, recon::BrdfModel::kWardAniso,
       {0.24656714823872172, 0.302148364767169, 0.44514178644244262}},
      {30, 20, 40, 215, recon::BrdfModel::kWardGmdAniso,
       {0.26776949258805627, 0.3445530534658382, 0.52995116383978103}},
      {60, 0, 55, 170, recon::BrdfModel::kWard,
       {0.27011614622872165, 0.34924636074716886, 0.53933777840244235}},
      {60, 0, 55, 170, recon::BrdfModel::kWardGmd,
       {0.36963202843275644, 0.54827812515523855, 0.93740130721858173}},
      {60, 0, 55, 170, recon::BrdfModel::kWardAniso,
       {0.27776687970547842, 0.36454782770068239, 0.56994071230946952}},
      {60, 0, 55, 170, recon::BrdfModel::kWardGmdAniso,
       {0.38414434478644571, 0.57730275786261698, 0.99545057263333869}},
      {10, 90, 80, -45, recon::BrdfModel::kWard,
       {0.15915511988962203, 0.12732430806896966, 0.095493673046043975}},
      {10, 90, 80, -45, recon::BrdfModel::kWardGmdAniso,
       {0.15915494764538407, 0.12732396358049375, 0.095492984069092138}},
      // The Fresnel-weighted models with ior = 1.7 (c = |wo + wi|/2 = 0.822, 0.542, 0.216).
      {30, 20, 40, 215, recon::BrdfModel::kWardFresnel,
       {0.24147140274572448, 0.29195687378117452, 0.42475880447045378}},
      {30, 20, 40, 215, recon::BrdfModel::kWardGmdAnisoFresnel,
       {0.26803516444640774, 0.34508439718254114, 0.5310138512731869}},
      {60, 0, 55, 170, recon::BrdfModel::kWardGmdFresnel,
       {0.42830857775844577, 0.66563122380661721, 1.1721075045213389}},
      {60, 0, 55, 170, recon::BrdfModel::kWardAnisoFresnel,
       {0.31083337308670023, 0.43068081446312612, 0.70220668583435686}},
      {80, 0, 75, 180, recon::BrdfModel::kWardFresnel,
       {2.4402983469669537, 4.6896107622236327, 9.2200665813553702}},
      {80, 0, 75, 180, recon::BrdfModel::kWardGmdFresnel,
       {10.521701932311395, 20.852417932912516, 41.545680922733133}},
      {80, 0, 75, 180, recon::BrdfModel::kWardAnisoFresnel,
       {2.1130547162013773, 4.0351235006924799, 7.9110920582930655}},
      {80, 0, 75, 180, recon::BrdfModel::kWardGmdAnisoFresnel,
       {9.0351327429432065, 17.87927955417614, 35.599404165260381}},
  };
  // clang-format on
  for (const Case& c : cases) {
    BrdfParams p = Make(c.model, {0.5, 0.4, 0.3}, {0.05, 0.1, 0.2}, 0.15, 0.3);
    p.ior = 1.7;  // read by the *_fresnel models only
    BrdfParams iso = p;
    iso.alpha = 0.2;
    const BrdfParams& params = recon::IsAnisotropic(c.model) ? p : iso;
    const Eigen::Vector3d f = EvalBrdf(params, Dir(c.theta_o, c.phi_o), Dir(c.theta_i, c.phi_i));
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(f[k], c.f[k], 1e-13 * c.f[k])
          << recon::BrdfModelName(c.model) << " channel " << k;
    }
  }
}

TEST(BrdfEvalTest, MatchesTheAngleFormOfEveryModel) {
  Pcg32 rng(1, 2);
  for (recon::BrdfModel model : kAllModels) {
    for (double alpha : {0.05, 0.2, 0.6}) {
      BrdfParams p = Make(model, {0.3, 0.2, 0.1}, {0.04, 0.08, 0.5}, alpha, 1.7 * alpha);
      p.ior = 1.33 + alpha;
      for (int i = 0; i < 200; ++i) {
        const Eigen::Vector3d wo = SampleUniformHemisphere(rng.Uniform2D());
        const Eigen::Vector3d wi = SampleUniformHemisphere(rng.Uniform2D());
        double s = 0.0;
        if (recon::HasSpecularLobe(model))
          s = ReferenceSpecular(model, p.AlphaX(), p.AlphaY(), wo, wi);
        const double w = ReferenceFresnelWeight(model, p.ior, wo, wi);
        EXPECT_NEAR(recon::HasFresnel(model) ? FresnelWeight(p.ior, wo, wi) : 1.0, w, 1e-12 * w);
        const Eigen::Vector3d expected = p.rho_d / kPi + p.rho_s * s * w;
        const Eigen::Vector3d f = EvalBrdf(p, wo, wi);
        // 1e-10 relative: acos/tan near θh = 0 lose a few digits in the reference.
        EXPECT_NEAR((f - expected).norm(), 0.0, 1e-10 * expected.norm())
            << recon::BrdfModelName(model);
        EXPECT_NEAR(SpecularFactor(model, p.AlphaX(), p.AlphaY(), wo, wi), s, 1e-10 * s + 1e-300);
        const BrdfEval both = EvalBrdfAndPdf(p, wo, wi);
        EXPECT_NEAR((both.f - f).norm(), 0.0, 1e-14 * f.norm());
      }
    }
  }
}

TEST(BrdfEvalTest, IsZeroBelowTheSurfaceAndOneSided) {
  for (recon::BrdfModel model : EveryModel()) {
    const BrdfParams p = Grey(model, 0.5, 0.3, 0.2, 0.3);
    EXPECT_EQ(EvalBrdf(p, Dir(30, 0), Dir(100, 180)), Eigen::Vector3d::Zero());
    EXPECT_EQ(EvalBrdf(p, Dir(120, 0), Dir(30, 180)), Eigen::Vector3d::Zero());
    EXPECT_EQ(EvalBrdf(p, Eigen::Vector3d::UnitX(), Dir(30, 180)), Eigen::Vector3d::Zero());
    EXPECT_EQ(EvalBrdf(p, Dir(30, 180), -Eigen::Vector3d::UnitY()), Eigen::Vector3d::Zero());
    EXPECT_EQ(BrdfPdf(p, Dir(120, 0), Dir(30, 180)), 0.0);
    EXPECT_FALSE(SampleBrdf(p, Dir(120, 0), 0.5, {0.3, 0.3}).Valid());
  }
  EXPECT_NEAR(
      EvalBrdf(Grey(recon::BrdfModel::kLambert, 0.6, 0.9, 0.1, 0.1), Dir(10, 0), Dir(70, 3))[0],
      0.6 / kPi, 1e-16);
}

TEST(BrdfEvalTest, FresnelModelsEqualThePlainOnesAtNormalIncidenceOnTheMicrofacet) {
  // W(c) = 1 exactly where c = |wo + wi|/2 = 1, i.e. wi = wo (the mirror configuration at the
  // normal included), and W -> 1 everywhere as ior -> ∞ (F0 -> 1). Elsewhere W >= 1. Tolerances:
  // 1e-14 relative (rounding) at c = 1; at ior = 1e6, 1 - F0 = 4e-6, so W - 1 < 4e-6.
  Pcg32 rng(11, 12);
  for (recon::BrdfModel model : kFresnelModels) {
    BrdfParams fresnel = Make(model, {0.3, 0.2, 0.1}, {0.2, 0.3, 0.4}, 0.12, 0.35);
    BrdfParams plain = fresnel;
    plain.model = recon::WithoutFresnel(model);
    for (int i = 0; i < 200; ++i) {
      const Eigen::Vector3d wo = SampleUniformHemisphere(rng.Uniform2D());
      const Eigen::Vector3d wi = SampleUniformHemisphere(rng.Uniform2D());
      fresnel.ior = 1.5;
      const Eigen::Vector3d same = EvalBrdf(plain, wo, wo);
      EXPECT_NEAR((EvalBrdf(fresnel, wo, wo) - same).norm(), 0.0, 1e-14 * same.norm());
      const Eigen::Vector3d f = EvalBrdf(plain, wo, wi);
      EXPECT_TRUE((EvalBrdf(fresnel, wo, wi).array() >= f.array()).all());
      fresnel.ior = 1e6;
      EXPECT_NEAR((EvalBrdf(fresnel, wo, wi) - f).norm(), 0.0, 4e-6 * f.norm());
    }
    const Eigen::Vector3d n = Eigen::Vector3d::UnitZ();
    fresnel.ior = 1.5;
    EXPECT_EQ(EvalBrdf(fresnel, n, n), EvalBrdf(plain, n, n)) << recon::BrdfModelName(model);
  }
  // ior = 1.5: F0 = 0.04, so W = 1 + 24 (1 - c)⁵; opposite grazing directions (θ = 89°) have
  // c = cos 89° = 0.017452, W = 1 + 24 · 0.982548⁵ = 22.97755 (Python; 1e-6 relative: the printed
  // digits).
  const Eigen::Vector3d a = Dir(89, 0);
  const Eigen::Vector3d b = Dir(89, 180);
  EXPECT_NEAR(FresnelWeight(1.5, a, b), 1.0 + 24.0 * std::pow(1.0 - std::cos(89 * kPi / 180), 5),
              1e-13);
  EXPECT_NEAR(FresnelWeight(1.5, a, b), 22.97755, 22.98e-6);
}

// The solver's α search builds SpecularFactor from these parts once per direction pair
// (solver/inverse/region_fit.cpp): they must give it back at any roughness, and nothing below the
// surface.
TEST(BrdfEvalTest, SpecularFactorPartsGiveTheFactorAtAnyRoughness) {
  Pcg32 rng(5, 6);
  for (recon::BrdfModel model : kAllModels) {
    for (int i = 0; i < 500; ++i) {
      const Eigen::Vector3d wo = SampleUniformHemisphere(rng.Uniform2D());
      const Eigen::Vector3d wi = SampleUniformHemisphere(rng.Uniform2D());
      const double ax = 0.02 + 0.5 * rng.UniformDouble(), ay = 0.02 + 0.5 * rng.UniformDouble();
      double qx = 0, qy = 0, g = 0;
      const double s = SpecularFactor<double>(model, ax, ay, wo, wi);
      if (!SpecularFactorParts(model, wo, wi, &qx, &qy, &g)) {
        EXPECT_FALSE(recon::HasSpecularLobe(model));
        EXPECT_EQ(s, 0.0);
        continue;
      }
      const double parts = g * std::exp(-(qx / (ax * ax) + qy / (ay * ay))) / (ax * ay);
      EXPECT_NEAR(parts, s, 1e-12 * std::max(1.0, s)) << recon::BrdfModelName(model);
    }
    double qx = 0, qy = 0, g = 0;
    EXPECT_FALSE(SpecularFactorParts(model, {0, 0.6, -0.8}, {0, 0, 1}, &qx, &qy, &g));
    EXPECT_FALSE(SpecularFactorParts(model, {0, 0, 1}, {0.6, 0, -0.8}, &qx, &qy, &g));
  }
}

TEST(BrdfEvalTest, IsReciprocal) {
  Pcg32 rng(3, 4);
  for (recon::BrdfModel model : EveryModel()) {
    const BrdfParams p = Make(model, {0.3, 0.2, 0.1}, {0.2, 0.3, 0.4}, 0.12, 0.35);
    for (int i = 0; i < 1000; ++i) {
      const Eigen::Vector3d a = SampleUniformHemisphere(rng.Uniform2D());
      const Eigen::Vector3d b = SampleUniformHemisphere(rng.Uniform2D());
      const Eigen::Vector3d fab = EvalBrdf(p, a, b);
      EXPECT_NEAR((fab - EvalBrdf(p, b, a)).norm(), 0.0, 1e-14 * fab.norm());
    }
  }
}

TEST(BrdfEvalTest, AnisotropicModelsReduceToIsotropicAndRotateWithTheTangent) {
  Pcg32 rng(5, 6);
  const std::pair<recon::BrdfModel, recon::BrdfModel> pairs[] = {
      {recon::BrdfModel::kWardAniso, recon::BrdfModel::kWard},
      {recon::BrdfModel::kWardGmdAniso, recon::BrdfModel::kWardGmd},
      {recon::BrdfModel::kWardAnisoFresnel, recon::BrdfModel::kWardFresnel},
      {recon::BrdfModel::kWardGmdAnisoFresnel, recon::BrdfModel::kWardGmdFresnel},
      {recon::BrdfModel::kGgxAniso, recon::BrdfModel::kGgx},
      {recon::BrdfModel::kBeckmannAniso, recon::BrdfModel::kBeckmann}};
  for (const auto& [aniso, iso] : pairs) {
    for (int i = 0; i < 200; ++i) {
      const Eigen::Vector3d wo = SampleUniformHemisphere(rng.Uniform2D());
      const Eigen::Vector3d wi = SampleUniformHemisphere(rng.Uniform2D());
      const Eigen::Vector3d f_iso = EvalBrdf(Grey(iso, 0.1, 0.5, 0.15, 0.9), wo, wi);
      const Eigen::Vector3d f_aniso = EvalBrdf(Grey(aniso, 0.1, 0.5, 0.15, 0.15), wo, wi);
      EXPECT_NEAR((f_iso - f_aniso).norm(), 0.0, 1e-13 * f_iso.norm());
      // Swapping αx and αy equals turning the directions by 90° about n: (x, y) -> (-y, x).
      auto turn = [](const Eigen::Vector3d& v) { return Eigen::Vector3d(-v.y(), v.x(), v.z()); };
      const Eigen::Vector3d f_xy = EvalBrdf(Grey(aniso, 0.1, 0.5, 0.1, 0.4), wo, wi);
      const Eigen::Vector3d f_yx = EvalBrdf(Grey(aniso, 0.1, 0.5, 0.4, 0.1), turn(wo), turn(wi));
      EXPECT_NEAR((f_xy - f_yx).norm(), 0.0, 1e-13 * f_xy.norm());
    }
  }
  // The highlight stretches along the rougher direction: at the same tilt of h, the lobe is
  // higher along y when αy > αx.
  const BrdfParams p = Grey(recon::BrdfModel::kWardAniso, 0.0, 1.0, 0.1, 0.4);
  EXPECT_GT(EvalBrdf(p, Dir(30, 90), Dir(40, 270))[0], EvalBrdf(p, Dir(30, 0), Dir(40, 180))[0]);
}

// ---- derivatives through Ceres Jets ---------------------------------------------------------

TEST(BrdfEvalTest, JetDerivativesMatchFiniteDifferences) {
  using Jet = ceres::Jet<double, 5>;
  const Eigen::Vector3d wo = Dir(35, 10);
  const Eigen::Vector3d wi = Dir(42, 200);
  for (recon::BrdfModel model : EveryModel()) {
    // Parameters: 0 = rho_d[0], 1 = rho_s[0], 2 = alpha or alpha_x, 3 = alpha_y, 4 = ior.
    const double x0[5] = {0.4, 0.2, 0.18, 0.27, 1.6};
    auto eval = [&](const double* x) {
      BrdfParams p = Make(model, {x[0], 0.3, 0.3}, {x[1], 0.1, 0.1}, x[2], x[3]);
      p.ior = x[4];
      return EvalBrdf(p, wo, wi)[0];
    };
    BrdfParamsT<Jet> pj;
    pj.model = model;
    pj.rho_d = {Jet(x0[0], 0), Jet(0.3), Jet(0.3)};
    pj.rho_s = {Jet(x0[1], 1), Jet(0.1), Jet(0.1)};
    pj.alpha = Jet(x0[2], 2);
    pj.alpha_x = Jet(x0[2], 2);
    pj.alpha_y = Jet(x0[3], 3);
    pj.ior = Jet(x0[4], 4);
    const Jet f = EvalBrdf<Jet>(pj, wo.cast<Jet>(), wi.cast<Jet>())[0];
    EXPECT_NEAR(f.a, eval(x0), 1e-15);
    for (int k = 0; k < 5; ++k) {
      // Central differences with step 1e-6: truncation ~1e-12 and rounding ~1e-10 relative to
      // derivatives of order 1-10, so 1e-7 relative + 1e-9 absolute is safe.
      double xp[5], xm[5];
      std::copy(x0, x0 + 5, xp);
      std::copy(x0, x0 + 5, xm);
      xp[k] += 1e-6;
      xm[k] -= 1e-6;
      const double fd = (eval(xp) - eval(xm)) / 2e-6;
      EXPECT_NEAR(f.v[k], fd, 1e-7 * std::abs(fd) + 1e-9)
          << recon::BrdfModelName(model) << " d" << k;
    }
    if (recon::HasSpecularLobe(model)) {
      EXPECT_GT(std::abs(f.v[2]), 1e-3);  // α really moves f
    }
    if (recon::HasFresnel(model)) {
      EXPECT_LT(f.v[4], -1e-4);  // a higher ior raises F0, so lowers F/F0 off normal incidence
    } else {
      EXPECT_EQ(f.v[4], 0.0);
    }
  }
}

// ---- energy ---------------------------------------------------------------------------------

// Directional albedo ∫ f(wo, wi) cosθi dωi (channel 0) by Simpson (θ) × trapezoid (φ,
// periodic: spectrally accurate) on a 200 × 1080 grid of the hemisphere. The φ step is the
// critical one: at grazing wo the lobe is narrow across the plane of incidence (α = 0.05 at
// 80°: about 0.02 rad). Against a 8000 × 8000 midpoint reference, and against 2400 × 1440, the
// error is < 1e-6 for α >= 0.05 and θo <= 85° (360 φ steps were 1.6e-3 off at 80°).
double Albedo(const BrdfParams& p, const Eigen::Vector3d& wo) {
  return IntegrateSphere([&](const Eigen::Vector3d& wi) { return EvalBrdf(p, wo, wi)[0] * wi.z(); },
                         kPi / 2, 200, 1080);
}

TEST(BrdfEnergyTest, LambertAlbedoIsRhoD) {
  EXPECT_NEAR(Albedo(Grey(recon::BrdfModel::kLambert, 0.7, 0.0, 0.1, 0.1), Dir(50, 0)), 0.7, 1e-9);
}

TEST(BrdfEnergyTest, AlbedoMatchesReferenceQuadrature) {
  // Specular albedos (ρs = 1) from an independent 8000 × 8000 midpoint quadrature (θ, φ) of the
  // contract formulas, printed to 5 digits: tolerance 1e-5 (their rounding).
  struct Case {
    recon::BrdfModel model;
    double alpha, theta_o, albedo;
  };
  for (const Case& c : {Case{recon::BrdfModel::kWardGmd, 0.05, 80, 0.95322},
                        Case{recon::BrdfModel::kWardGmd, 0.1, 85, 0.81277},
                        Case{recon::BrdfModel::kWardGmd, 0.5, 0, 0.75458},
                        Case{recon::BrdfModel::kWard, 0.2, 60, 0.45885},
                        Case{recon::BrdfModel::kWard, 0.5, 75, 0.27717}}) {
    EXPECT_NEAR(Albedo(Grey(c.model, 0.0, 1.0, c.alpha, c.alpha), Dir(c.theta_o, 0)), c.albedo,
                1e-5)
        << recon::BrdfModelName(c.model) << " alpha " << c.alpha << " theta " << c.theta_o;
  }
}

TEST(BrdfEnergyTest, NoModelCreatesEnergyForPlausibleParameters) {
  // With ρd = 0, ρs = 1 the albedo is the specular lobe's: <= 1 means any ρd + ρs <= 1
  // conserves energy (the diffuse albedo is ρd exactly). Checked for α in [0.05, 0.5] and
  // θo <= 80°. Ward-GMD stays near 1 for small α at all angles (0.99 at 0°, 0.95 at 80°,
  // α = 0.05) and falls to 0.75 at α = 0.5, its known off-specular loss.
  for (recon::BrdfModel model :
       {recon::BrdfModel::kWard, recon::BrdfModel::kWardGmd, recon::BrdfModel::kWardAniso,
        recon::BrdfModel::kWardGmdAniso, recon::BrdfModel::kGgx, recon::BrdfModel::kGgxAniso,
        recon::BrdfModel::kBeckmann, recon::BrdfModel::kBeckmannAniso}) {
    for (double alpha : {0.05, 0.2, 0.5}) {
      for (double theta : {0.0, 45.0, 70.0, 80.0}) {
        const double a = Albedo(Grey(model, 0.0, 1.0, alpha, 0.6 * alpha), Dir(theta, 25));
        // 2e-5: the quadrature's error on the narrowest lobes, whose albedo is within 1e-5 of 1
        // (Beckmann at α 0.05: 1.00001).
        EXPECT_LE(a, 1.0 + 2e-5) << recon::BrdfModelName(model) << " alpha " << alpha << " theta "
                                 << theta;
        if (recon::IsGmd(model)) {
          EXPECT_GT(a, 0.7) << "alpha " << alpha << " theta " << theta;
        }
      }
    }
  }
}

// Oren–Nayar's diffuse term against its angle form (Oren and Nayar 1994): σ 0 is Lambert's; at
// normal viewing it is A·ρd/π whatever the light; it is reciprocal; and where light and view lie
// on one side of the normal (φi = φo) it adds B·sin(max θ)·tan(min θ), none on opposite sides.
TEST(BrdfEvalTest, OrenNayarMatchesItsAngleForm) {
  BrdfParams p = Grey(recon::BrdfModel::kLambert, 0.6, 0.0, 0.1, 0.1);
  p.diffuse = recon::DiffuseShape::kOrenNayar;
  p.sigma = 0.0;
  EXPECT_NEAR(EvalBrdf(p, Dir(40, 10), Dir(60, 100))[0], 0.6 / kPi, 1e-15);
  p.sigma = 0.4;
  const double s2 = 0.16, a = 1 - 0.5 * s2 / (s2 + 0.33), b = 0.45 * s2 / (s2 + 0.09);
  EXPECT_NEAR(EvalBrdf(p, Dir(0, 0), Dir(70, 40))[0], 0.6 / kPi * a, 1e-15);
  for (auto [ti, to, dphi] :
       {std::tuple{60.0, 20.0, 0.0}, {20.0, 60.0, 30.0}, {75.0, 75.0, 80.0}, {30.0, 50.0, 120.0}}) {
    const double alpha = std::max(ti, to) * kPi / 180, beta = std::min(ti, to) * kPi / 180;
    const double want =
        0.6 / kPi *
        (a + b * std::max(0.0, std::cos(dphi * kPi / 180)) * std::sin(alpha) * std::tan(beta));
    EXPECT_NEAR(EvalBrdf(p, Dir(to, 15), Dir(ti, 15 + dphi))[0], want, 1e-14 * want)
        << ti << " " << to << " " << dphi;
    EXPECT_NEAR(EvalBrdf(p, Dir(ti, 15 + dphi), Dir(to, 15))[0], want, 1e-14 * want);
  }
}

// Oren–Nayar's qualitative model is not exactly energy-conserving: with ρd = 1 its albedo is A
// at normal viewing and rises toward grazing views, past 1 only for small σ beyond ~75°
// (σ 0.2: 1.007 at 80°, 1.013 at 89°; σ 0.5: 0.78 at 0°, 0.93 at 80°; independent midpoint
// quadrature). The furnace: at most 1.015, and at most 1 up to 70°.
TEST(BrdfEnergyTest, OrenNayarAlbedoIsAtMostOneBelowGrazing) {
  BrdfParams p = Grey(recon::BrdfModel::kLambert, 1.0, 0.0, 0.1, 0.1);
  p.diffuse = recon::DiffuseShape::kOrenNayar;
  for (double sigma : {0.2, 0.5, 1.0}) {
    p.sigma = sigma;
    const double s2 = sigma * sigma;
    EXPECT_NEAR(Albedo(p, Dir(0, 0)), 1 - 0.5 * s2 / (s2 + 0.33), 1e-6);
    for (double theta : {30.0, 70.0, 80.0, 88.0}) {
      const double a = Albedo(p, Dir(theta, 20));
      EXPECT_LE(a, theta <= 70 ? 1.0 : 1.015) << sigma << " " << theta;
      EXPECT_GT(a, Albedo(p, Dir(0, 0)));  // brighter toward grazing views (back-scatter)
    }
  }
  p.sigma = 0.5;
  EXPECT_NEAR(Albedo(p, Dir(60, 0)), 0.8831, 2e-4);  // the midpoint quadrature's value
  // The albedo is A + B·OrenNayarMeanG(cosθo): the term's mean over the cosine-weighted light.
  for (double theta : {0.0, 30.0, 60.0, 85.0}) {
    const double mean_g = OrenNayarMeanG(std::cos(theta * kPi / 180));
    EXPECT_NEAR(Albedo(p, Dir(theta, 10)), OrenNayarA(0.5) + OrenNayarB(0.5) * mean_g, 1e-3)
        << theta;
  }
}

// The coated base's diffuse term: ρd/π·T(cosθi)·T(cosθo), T(c) = 1 − (1 − c)⁵, the Schlick
// transmittance with F0 folded into ρd: ρd/π at normal light and view, reciprocal, and the
// darkening toward grazing light a Lambertian surface does not have (T(cos 80°) = 0.6147).
TEST(BrdfEvalTest, CoatedDiffuseIsTheCoatsTwoTransmittances) {
  BrdfParams p = Grey(recon::BrdfModel::kLambert, 0.6, 0.0, 0.1, 0.1);
  p.diffuse = recon::DiffuseShape::kCoated;
  EXPECT_NEAR(EvalBrdf(p, Dir(0, 0), Dir(0, 0))[0], 0.6 / kPi, 1e-15);
  EXPECT_NEAR(CoatTransmission(std::cos(80 * kPi / 180)), 0.6147, 1e-4);
  for (auto [ti, to, dphi] :
       {std::tuple{60.0, 20.0, 0.0}, {20.0, 60.0, 30.0}, {75.0, 75.0, 80.0}, {85.0, 5.0, 170.0}}) {
    const double ci = std::cos(ti * kPi / 180), co = std::cos(to * kPi / 180);
    const double want = 0.6 / kPi * (1 - std::pow(1 - ci, 5)) * (1 - std::pow(1 - co, 5));
    EXPECT_NEAR(EvalBrdf(p, Dir(to, 15), Dir(ti, 15 + dphi))[0], want, 1e-14) << ti << " " << to;
    EXPECT_NEAR(EvalBrdf(p, Dir(ti, 15 + dphi), Dir(to, 15))[0], want, 1e-14);
  }
  // Under a lobe the diffuse term is the same and the lobe is added unchanged.
  BrdfParams ggx = Grey(recon::BrdfModel::kGgx, 0.6, 0.04, 0.2, 0.2);
  BrdfParams coated_ggx = ggx;
  coated_ggx.diffuse = recon::DiffuseShape::kCoated;
  const Eigen::Vector3d wo = Dir(30, 0), wi = Dir(50, 160);
  EXPECT_NEAR((EvalBrdf(coated_ggx, wo, wi) - EvalBrdf(ggx, wo, wi))[0],
              0.6 / kPi * (CoatTransmission(wo.z()) * CoatTransmission(wi.z()) - 1), 1e-15);
}

// The coated term only takes energy away: with ρd = 1 its albedo is T(cosθo)·20/21 (T's mean
// over the cosine-weighted light is 1 − 2∫(1 − c)⁵c dc = 20/21), below 1 at every view.
TEST(BrdfEnergyTest, CoatedDiffuseAlbedoIsTheViewsTransmittanceTimesTheMean) {
  BrdfParams p = Grey(recon::BrdfModel::kLambert, 1.0, 0.0, 0.1, 0.1);
  p.diffuse = recon::DiffuseShape::kCoated;
  for (double theta : {0.0, 30.0, 60.0, 80.0, 88.0}) {
    const double a = Albedo(p, Dir(theta, 20));
    EXPECT_NEAR(a, CoatTransmission(std::cos(theta * kPi / 180)) * 20.0 / 21.0, 1e-4) << theta;
    EXPECT_LT(a, 1.0);
  }
}

// DiffuseMeanFactor is the directional albedo's mean over cosine-weighted views (with ρd = 1):
// what a patch that no photo sees sends the rest of the room under light from everywhere.
TEST(BrdfEnergyTest, DiffuseMeanFactorIsTheAlbedosMeanOverViews) {
  BrdfParams p = Grey(recon::BrdfModel::kLambert, 1.0, 0.0, 0.1, 0.1);
  EXPECT_EQ(DiffuseMeanFactor(p), 1.0);
  p.diffuse = recon::DiffuseShape::kCoated;
  BrdfParams on = p;
  on.diffuse = recon::DiffuseShape::kOrenNayar;
  on.sigma = 0.5;
  for (const BrdfParams& q : {p, on}) {
    constexpr int kN = 24;  // midpoint rule in cos²θo: the cosine weight's 2c dc
    double mean = 0;
    for (int i = 0; i < kN; ++i) {
      const double theta = std::acos(std::sqrt((i + 0.5) / kN)) * 180 / kPi;
      mean += Albedo(q, Dir(theta, 30)) / kN;
    }
    EXPECT_NEAR(DiffuseMeanFactor(q), mean, 2e-3) << recon::DiffuseShapeName(q.diffuse);
  }
  EXPECT_NEAR(DiffuseMeanFactor(p), 400.0 / 441.0, 1e-15);
}

TEST(BrdfEnergyTest, FresnelWeightRaisesTheSpecularAlbedoMostTowardGrazing) {
  // The albedo ratio fresnel/plain (ρd = 0, ρs = 1, α = 0.1, ior 1.5) is ~1 at normal viewing
  // (c ≈ 1 over the whole lobe) and grows toward grazing, as Schlick's factor does at the mirror
  // direction (W(cos θo) = 1 + 24 (1 - cos θo)⁵: 1.0000, 1.0008, 1.75, 8.1 at 0, 30, 60, 80°).
  // Tolerance: the quadrature's 1e-6 becomes 1e-4 on ratios of spread-out lobes; the bounds are
  // loose brackets around W(cos θo) (the lobe averages W over its width).
  double previous = 0.0;
  for (double theta : {0.0, 30.0, 60.0, 80.0}) {
    const double plain =
        Albedo(Grey(recon::BrdfModel::kWardGmd, 0.0, 1.0, 0.1, 0.1), Dir(theta, 0));
    BrdfParams p = Grey(recon::BrdfModel::kWardGmdFresnel, 0.0, 1.0, 0.1, 0.1);
    p.ior = 1.5;
    const double ratio = Albedo(p, Dir(theta, 0)) / plain;
    const double w_mirror = 1.0 + 24.0 * std::pow(1.0 - std::cos(theta * kPi / 180), 5);
    EXPECT_GT(ratio, previous) << theta;
    EXPECT_GE(ratio, 1.0) << theta;
    EXPECT_NEAR(ratio, w_mirror, 0.25 * w_mirror) << theta;
    previous = ratio;
  }
}

TEST(BrdfEnergyTest, Ward1992LosesEnergyTowardGrazingWhereGmdDoesNot) {
  // The 1/√(cosθi cosθo) normalisation makes the specular albedo of a narrow lobe fall like
  // cosθo (measured, ρs = 1, α = 0.05: 0.99, 0.86, 0.50, 0.26 at 0°, 30°, 60°, 75°); Ward-GMD
  // keeps it (0.997, 0.997, 0.994, 0.979). It never exceeds 1 for α <= 0.5 (test above).
  for (double theta : {30.0, 60.0, 75.0}) {
    const double ward = Albedo(Grey(recon::BrdfModel::kWard, 0.0, 1.0, 0.05, 0.05), Dir(theta, 0));
    const double gmd =
        Albedo(Grey(recon::BrdfModel::kWardGmd, 0.0, 1.0, 0.05, 0.05), Dir(theta, 0));
    const double cos_o = std::cos(theta * kPi / 180.0);
    EXPECT_NEAR(ward, cos_o, 0.01 * cos_o) << theta;
    EXPECT_GT(gmd, 0.97) << theta;
  }
}

// ---- sampling -------------------------------------------------------------------------------

struct SamplingCase {
  BrdfParams params;
  Eigen::Vector3d wo;
};

std::vector<SamplingCase> SamplingCases() {
  std::vector<BrdfParams> params = {Grey(recon::BrdfModel::kLambert, 0.6, 0.0, 0.1, 0.1)};
  for (recon::BrdfModel model : {recon::BrdfModel::kWard, recon::BrdfModel::kWardGmd}) {
    params.push_back(Grey(model, 0.4, 0.3, 0.05, 0.05));
    params.push_back(Grey(model, 0.0, 0.5, 0.3, 0.3));
  }
  for (recon::BrdfModel model : {recon::BrdfModel::kWardAniso, recon::BrdfModel::kWardGmdAniso}) {
    params.push_back(Grey(model, 0.4, 0.3, 0.05, 0.25));
    params.push_back(Grey(model, 0.0, 0.5, 0.4, 0.1));
  }
  // The *_fresnel models draw as their plain models do; f (and so the weights) differ.
  for (recon::BrdfModel model :
       {recon::BrdfModel::kWardFresnel, recon::BrdfModel::kWardGmdFresnel}) {
    params.push_back(Grey(model, 0.4, 0.3, 0.05, 0.05));
    params.back().ior = 1.4;
    params.push_back(Grey(model, 0.0, 0.5, 0.3, 0.3));
  }
  params.push_back(Grey(recon::BrdfModel::kWardGmdAnisoFresnel, 0.2, 0.3, 0.05, 0.25));
  // The microfacet lobes: GGX's visible normals, Beckmann's Gaussian slopes.
  for (recon::BrdfModel model : {recon::BrdfModel::kGgx, recon::BrdfModel::kBeckmann}) {
    params.push_back(Grey(model, 0.4, 0.3, 0.05, 0.05));
    params.push_back(Grey(model, 0.0, 0.5, 0.3, 0.3));
  }
  for (recon::BrdfModel model : {recon::BrdfModel::kGgxAniso, recon::BrdfModel::kBeckmannAniso}) {
    params.push_back(Grey(model, 0.2, 0.04, 0.05, 0.25));
    params.push_back(Grey(model, 0.0, 0.9, 0.6, 0.1));
  }
  // Oren–Nayar's and the coated diffuse term alone and under a lobe: drawn cosine-weighted,
  // weighted by f.
  for (recon::BrdfModel model : {recon::BrdfModel::kLambert, recon::BrdfModel::kGgx}) {
    params.push_back(Grey(model, 0.6, 0.2, 0.2, 0.2));
    params.back().diffuse = recon::DiffuseShape::kOrenNayar;
    params.back().sigma = 0.5;
    params.push_back(Grey(model, 0.6, 0.2, 0.2, 0.2));
    params.back().diffuse = recon::DiffuseShape::kCoated;
  }
  std::vector<SamplingCase> cases;
  for (const BrdfParams& p : params) {
    for (double theta : {0.0, 35.0, 70.0}) cases.push_back({p, Dir(theta, 30)});
  }
  return cases;
}

std::string Describe(const SamplingCase& c) {
  return std::string(recon::BrdfModelName(c.params.model)) + " ax " +
         std::to_string(c.params.AlphaX()) + " ay " + std::to_string(c.params.AlphaY()) +
         " rho_d " + std::to_string(c.params.rho_d[0]) + " theta_o " +
         std::to_string(std::acos(c.wo.z()) * 180 / kPi);
}

std::optional<Eigen::Vector3d> Draw(const SamplingCase& c, Pcg32& rng) {
  const double u_lobe = rng.UniformDouble();
  const BrdfSample s = SampleBrdf(c.params, c.wo, u_lobe, rng.Uniform2D());
  if (s.pdf > 0.0) return s.wi;
  return std::nullopt;
}

TEST(BrdfSamplingTest, SampledDirectionsFollowThePdf) {
  // Pearson chi-square on 4.5° × 9° bins of the upper hemisphere plus one bin for draws below it
  // or failed, 200k draws per case, family-wise significance 1% (Šidák over the cases).
  const std::vector<SamplingCase> cases = SamplingCases();
  const SphereHistogram histogram{20, 40, kPi / 2};
  for (size_t i = 0; i < cases.size(); ++i) {
    const SamplingCase& c = cases[i];
    const auto result =
        TestDirections([&](Pcg32& rng) { return Draw(c, rng); },
                       [&](const Eigen::Vector3d& wi) { return BrdfPdf(c.params, c.wo, wi); },
                       histogram, 200000, 1000 + i);
    EXPECT_GT(result.p_value, SidakLevel(0.01, static_cast<int>(cases.size())))
        << Describe(c) << ": chi2 " << result.statistic << " dof " << result.dof;
  }
}

TEST(BrdfSamplingTest, ChiSquareDetectsAPdfTenPercentOffInAlpha) {
  // The power check: draws with α = 0.3 against the pdf of α = 0.33 must be rejected.
  const SamplingCase c{Grey(recon::BrdfModel::kWardGmd, 0.0, 0.5, 0.3, 0.3), Dir(35, 30)};
  const BrdfParams wrong = Grey(recon::BrdfModel::kWardGmd, 0.0, 0.5, 0.33, 0.33);
  const auto result =
      TestDirections([&](Pcg32& rng) { return Draw(c, rng); },
                     [&](const Eigen::Vector3d& wi) { return BrdfPdf(wrong, c.wo, wi); },
                     SphereHistogram{20, 40, kPi / 2}, 200000, 99);
  EXPECT_LT(result.p_value, 1e-6);
}

// Probability that the specular lobe's draw lands in the upper hemisphere, from the half-vector
// distribution alone (no use of the code's Jacobian): slopes p = (h.x, h.y)/h.z have density
// exp(-(px²/αx² + py²/αy²))/(π αx αy); write p = (αx r cosφ, αy r sinφ). With wo fixed,
// wi = 2(wo·ĥ)ĥ - wo has wi.z > 0 iff wo.z q r² - 2 c r - wo.z < 0 (c = wo.x αx cosφ +
// wo.y αy sinφ, q = αx² cos²φ + αy² sin²φ), i.e. r < r+(φ) = (c + √(c² + wo.z² q))/(wo.z q),
// which also implies wo·ĥ > 0. So the probability is the φ-mean of 1 - exp(-r+²).
double SpecularUpperMass(double ax, double ay, const Eigen::Vector3d& wo) {
  constexpr int kN = 4096;  // trapezoid rule on a smooth periodic integrand: spectral accuracy
  double sum = 0.0;
  for (int k = 0; k < kN; ++k) {
    const double phi = 2.0 * kPi * k / kN;
    const double c = wo.x() * ax * std::cos(phi) + wo.y() * ay * std::sin(phi);
    const double q = std::pow(ax * std::cos(phi), 2) + std::pow(ay * std::sin(phi), 2);
    const double r_plus = (c + std::sqrt(c * c + wo.z() * wo.z() * q)) / (wo.z() * q);
    sum += 1.0 - std::exp(-r_plus * r_plus);
  }
  return sum / kN;
}

// The same for GGX's visible normals (no draw fails): the share of the normals, with density
// G1(wo)·D(ĥ)·max(0, wo·ĥ)/cosθo over the hemisphere of ĥ, that mirror wo above the surface. The
// midpoint rule in θh (1000 steps) and φh (2000): the density's kink where wo·ĥ = 0 costs
// Simpson's rule its order; the whole density integrates to 1 within 2.5e-6 at these steps.
double GgxUpperMass(double ax, double ay, const Eigen::Vector3d& wo) {
  constexpr int kN = 1000;
  const double g1 = microfacet::SmithG1<double>(recon::LobeShape::kGgx, ax, ay, wo);
  double sum = 0;
  for (int i = 0; i < kN; ++i) {
    const double theta = (i + 0.5) / kN * kPi / 2, s = std::sin(theta);
    for (int j = 0; j < 2 * kN; ++j) {
      const double phi = kPi * (j + 0.5) / kN;
      const Eigen::Vector3d h(s * std::cos(phi), s * std::sin(phi), std::cos(theta));
      const double cos_oh = wo.dot(h);
      if (!(cos_oh > 0) || !((2 * cos_oh * h - wo).z() > 0)) continue;
      sum += s * microfacet::Distribution<double>(recon::LobeShape::kGgx, ax, ay, h) * cos_oh;
    }
  }
  return g1 / wo.z() * sum * (kPi / 2 / kN) * (kPi / kN);
}

TEST(BrdfSamplingTest, PdfIntegratesToTheProbabilityOfItsDraws) {
  for (const SamplingCase& c : SamplingCases()) {
    const BrdfParams& p = c.params;
    const double p_spec = SpecularLobeProbability(p, c.wo);
    auto pdf = [&](const Eigen::Vector3d& wi) { return BrdfPdf(p, c.wo, wi); };
    // Upper hemisphere: (1 - P_spec) · 1 + P_spec · the specular draws' mass there. Quadrature
    // as in Albedo() (error < 1e-6); the 1e-4 tolerance still catches any wrong factor in the
    // Jacobian (a missing cosθh changes the mass by > 1e-3 even at α = 0.05).
    const double upper = IntegrateSphere(pdf, kPi / 2, 200, 1080);
    const double mass = recon::Lobe(p.model) == recon::LobeShape::kGgx
                            ? GgxUpperMass(p.AlphaX(), p.AlphaY(), c.wo)
                            : SpecularUpperMass(p.AlphaX(), p.AlphaY(), c.wo);
    const double expected = (1.0 - p_spec) + p_spec * mass;
    EXPECT_NEAR(upper, expected, 1e-4) << Describe(c);
    if (c.wo.z() == 1.0) {
      // wo = n: no draw fails (wo·ĥ = cosθh > 0), so over the whole sphere the pdf integrates
      // to exactly 1; the draws with θh > 45° land below the surface.
      EXPECT_NEAR(IntegrateSphere(pdf, kPi, 400, 1080), 1.0, 1e-4) << Describe(c);
    }
  }
}

TEST(BrdfSamplingTest, SampleReportsEvalAndPdfAtItsDirection) {
  Pcg32 rng(7, 8);
  for (const SamplingCase& c : SamplingCases()) {
    int valid = 0;
    for (int i = 0; i < 2000; ++i) {
      const double u_lobe = rng.UniformDouble();
      const BrdfSample s = SampleBrdf(c.params, c.wo, u_lobe, rng.Uniform2D());
      if (s.pdf == 0.0) {
        EXPECT_EQ(s.lobe, BrdfLobe::kSpecular);  // only the specular draw can fail
        EXPECT_FALSE(s.Valid());
        continue;
      }
      EXPECT_NEAR(s.wi.norm(), 1.0, 1e-12);
      EXPECT_EQ(s.lobe, u_lobe < SpecularLobeProbability(c.params, c.wo) ? BrdfLobe::kSpecular
                                                                         : BrdfLobe::kDiffuse);
      const Eigen::Vector3d f = EvalBrdf(c.params, c.wo, s.wi);
      EXPECT_NEAR((s.f - f).norm(), 0.0, 1e-14 * f.norm());
      EXPECT_NEAR(s.pdf, BrdfPdf(c.params, c.wo, s.wi), 1e-14 * s.pdf);
      if (!s.Valid()) {
        EXPECT_LE(s.wi.z(), 0.0);
        EXPECT_EQ(s.weight, Eigen::Vector3d::Zero());
        continue;
      }
      ++valid;
      const Eigen::Vector3d weight = f * s.wi.z() / BrdfPdf(c.params, c.wo, s.wi);
      EXPECT_NEAR((s.weight - weight).norm(), 0.0, 1e-13 * weight.norm());
    }
    EXPECT_GT(valid, 1000) << Describe(c);
  }
}

TEST(BrdfSamplingTest, WeightsEstimateTheAlbedoWithoutBias) {
  // E[weight] over draws = ∫ f cosθi dωi: Monte Carlo with 100k draws against the quadrature of
  // Albedo(); tolerance 5 standard errors of the sample mean.
  for (const SamplingCase& c : SamplingCases()) {
    Pcg32 rng(9, 10);
    constexpr int kN = 100000;
    double sum = 0.0;
    double sum2 = 0.0;
    for (int i = 0; i < kN; ++i) {
      const double u_lobe = rng.UniformDouble();
      const double w = SampleBrdf(c.params, c.wo, u_lobe, rng.Uniform2D()).weight[0];
      sum += w;
      sum2 += w * w;
    }
    const double mean = sum / kN;
    const double std_error = std::sqrt(std::max(0.0, sum2 / kN - mean * mean) / kN);
    // 2e-6: the quadrature's error where the draws' weights are nearly constant (the narrow
    // Beckmann lobe at normal viewing: its standard error 4e-9, the quadrature 7.6e-7 high).
    EXPECT_NEAR(mean, Albedo(c.params, c.wo), 5.0 * std_error + 2e-6) << Describe(c);
  }
}

}  // namespace
}  // namespace igi::render
