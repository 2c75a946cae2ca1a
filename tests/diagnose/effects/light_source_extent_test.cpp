// light_source_extent (solver/diagnose/effects/light_source_extent.cpp) on floor records the
// renderer path-traces (an independent estimator of a sphere's direct light): a sphere light's
// radius is recovered from soft shadow edges, also when the residual's tail there is flagged as
// outliers, and from the light an opaque sphere hides; photos of a point light earn nothing. And
// its Write: the light becomes a sphere of the same intensity.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <set>
#include <vector>

#include "solver/diagnose/candidates.h"
#include "solver/diagnose/effects/effects.h"
#include "solver/diagnose/pixel_records.h"
#include "solver/diagnose/residual_fit.h"
#include "solver/render/sampling.h"
#include "tests/diagnose/one_light_record.h"
#include "tests/diagnose/shadow_records.h"

namespace igi::diagnose {
namespace {

using Eigen::Vector3d;
using Eigen::Vector3f;
using namespace test::shadow;

TEST(LightSourceExtentTest, RecoversTheRadiusFromSoftShadows) {
  const recon::Scene model = ShadowScene(0);
  const Json declared = Json{{"lights", {{"lamp", {{"type", "point"}}}}}};
  const std::vector<PixelRecord> records = ShadowRecords(model, 0.2);
  const ResidualFitter f(records, std::vector<int>(records.size(), 0), 1, false, 8);
  const CandidateResult c = LightSourceExtent({model, declared, false}, f, 0);
  ASSERT_TRUE(c.valid) << c.note;
  EXPECT_EQ(c.effect, "light_source_extent");
  EXPECT_GT(c.Gain(), 0.5);
  EXPECT_GT(c.z, 5);
  // The photo's penumbrae carry 256-sample noise, the candidate's prediction 16 samples per
  // record: the radius is pinned to about 10 %; allow 15 %.
  EXPECT_NEAR(c.params["radius"].get<double>(), 0.2, 0.03);
  Json doc = declared;
  test::WriteCandidate(c, &doc);
  const Json& l = doc["lights"]["lamp"];
  EXPECT_EQ(l["type"], "sphere");
  EXPECT_NEAR(l["radius"].get<double>(), c.params["radius"].get<double>(), 1e-12);
  const double r = l["radius"];
  EXPECT_NEAR(l["radiance"][0].get<double>() * render::kPi * r * r, kIntensity,
              1e-9);  // same intensity
  EXPECT_NEAR(l["center"][0].get<double>(), kLamp.x(), 1e-12);
  // Its support: held-out blocks at the penumbrae, a small part of all the held-out blocks (the
  // step's significance counts these; igi-diagnose's refit test).
  const int block = CandidateContext{model, declared, false}.block_px;
  std::set<std::array<int, 3>> held, edges;
  for (const PixelRecord& rec : records) {
    if (!rec.held_out) continue;
    const std::array<int, 3> b = {rec.photo, rec.x / block, rec.y / block};
    held.insert(b);
    if ((rec.recorded - rec.sim).norm() > 0.08f * rec.sim.norm()) edges.insert(b);
  }
  ASSERT_GE(c.support_blocks.size(), 2u);
  EXPECT_LT(c.support_blocks.size(), held.size() / 2);
  int at_edges = 0;
  for (const std::array<int, 3>& b : c.support_blocks) {
    EXPECT_TRUE(held.count(b)) << b[1] << "," << b[2];
    at_edges += int(edges.count(b));
  }
  // Most where the photo differs from the model by 8 %; the others (4 of 11) lie in the umbra,
  // photo and model 0 (nothing else lights this floor), where the fitted sphere predicts a sliver
  // of light: any change is "15 % of the model's value" against a model of 0.
  EXPECT_GE(10 * at_edges, 6 * int(c.support_blocks.size()));
}

// igi-diagnose flags the residual's far tail as outliers (FlagOutliers: fireflies, unmodelled
// objects), and the other candidates leave those records out; at the light's shadow edges the
// tail is the extent's own signal. The candidate takes back the flagged records whose direct
// term a larger sphere changes, and still finds the radius.
TEST(LightSourceExtentTest, TakesBackTheTailAtItsShadowEdges) {
  const recon::Scene model = ShadowScene(0);
  const Json declared = Json{{"lights", {{"lamp", {{"type", "point"}}}}}};
  std::vector<PixelRecord> records = ShadowRecords(model, 0.2);
  FlagOutliers(&records);
  int flagged = 0;
  for (const PixelRecord& r : records) flagged += r.outlier;
  ASSERT_GT(flagged, 20);  // the penumbrae's records differ from the hard shadow by far more
  const ResidualFitter f(records, std::vector<int>(records.size(), 0), 1, false, 8);
  const CandidateResult c = LightSourceExtent({model, declared, false}, f, 0);
  ASSERT_TRUE(c.valid) << c.note;
  EXPECT_NE(c.evidence.find("taken back"), std::string::npos) << c.evidence;
  EXPECT_NEAR(c.params["radius"].get<double>(), 0.2, 0.03);
  EXPECT_GT(c.Gain(), 0.5);
  EXPECT_GT(c.z, 5);
  // Left out, as the other candidates leave them, the flagged records take the evidence with them.
  std::vector<PixelRecord> kept;
  for (const PixelRecord& r : records) {
    if (!r.outlier) kept.push_back(r);
  }
  const ResidualFitter g(kept, std::vector<int>(kept.size(), 0), 1, false, 8);
  const CandidateResult without = LightSourceExtent({model, declared, false}, g, 0);
  std::printf("with the tail taken back: z %.1f, radius %.3f; without it: %s z %.1f\n", c.z,
              c.params["radius"].get<double>(), without.valid ? "valid" : "invalid", without.z);
  if (without.valid) {
    EXPECT_GT(c.z, without.z);
  }
}

TEST(LightSourceExtentTest, APointLightEarnsNothing) {
  const recon::Scene model = ShadowScene(0);
  const Json declared = Json{{"lights", {{"lamp", {{"type", "point"}}}}}};
  const std::vector<PixelRecord> records = ShadowRecords(model, 0);
  const ResidualFitter f(records, std::vector<int>(records.size(), 0), 1, false, 8);
  const CandidateResult c = LightSourceExtent({model, declared, false}, f, 0);
  if (c.valid) {
    EXPECT_LT(c.Gain(), 0.01) << c.evidence;
  }
}

// An opaque sphere hides what lies behind it: a lamp 0.6 m under a white ceiling (igi-synth's
// room: 0.6 m) hides the ceiling's brightest patch, lit at I/0.36, from the floor below, and the
// floor's bounced light drops (here about 14 % of the direct light straight below for 0.25 m). No
// shadow edge or highlight shows the size: only that smooth loss does. Records on a floor under a
// ceiling, the photo path-traced with a sphere of 0.25 m and the same intensity, the model with
// the point lamp (path-traced too). The candidate finds the sphere from the light it hides.
recon::Scene CeilingScene(double radius) {
  recon::Scene s = ShadowScene(radius);
  s.mesh = recon::TriangleMesh{};
  AddQuad(&s.mesh, {Vector3f(-2, -2, 0), Vector3f(2, -2, 0), Vector3f(2, 2, 0), Vector3f(-2, 2, 0)},
          0);
  AddQuad(
      &s.mesh,
      {Vector3f(-2, -2, 2.6f), Vector3f(-2, 2, 2.6f), Vector3f(2, 2, 2.6f), Vector3f(2, -2, 2.6f)},
      1);
  s.mesh.region_names = {"floor", "ceiling"};
  s.materials[1].name = "ceiling";
  s.materials[1].brdf = recon::BrdfModel::kLambert;
  s.materials[1].rho_d = Vector3d::Constant(0.8);
  return s;
}

TEST(LightSourceExtentTest, FindsTheSphereFromTheLightItHides) {
  const recon::Scene model = CeilingScene(0);
  const recon::Scene truth = CeilingScene(0.25);
  const Json declared = Json{{"lights", {{"lamp", {{"type", "point"}}}}}};
  const std::vector<PixelRecord> records =
      FloorGridRecords(model, truth, Vector3d(0, -1.9, 2.3), 40, 256, 256);
  const ResidualFitter f(records, std::vector<int>(records.size(), 0), 1, false, 8);
  const CandidateResult c = LightSourceExtent({model, declared, false}, f, 0);
  ASSERT_TRUE(c.valid) << c.note;
  std::printf("hidden: radius %.3f, amplitude %.2f, gain %.3f, z %.1f\n",
              c.params["radius"].get<double>(), c.params["amplitude"].get<double>(), c.Gain(), c.z);
  // Measured: radius 0.246, amplitude 1.01, held-out gain 0.27 (the rest is both renders' path
  // noise at 256 paths), z 5.2. The ceiling's own bounced light, which the sphere also hides, is
  // left out of the prediction: a radius read somewhat large would be its sign.
  EXPECT_NEAR(c.params["radius"].get<double>(), 0.25, 0.04) << c.evidence;
  EXPECT_NEAR(c.params["amplitude"].get<double>(), 1.0, 0.2) << c.evidence;
  EXPECT_GT(c.Gain(), 0.15) << c.evidence;
  EXPECT_GT(c.z, 3) << c.evidence;
  EXPECT_NE(c.evidence.find("0 samples changed"), std::string::npos) << c.evidence;  // no edge
}

// Write replaces the light's entry by a sphere at the params' centre with the fitted radius and
// the radiance that keeps its intensity: radiance·π·r² equals the params' intensity in every
// channel. The other lights and the lightings are left as they were.
TEST(LightSourceExtentTest, WriteMakesASphereOfTheSameIntensity) {
  CandidateResult c;
  c.effect = "light_source_extent";
  const double radius = 0.2;
  c.params = {{"light", "lamp"},   {"radius", radius},          {"declared_radius", 0.0},
              {"amplitude", 0.97}, {"center", {0.3, 0.2, 2.0}}, {"intensity", {20.0, 10.0, 5.0}}};
  Json doc = {
      {"lights",
       {{"lamp", {{"type", "point"}, {"position", {0.3, 0.2, 2.0}}, {"intensity", {20, 10, 5}}}},
        {"sun", {{"type", "directional"}, {"direction", {0, 0, -1}}, {"irradiance", {1, 1, 1}}}}}},
      {"lightings", {{"L0", {"lamp", "sun"}}}}};
  Json expected = doc;
  const double area = render::kPi * radius * radius;
  expected["lights"]["lamp"] = {{"type", "sphere"},
                                {"center", {0.3, 0.2, 2.0}},
                                {"radius", radius},
                                {"radiance", {20.0 / area, 10.0 / area, 5.0 / area}}};
  test::WriteCandidate(c, &doc);
  EXPECT_EQ(doc, expected) << doc.dump();
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(doc["lights"]["lamp"]["radiance"][k].get<double>() * area,
                c.params["intensity"][k].get<double>(), 1e-12)
        << k;
  }
}

}  // namespace
}  // namespace igi::diagnose
