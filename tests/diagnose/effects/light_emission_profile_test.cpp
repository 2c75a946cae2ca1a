// light_emission_profile (solver/diagnose/effects/light_emission_profile.cpp) on synthetic records
// with known truth: a point lamp that truly is a cos² spot pointing down, seen on a floor and a
// wall, in photos that also hide a camera response (a power 0.8 of the pixel value). The
// candidate searches the profile's axis and power with the response as a nuisance, so the
// response does not bend them. And its Write: the light becomes a spot with the fitted profile.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "solver/diagnose/candidates.h"
#include "solver/diagnose/effects/effects.h"
#include "solver/diagnose/residual_fit.h"
#include "solver/render/sampling.h"
#include "tests/diagnose/one_light_record.h"
#include "tests/diagnose/room_records.h"

namespace igi::diagnose {
namespace {

using Eigen::Vector3d;
using Eigen::Vector3f;
using namespace test::room;

// The emission-profile candidate fitted to RoomRecords(power, exponent, seed, peak), its axis and
// power searched on every `stride`-th record (1: on all of them).
CandidateResult FitProfile(double power, double exponent, uint64_t seed, int stride = 1,
                           double peak = 1.0) {
  const recon::Scene model = RoomModelWithPhotos();
  const Json declared = {{"lights", {{"lamp", {{"type", "point"}}}}}};
  const std::vector<PixelRecord> records = RoomRecords(power, exponent, seed, peak);
  std::vector<int> cells(records.size());
  for (size_t i = 0; i < records.size(); ++i) cells[i] = records[i].region;
  const ResidualFitter f(records, cells, 2, false, 8);
  if (stride == 1) return EmissionProfile({model, declared, false}, f, 0);
  const RecordSubset search(model, records, 0.05, false, 8, stride);
  return EmissionProfile({model, declared, false}, f, 0, &search);
}

// The emission-profile candidate of light 0 fitted to `records` (one cell per region; the albedo
// nuisance on when `solved`), and the angle of its axis from −z in degrees.
CandidateResult ProfileOn(const recon::Scene& model, const Json& declared,
                          const std::vector<PixelRecord>& records, bool solved) {
  std::vector<int> cells(records.size());
  for (size_t i = 0; i < records.size(); ++i) cells[i] = records[i].region;
  const ResidualFitter f(records, cells, 2, solved, 8);
  return EmissionProfile({model, declared, solved}, f, 0);
}
double DegreesFromDown(const CandidateResult& c) {
  const std::vector<double> axis = c.params["direction"].get<std::vector<double>>();
  return std::acos(std::min(1.0, -axis[2])) * 180 / render::kPi;
}

// Measured (seed 1): axis 0.3° from −z, power 2.12. Searched without the response nuisance the
// same records gave axis 1.8°, power 1.60 (the response's power of the pixel value reads as a
// weaker profile), which fails here. Allowed: 3° and 15 %.
TEST(EmissionProfileTest, AHiddenResponseDoesNotBendTheProfile) {
  const CandidateResult c = FitProfile(2.0, 0.8, 1);
  ASSERT_TRUE(c.valid) << c.note;
  const std::vector<double> axis = c.params["direction"].get<std::vector<double>>();
  EXPECT_GT(-axis[2], std::cos(3 * render::kPi / 180)) << c.params.dump();
  EXPECT_NEAR(c.params["cos_power"].get<double>(), 2.0, 0.3) << c.params.dump();
  EXPECT_GT(c.Gain(), 0.5);
}

// With the materials given, the spot's peak intensity is fitted with its profile: a lamp that
// sends 2·cos θ of its declared intensity about straight down (a reflector: more along the axis,
// none above) is a spot of twice the intensity, cos¹ (held at the declared peak, the power of
// the RADIANCE room's Cycles capture ran to 0.03). Measured: peak 2.00, power 1.00.
TEST(EmissionProfileTest, ThePeakIntensityIsFittedWithTheMaterialsGiven) {
  const CandidateResult c = FitProfile(1.0, 1.0, 3, 1, 2.0);
  ASSERT_TRUE(c.valid) << c.note;
  std::printf("peak and profile: %s\n", c.params.dump().c_str());
  EXPECT_NEAR(c.params["peak_factor"].get<double>(), 2.0, 0.1) << c.params.dump();
  EXPECT_NEAR(c.params["cos_power"].get<double>(), 1.0, 0.15) << c.params.dump();
  EXPECT_NEAR(c.params["intensity"][0].get<double>(), 2 * kIntensity, 0.1 * 2 * kIntensity);
  EXPECT_GT(c.Gain(), 0.9);
  EXPECT_EQ(c.num_params, 4);
}

// A light's bounced light changes in its own photos only: lamp2's profile cannot take a scale of
// the lamp's photos through its free scale per region. The lamp's 4 photos record 0.6x the model
// (the lamp dimmer than declared), lamp2's 4 agree with it; lamp2's profile candidate explains
// almost nothing (with the region scales over every photo it predicted 69 % on the RADIANCE
// room's Cycles capture and was tried first).
TEST(EmissionProfileTest, AnotherLightingsScaleIsNotThisLightsProfile) {
  const recon::Scene model = TwoLightingRoomModel();
  const std::vector<PixelRecord> records =
      TwoLightingRoomRecords(7, [](int photo) { return photo < 4 ? 0.6 : 1.0; });
  std::vector<int> cells(records.size());
  for (size_t i = 0; i < records.size(); ++i) cells[i] = records[i].region;
  const ResidualFitter f(records, cells, 2, false, 8);
  const Json declared = {
      {"lights", {{"lamp", {{"type", "point"}}}, {"lamp2", {{"type", "point"}}}}}};
  const CandidateResult c = EmissionProfile({model, declared, false}, f, 1);
  if (c.valid) {
    std::printf("lamp2's profile: predicted held-out gain %.4f, %s\n", c.Gain(),
                c.params.dump().c_str());
    EXPECT_LT(c.Gain(), 0.05);
  }
}

// With the materials given, the candidate's predicted held-out residual is the one its model
// renders: the photos record the lamp's direct light 1.3x as bright and its bounced light as
// modelled (as a renderer with fewer bounces would), which a spot of peak 1.3x about straight down
// mimics only in part, since the light it bounces scales as its flux (half the isotropic lamp's:
// nothing above the horizon). The residual of the found spot rendered so (peak·D·cos^n + the
// bounce term times peak / (2(n + 1))) on the held-out records is the predicted one. Credited
// with a free scale of the bounced light per region, the prediction was that of a better fit
// than the spot renders.
TEST(EmissionProfileTest, ThePredictedResidualIsTheOneTheProfileRenders) {
  const recon::Scene model = RoomModelWithPhotos();
  std::mt19937_64 rng(5);
  std::normal_distribution<double> g(0, 1);
  std::vector<PixelRecord> records;
  std::vector<double> direct;
  for (int i = 0; i < 8000; ++i) {
    RoomPoint q;
    PixelRecord r = RoomRecordAt(i, rng, &q);
    const double d = kRho / render::kPi * q.e;
    for (int c = 0; c < 3; ++c) {
      r.sim[c] = float(d + kBounce);
      r.recorded[c] = float((1.3 * d + kBounce) * (1 + 0.01 * g(rng)));
    }
    records.push_back(r);
    direct.push_back(d);
  }
  std::vector<int> cells(records.size());
  for (size_t i = 0; i < records.size(); ++i) cells[i] = records[i].region;
  const ResidualFitter f(records, cells, 2, false, 8);
  const Json declared = {{"lights", {{"lamp", {{"type", "point"}}}}}};
  const CandidateResult c = EmissionProfile({model, declared, false}, f, 0);
  ASSERT_TRUE(c.valid) << c.note;
  const std::vector<double> axis = c.params["direction"].get<std::vector<double>>();
  const Vector3d a(axis[0], axis[1], axis[2]);
  const double n = c.params["cos_power"].get<double>(), peak = c.params["peak_factor"];
  double rendered = 0;
  for (size_t i = 0; i < records.size(); ++i) {
    const PixelRecord& r = records[i];
    if (!r.held_out || r.outlier) continue;
    const double cos_axis = std::max(0.0, -r.lights[0].wi.cast<double>().dot(a));
    const double v = peak * direct[i] * std::pow(cos_axis, n) + kBounce * peak / (2 * (n + 1));
    for (int ch = 0; ch < 3; ++ch) rendered += std::pow(r.recorded[ch] - v, 2);
  }
  std::printf("spot: %s; held-out residual² before %.5f, predicted %.5f, rendered %.5f\n",
              c.params.dump().c_str(), c.held_before, c.held_after, rendered);
  EXPECT_NEAR(c.held_after, rendered, 0.02 * c.held_before);
}

// Without a response the profile is found as well (measured: axis 0.3°, power 2.01).
TEST(EmissionProfileTest, FindsTheProfileAlone) {
  const CandidateResult c = FitProfile(2.0, 1.0, 2);
  ASSERT_TRUE(c.valid) << c.note;
  const std::vector<double> axis = c.params["direction"].get<std::vector<double>>();
  EXPECT_GT(-axis[2], std::cos(3 * render::kPi / 180)) << c.params.dump();
  EXPECT_NEAR(c.params["cos_power"].get<double>(), 2.0, 0.3) << c.params.dump();
  EXPECT_GT(c.Gain(), 0.9);
}

// The search on a quarter of the records (as igi-diagnose does on large captures) finds the same
// profile, and the candidate's scores are those of the fit on every record: searched on a
// subsample whose scores were kept, the held-out error before the change would be a quarter.
TEST(EmissionProfileTest, SearchOnASubsampleScoresOnEveryRecord) {
  const CandidateResult all = FitProfile(2.0, 0.8, 1);
  const CandidateResult sub = FitProfile(2.0, 0.8, 1, 4);
  ASSERT_TRUE(all.valid) << all.note;
  ASSERT_TRUE(sub.valid) << sub.note;
  const std::vector<double> axis = sub.params["direction"].get<std::vector<double>>();
  EXPECT_GT(-axis[2], std::cos(3 * render::kPi / 180)) << sub.params.dump();
  EXPECT_NEAR(sub.params["cos_power"].get<double>(), 2.0, 0.3) << sub.params.dump();
  EXPECT_DOUBLE_EQ(sub.held_before, all.held_before);
  EXPECT_DOUBLE_EQ(sub.train_before, all.train_before);
  EXPECT_NEAR(sub.Gain(), all.Gain(), 0.02);
}

// With the materials solved and a second lighting photographed, the albedos (the fit's nuisance,
// a free scale per cell) are shared by both lightings. The lamp truly is a cos² spot straight
// down: its direct light falls off with the angle, and the light it sends after a bounce, most
// of what the wall shows, drops in its own photos by a share that differs between surfaces
// (the wall loses more than the floor). lamp2's photos agree with the model. The profile's axis
// and power are searched on the lamp's photos alone, with their own albedo nuisance, and scored
// on every record. Measured: axis 0.3° from −z, power 2.25; searched on every record with the
// shared albedos the power comes out 2.53, which fails here. (A mild form of
// the suite's seed-107 capture, where the search on every record gave cos^14 about an axis
// pointing up, and on the lamp's photos alone cos^1.43 about one 6.8° from the true one.)
TEST(EmissionProfileTest, SearchedOnItsOwnPhotosWhenAnotherLightingSharesTheAlbedos) {
  recon::Scene model = RoomModel();
  recon::Light lamp2 = model.lights[0];
  lamp2.name = "lamp2";
  const Vector3d at2(-1, 1, 2.2);
  lamp2.position = at2;
  model.lights.push_back(lamp2);
  model.lightings.push_back(recon::Lighting{"L1", {1}});
  for (int j = 0; j < 8; ++j) {
    recon::Photo ph;
    ph.lighting = j < 4 ? 0 : 1;
    model.photos.push_back(ph);
  }
  const Json declared = {
      {"lights", {{"lamp", {{"type", "point"}}}, {"lamp2", {{"type", "point"}}}}}};
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0, 1);
  std::normal_distribution<double> g(0, 1);
  std::vector<PixelRecord> records;
  const double bounce = 0.02;  // the model's bounced light, the same everywhere
  for (int i = 0; i < 16000; ++i) {
    const bool wall = (i / 2) % 2 == 1;
    const int lighting = i % 2;
    const RoomPoint q = DrawRoomPoint(rng, wall, lighting == 0 ? kLamp : at2);
    const Vector3d &p = q.p, &n = q.n, &wi = q.wi;
    const double d = q.d, e = q.e;
    const double direct = kRho / render::kPi * e;
    const int photo = 4 * lighting + (i / 4) % 4;
    PixelRecord r = test::OneLightRecord(photo, (i / 16) % 160, (i / 2560) % 120, wall ? 1 : 0, p,
                                         n, n, Vector3f::Constant(float(kRho)), wi, e, d);
    r.lights[0].light = lighting;
    const double truth =
        lighting == 0 ? direct * std::pow(std::max(0.0, wi.z()), 2.0) + bounce * (wall ? 0.35 : 0.7)
                      : direct + bounce;
    for (int c = 0; c < 3; ++c) {
      r.sim[c] = float(direct + bounce);
      r.recorded[c] = float(truth * (1 + 0.01 * g(rng)));
    }
    records.push_back(r);
  }
  const CandidateResult c = ProfileOn(model, declared, records, true);
  ASSERT_TRUE(c.valid) << c.note;
  std::printf("axis %.1f deg from -z, power %.2f, predicted gain %.3f, z %.1f\n",
              DegreesFromDown(c), c.params["cos_power"].get<double>(), c.Gain(), c.z);
  EXPECT_LT(DegreesFromDown(c), 3) << c.params.dump();
  EXPECT_NEAR(c.params["cos_power"].get<double>(), 2.0, 0.3) << c.params.dump();
  EXPECT_GT(c.Gain(), 0.3);
}

// A profile kept in an earlier step is refitted from the one in the model: the lamp is modelled
// as a cos^1.4 spot about an axis 6° off (what a first round found on the suite's seed-107
// capture: cos^1.43, 6.8° off); the photos show cos² straight down. The records' light carries
// the model's profile, which the new one replaces. Materials given. Allowed: 1° and 0.15.
TEST(EmissionProfileTest, AKeptProfileIsRefittedFromTheModelsOne) {
  recon::Scene model = RoomModel();
  recon::Light& lamp = model.lights[0];
  lamp.type = recon::LightType::kSpot;
  const double tilt = 6 * render::kPi / 180;
  lamp.direction = Vector3d(std::sin(tilt), 0, -std::cos(tilt));
  lamp.profile.kind = recon::SpotProfile::Kind::kCosPower;
  lamp.profile.cos_power = 1.4;
  const Json declared = {{"lights", {{"lamp", {{"type", "spot"}}}}}};
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0, 1);
  std::normal_distribution<double> g(0, 1);
  std::vector<PixelRecord> records;
  for (int i = 0; i < 8000; ++i) {
    const bool wall = i % 2 == 1;
    const RoomPoint q = DrawRoomPoint(rng, wall, kLamp);
    const Vector3d &p = q.p, &n = q.n, &wi = q.wi;
    const double d = q.d, e = q.e;
    const double now = std::pow(std::max(0.0, (-wi).dot(lamp.direction)), 1.4);
    PixelRecord r = test::OneLightRecord(i % 4, (i / 4) % 160, (i / 640) % 120, wall ? 1 : 0, p, n,
                                         n, Vector3f::Constant(float(kRho)), wi, e * now, d);
    const double truth = kRho / render::kPi * e * std::pow(std::max(0.0, wi.z()), 2.0) + kBounce;
    for (int c = 0; c < 3; ++c) {
      r.sim[c] = float(kRho / render::kPi * e * now + kBounce);
      r.recorded[c] = float(truth * (1 + 0.01 * g(rng)));
    }
    records.push_back(r);
  }
  const CandidateResult c = ProfileOn(model, declared, records, false);
  ASSERT_TRUE(c.valid) << c.note;
  std::printf("refitted: axis %.2f deg from -z, power %.2f, gain %.3f; key %s\n",
              DegreesFromDown(c), c.params["cos_power"].get<double>(), c.Gain(), c.Key().c_str());
  EXPECT_LT(DegreesFromDown(c), 1) << c.params.dump();
  EXPECT_NEAR(c.params["cos_power"].get<double>(), 2.0, 0.15) << c.params.dump();
  ASSERT_TRUE(c.params.contains("refined_from")) << c.params.dump();
  EXPECT_NEAR(c.params["refined_from"]["cos_power"].get<double>(), 1.4, 1e-9);
  EXPECT_EQ(c.Key(), "light_emission_profile:lamp:refit");
  EXPECT_GT(c.Gain(), 0.5);
}

// Write replaces the light's whole entry (a sphere here: its centre, radius and radiance go) by a
// spot at the params' position, with their intensity, axis and cos^n profile; the other light
// and the rest of the document are left as they were.
TEST(EmissionProfileTest, WriteMakesTheLightASpotWithTheFittedProfile) {
  CandidateResult c;
  c.effect = "light_emission_profile";
  c.params = {{"light", "lamp"},
              {"direction", {0.1, 0.0, -0.995}},
              {"cos_power", 2.5},
              {"position", {0.0, 0.0, 2.5}},
              {"intensity", {8.0, 7.0, 6.0}}};
  Json doc = {{"lights",
               {{"lamp",
                 {{"type", "sphere"},
                  {"center", {0.0, 0.0, 2.5}},
                  {"radius", 0.05},
                  {"radiance", {1000.0, 900.0, 800.0}}}},
                {"lamp2", {{"type", "point"}, {"position", {1, 1, 2}}, {"intensity", {3, 3, 3}}}}}},
              {"lightings", {{"L0", {"lamp", "lamp2"}}}}};
  Json expected = doc;
  expected["lights"]["lamp"] = {{"type", "spot"},
                                {"position", {0.0, 0.0, 2.5}},
                                {"direction", {0.1, 0.0, -0.995}},
                                {"intensity", {8.0, 7.0, 6.0}},
                                {"profile", {{"cos_power", 2.5}}}};
  test::WriteCandidate(c, &doc);
  EXPECT_EQ(doc, expected) << doc.dump();
}

}  // namespace
}  // namespace igi::diagnose
