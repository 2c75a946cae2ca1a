// The light_emission_profile candidate (solver/diagnose/candidates.cpp) on synthetic records with
// known truth: a point lamp that truly is a cos² spot pointing down, seen on a floor and a wall,
// in photos that also hide a camera response (a power 0.8 of the pixel value). The candidate
// searches the profile's axis and power with the response as a nuisance, so the response does
// not bend them.
#include "solver/diagnose/candidates.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "solver/brdf.h"
#include "solver/diagnose/residual_fit.h"
#include "solver/photo_model.h"
#include "solver/sampling.h"
#include "tests/diagnose/one_light_record.h"

namespace igi {
namespace {

using Eigen::Vector3d;
using Eigen::Vector3f;

constexpr double kRho = 0.5;        // every surface's ρd (Lambert)
constexpr double kIntensity = 8.0;  // the lamp's peak intensity, W/sr
constexpr double kBounce = 0.03;    // light after a bounce (the same in the model and photos)
const Vector3d kLamp(0, 0, 2.5);

Scene RoomModel() {
  Scene s;
  for (const char* name : {"floor", "wall"}) {
    Material m;
    m.name = name;
    m.brdf = BrdfModel::kLambert;
    m.rho_d = Vector3d::Constant(kRho);
    s.materials.push_back(m);
  }
  Light lamp;
  lamp.name = "lamp";
  lamp.type = LightType::kPoint;
  lamp.position = kLamp;
  lamp.intensity = Vector3d::Constant(kIntensity);
  s.lights.push_back(lamp);
  s.lightings.push_back(Lighting{"L0", {0}});
  return s;
}

// A point on the floor (z = 0, |x|, |y| < 3) or a wall (x = 3, |y| < 3, 0 < z < 2.5), seen along
// its normal, lit by a point light of kIntensity at `light`: the unit direction toward the
// light, its distance and the irradiance.
struct RoomPoint {
  Vector3d p, n, wi;
  double d = 0, e = 0;
};
RoomPoint DrawRoomPoint(std::mt19937_64& rng, bool wall, const Vector3d& light) {
  std::uniform_real_distribution<double> u(0, 1);
  RoomPoint q;
  q.p = wall ? Vector3d(3, 6 * u(rng) - 3, 2.5 * u(rng))
             : Vector3d(6 * u(rng) - 3, 6 * u(rng) - 3, 0);
  q.n = wall ? Vector3d(-1, 0, 0) : Vector3d(0, 0, 1);
  q.d = (light - q.p).norm();
  q.wi = (light - q.p) / q.d;
  q.e = kIntensity * std::max(0.0, q.wi.dot(q.n)) / (q.d * q.d);
  return q;
}

// Records on the floor (z = 0, |x|, |y| < 3) and a wall (x = 3, |y| < 3, 0 < z < 2.5), the view
// straight along the normal. The photo: the lamp's direct light times cos^power of the angle from
// −z, plus the bounce term, through the response v = (u/ref)^exponent·ref (ref 0.05), 1 % noise.
std::vector<PixelRecord> RoomRecords(double power, double exponent, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::normal_distribution<double> g(0, 1);
  const double ref = 0.05;
  std::vector<PixelRecord> out;
  for (int i = 0; i < 8000; ++i) {
    const bool wall = i % 2 == 1;
    const RoomPoint q = DrawRoomPoint(rng, wall, kLamp);
    const Vector3d &p = q.p, &n = q.n, &wi = q.wi;
    const double d = q.d, e = q.e;
    const double direct = kRho / kPi * e;
    const double cos_axis = wi.z();  // cos of the angle from −z of the direction lamp → point
    PixelRecord r = test::OneLightRecord(i % 4, (i / 4) % 160, (i / 640) % 120, wall ? 1 : 0, p, n,
                                         n, Vector3f::Constant(float(kRho)), wi, e, d);
    const double truth = direct * std::pow(std::max(0.0, cos_axis), power) + kBounce;
    const double recorded = ref * std::pow(truth / ref, exponent);
    for (int c = 0; c < 3; ++c) {
      r.sim[c] = float(direct + kBounce);
      r.recorded[c] = float(recorded * (1 + 0.01 * g(rng)));
    }
    out.push_back(r);
  }
  return out;
}

// The emission-profile candidate fitted to RoomRecords(power, exponent, seed), its axis and power
// searched on every `stride`-th record (1: on all of them).
CandidateResult FitProfile(double power, double exponent, uint64_t seed, int stride = 1) {
  const Scene model = RoomModel();
  const Json declared = {{"lights", {{"lamp", {{"type", "point"}}}}}};
  const std::vector<PixelRecord> records = RoomRecords(power, exponent, seed);
  std::vector<int> cells(records.size());
  for (size_t i = 0; i < records.size(); ++i) cells[i] = records[i].region;
  const ResidualFitter f(records, cells, 2, false, 8);
  if (stride == 1) return EmissionProfile({model, declared, false}, f, 0);
  const RecordSubset search(model, records, 0.05, false, 8, stride);
  return EmissionProfile({model, declared, false}, f, 0, &search);
}

// The emission-profile candidate of light 0 fitted to `records` (one cell per region; the albedo
// nuisance on when `solved`), and the angle of its axis from −z in degrees.
CandidateResult ProfileOn(const Scene& model, const Json& declared,
                          const std::vector<PixelRecord>& records, bool solved) {
  std::vector<int> cells(records.size());
  for (size_t i = 0; i < records.size(); ++i) cells[i] = records[i].region;
  const ResidualFitter f(records, cells, 2, solved, 8);
  return EmissionProfile({model, declared, solved}, f, 0);
}
double DegreesFromDown(const CandidateResult& c) {
  const std::vector<double> axis = c.params["direction"].get<std::vector<double>>();
  return std::acos(std::min(1.0, -axis[2])) * 180 / kPi;
}

// Measured (seed 1): axis 0.3° from −z, power 2.12. Searched without the response nuisance the
// same records gave axis 1.8°, power 1.60 (the response's power of the pixel value reads as a
// weaker profile), which fails here. Allowed: 3° and 15 %.
TEST(EmissionProfileTest, AHiddenResponseDoesNotBendTheProfile) {
  const CandidateResult c = FitProfile(2.0, 0.8, 1);
  ASSERT_TRUE(c.valid) << c.note;
  const std::vector<double> axis = c.params["direction"].get<std::vector<double>>();
  EXPECT_GT(-axis[2], std::cos(3 * kPi / 180)) << c.params.dump();
  EXPECT_NEAR(c.params["cos_power"].get<double>(), 2.0, 0.3) << c.params.dump();
  EXPECT_GT(c.Gain(), 0.5);
}

// Without a response the profile is found as well (measured: axis 0.3°, power 2.01).
TEST(EmissionProfileTest, FindsTheProfileAlone) {
  const CandidateResult c = FitProfile(2.0, 1.0, 2);
  ASSERT_TRUE(c.valid) << c.note;
  const std::vector<double> axis = c.params["direction"].get<std::vector<double>>();
  EXPECT_GT(-axis[2], std::cos(3 * kPi / 180)) << c.params.dump();
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
  EXPECT_GT(-axis[2], std::cos(3 * kPi / 180)) << sub.params.dump();
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
// shared albedos (before session 20) the power came out 2.53, which fails here. (A mild form of
// the suite's seed-107 capture, where the search on every record gave cos^14 about an axis
// pointing up, and on the lamp's photos alone cos^1.43 about one 6.8° from the true one.)
TEST(EmissionProfileTest, SearchedOnItsOwnPhotosWhenAnotherLightingSharesTheAlbedos) {
  Scene model = RoomModel();
  Light lamp2 = model.lights[0];
  lamp2.name = "lamp2";
  const Vector3d at2(-1, 1, 2.2);
  lamp2.position = at2;
  model.lights.push_back(lamp2);
  model.lightings.push_back(Lighting{"L1", {1}});
  for (int j = 0; j < 8; ++j) {
    Photo ph;
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
    const double direct = kRho / kPi * e;
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
// as a cos^1.4 spot about an axis 6° off (what a first round found, session 20's seed-107
// capture: cos^1.43, 6.8° off); the photos show cos² straight down. The records' light carries
// the model's profile, which the new one replaces. Materials given. Allowed: 1° and 0.15.
TEST(EmissionProfileTest, AKeptProfileIsRefittedFromTheModelsOne) {
  Scene model = RoomModel();
  Light& lamp = model.lights[0];
  lamp.type = LightType::kSpot;
  const double tilt = 6 * kPi / 180;
  lamp.direction = Vector3d(std::sin(tilt), 0, -std::cos(tilt));
  lamp.profile.kind = SpotProfile::Kind::kCosPower;
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
    const double truth = kRho / kPi * e * std::pow(std::max(0.0, wi.z()), 2.0) + kBounce;
    for (int c = 0; c < 3; ++c) {
      r.sim[c] = float(kRho / kPi * e * now + kBounce);
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

// ---------------------------------------------------------------- exposure_scale
// Materials solved, photos under two lightings (the albedos shared by both): 4 photos under the
// lamp, 4 under lamp2, on the floor and the wall. The photos under lamp2 record 0.6x the model
// (lamp2 is dimmer than declared: a scale common to its lighting, another effect's), and photo
// `off` (under lamp2; -1: none) records a further `off_scale`.
CandidateResult ExposureWithTwoLightings(int off, double off_scale) {
  Scene model = RoomModel();
  Light lamp2 = model.lights[0];
  lamp2.name = "lamp2";
  lamp2.position = Vector3d(-1, 1, 2.2);
  model.lights.push_back(lamp2);
  model.lightings.push_back(Lighting{"L1", {1}});
  for (int j = 0; j < 8; ++j) {
    Photo ph;
    ph.file = "cam" + std::to_string(j % 4) + "_L" + std::to_string(j / 4) + ".exr";
    ph.lighting = j / 4;
    model.photos.push_back(ph);
  }
  const Json declared = {
      {"lights", {{"lamp", {{"type", "point"}}}, {"lamp2", {{"type", "point"}}}}}};
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0, 1);
  std::normal_distribution<double> g(0, 1);
  std::vector<PixelRecord> records;
  for (int i = 0; i < 16000; ++i) {
    const bool wall = (i / 8) % 2 == 1;
    const int photo = i % 8;
    const RoomPoint q = DrawRoomPoint(rng, wall, photo < 4 ? kLamp : lamp2.position);
    const Vector3d &p = q.p, &n = q.n, &wi = q.wi;
    const double d = q.d, e = q.e;
    PixelRecord r = test::OneLightRecord(photo, (i / 16) % 160, (i / 2560) % 120, wall ? 1 : 0, p,
                                         n, n, Vector3f::Constant(float(kRho)), wi, e, d);
    r.lights[0].light = photo < 4 ? 0 : 1;
    const double sim = kRho / kPi * e + kBounce;
    const double scale = (photo < 4 ? 1.0 : 0.6) * (photo == off ? off_scale : 1.0);
    for (int c = 0; c < 3; ++c) {
      r.sim[c] = float(sim);
      r.recorded[c] = float(sim * scale * (1 + 0.01 * g(rng)));
    }
    records.push_back(r);
  }
  std::vector<std::string> excluded;
  for (const char* e : {"vignetting", "camera_response", "ambient_light"}) excluded.push_back(e);
  for (const char* l : {"lamp", "lamp2"}) {
    for (const char* e : {"light_emission_profile:", "light_intensity:", "light_source_extent:"}) {
      excluded.push_back(std::string(e) + l);
    }
  }
  for (const char* r : {"floor", "wall"}) {
    for (const char* e :
         {"specular_lobe_shape:", "fresnel:", "anisotropic_reflection:", "specular_reflection:"}) {
      excluded.push_back(std::string(e) + r);
    }
  }
  const std::vector<CandidateResult> cands =
      EvaluateCandidates({model, declared, true}, records, excluded);
  for (const CandidateResult& c : cands) {
    if (c.effect == "exposure_scale") return c;
  }
  ADD_FAILURE() << "no exposure_scale candidate among " << cands.size();
  return {};
}

// A scale common to one lighting's photos is not credited to per-photo scales (it is the
// lighting's lights': light_intensity, light_emission_profile): fitted free, the 8 photos'
// scales (0.6 under lamp2, relative to the median photo) explained nearly all the residual, and
// the suite's seed-107 emission-profile capture applied them in the profile's place.
TEST(ExposureScaleTest, ALightingsCommonScaleIsNotThePhotos) {
  const CandidateResult c = ExposureWithTwoLightings(-1, 1.0);
  if (c.valid) {
    std::printf("exposure_scale: predicted held-out gain %.4f, z %.1f, %s\n", c.Gain(), c.z,
                c.params.dump().c_str());
    EXPECT_LT(c.Gain(), 0.02);
    for (const auto& [file, v] : c.params["scale"].items()) {
      EXPECT_NEAR(v.get<double>(), 1.0, 0.01) << file;
    }
  } else {
    EXPECT_FALSE(c.note.empty());
  }
}

// One photo off within its lighting is still found, relative to its lighting's other photos.
TEST(ExposureScaleTest, OnePhotoOffWithinItsLightingIsFound) {
  const CandidateResult c = ExposureWithTwoLightings(5, 0.8);
  ASSERT_TRUE(c.valid) << c.note;
  std::printf("exposure_scale: predicted held-out gain %.4f, z %.1f, %s\n", c.Gain(), c.z,
              c.params.dump().c_str());
  EXPECT_EQ(c.num_params, 6);  // 8 photos less one reference per lighting
  EXPECT_GT(c.Gain(), 0.2);
  for (const auto& [file, v] : c.params["scale"].items()) {
    EXPECT_NEAR(v.get<double>(), file == "cam1_L1.exr" ? 0.8 : 1.0, 0.01) << file;
  }
}

// ---------------------------------------------------------------- camera_response
// Materials solved (a free albedo per region), 4 photos under the lamp of the floor and the
// wall: the photos follow the true value through the response ref·(v/ref)^0.8 (ref 0.2), the
// wall's albedo 10 % off, 1 % photo noise. The model's value is the true value scaled per region
// to the photos' level (least squares, as the baseline's solved albedos do), rendered with
// `render_noise` relative Monte Carlo noise, its variance known to the records when
// `variance_known` (as SimulatePhotos estimates it). The camera_response candidate.
CandidateResult ResponseWithNoisyRenders(double render_noise, bool variance_known) {
  Scene model = RoomModel();
  for (int j = 0; j < 4; ++j) {
    Photo ph;
    ph.file = "cam" + std::to_string(j) + "_L0.exr";
    model.photos.push_back(ph);
  }
  const Json declared = {{"lights", {{"lamp", {{"type", "point"}}}}}};
  std::mt19937_64 rng(11);
  std::normal_distribution<double> g(0, 1);
  const double ref = 0.2;
  std::vector<PixelRecord> records;
  for (int i = 0; i < 16000; ++i) {
    const bool wall = i % 2 == 1;
    const RoomPoint q = DrawRoomPoint(rng, wall, kLamp);
    PixelRecord r = test::OneLightRecord(i % 4, (i / 4) % 160, (i / 640) % 120, wall ? 1 : 0, q.p,
                                         q.n, q.n, Vector3f::Constant(float(kRho)), q.wi, q.e, q.d);
    const double truth = kRho / kPi * q.e + kBounce;
    const double recorded = ref * std::pow(truth * (wall ? 1.1 : 1.0) / ref, 0.8);
    for (int c = 0; c < 3; ++c) {
      r.sim[c] = float(truth);
      r.recorded[c] = float(recorded * (1 + 0.01 * g(rng)));
    }
    records.push_back(r);
  }
  // The baseline's albedos: per region, the model's level is the photos' (least squares).
  double sp[2] = {0, 0}, ss[2] = {0, 0};
  for (const PixelRecord& r : records) {
    sp[r.region] += double(r.recorded[0]) * r.sim[0];
    ss[r.region] += double(r.sim[0]) * r.sim[0];
  }
  for (PixelRecord& r : records) {
    for (int c = 0; c < 3; ++c) {
      const double v = r.sim[c] * sp[r.region] / ss[r.region];
      r.sim[c] = float(v * (1 + render_noise * g(rng)));
      r.sim_var[c] = variance_known ? float(std::pow(render_noise * v, 2)) : 0.0f;
    }
  }
  std::vector<int> cells(records.size());
  for (size_t i = 0; i < records.size(); ++i) cells[i] = records[i].region;
  const ResidualFitter f(records, cells, 2, true, 8);
  return Response({model, declared, true}, f);
}

// With noise-free renders the exponent is the photos' (measured 0.791; the linearised exponent
// 1 + c (e − 1) of a fit whose albedo nuisance scales the model's value, not the curve). With
// 10 % render noise a plain fit reads the noise in the model's value as a steeper fall of
// photo/model with the value (regression dilution of the photo's slope on the noisy model value):
// measured 0.718, 0.523 at 20 %. Corrected by the renders' variance: 0.794 (0.763 at 20 %, where
// the second-order expansion begins to fall short).
TEST(ResponseTest, TheRendersNoiseDoesNotBendTheCurve) {
  const CandidateResult exact = ResponseWithNoisyRenders(0.0, true);
  const CandidateResult plain = ResponseWithNoisyRenders(0.1, false);
  const CandidateResult corrected = ResponseWithNoisyRenders(0.1, true);
  for (const CandidateResult* c : {&exact, &plain, &corrected}) {
    ASSERT_TRUE(c->valid) << c->note;
    std::printf("camera_response: exponent %.4f, predicted held-out gain %.4f, z %.1f\n",
                c->params["exponent"].get<double>(), c->Gain(), c->z);
  }
  const double e_exact = exact.params["exponent"].get<double>();
  EXPECT_NEAR(e_exact, 0.8, 0.015);
  EXPECT_NEAR(corrected.params["exponent"].get<double>(), e_exact, 0.01);
  EXPECT_LT(plain.params["exponent"].get<double>(), e_exact - 0.05);  // what it corrects
  EXPECT_GT(corrected.z, 10);
}

// RecordSubset: one record in `stride` with no pattern, or one region's records.
TEST(RecordSubsetTest, AQuarterOrOneRegion) {
  const Scene model = RoomModel();
  const std::vector<PixelRecord> records = RoomRecords(2.0, 1.0, 3);
  const RecordSubset every(model, records, 0.05, true, 8, 1);
  EXPECT_EQ(every.records().size(), records.size());
  // A quarter, drawn without a pattern: the records alternate floor and wall (every 4th record
  // would be the floor's alone, and the profile's power could not be told from the response).
  const RecordSubset quarter(model, records, 0.05, true, 8, 4);
  EXPECT_NEAR(double(quarter.records().size()), records.size() / 4.0, 0.05 * records.size() / 4);
  int walls_in_quarter = 0;
  for (const PixelRecord& r : quarter.records()) walls_in_quarter += r.region == 1;
  EXPECT_NEAR(walls_in_quarter, quarter.records().size() / 2.0, 0.1 * quarter.records().size());
  const RecordSubset walls(model, records, 0.05, true, 8, 1, 1);  // odd records are the wall's
  EXPECT_EQ(walls.records().size(), records.size() / 2);
  for (const PixelRecord& r : walls.records()) EXPECT_EQ(r.region, 1);
  EXPECT_EQ(SearchStride(records, 1000),
            int(std::count_if(records.begin(), records.end(),
                              [](const PixelRecord& r) { return !r.held_out && !r.outlier; }) /
                1000));
  EXPECT_EQ(SearchStride(records, 1000000), 1);
}

// The lobe candidates with the materials solved (the refit re-solves ρs and α): a glossy plate
// under a point lamp 1 m above it, seen on the mirror views of its highlight at 30° and at 70°
// from the normal, and a third of its pixels off the highlight. The photos follow the true lobe
// (Fresnel-weighted or not, α `truth_alpha`); the model is a plain Ward lobe whose ρs and α a
// solver fitted over both views (`model_rho_s`, `model_alpha`).
std::vector<PixelRecord> PlateRecords(bool fresnel_truth, double truth_alpha, double model_rho_s,
                                      double model_alpha, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::normal_distribution<double> g(0, 1);
  const Vector3d lamp(0, 0, 1), n(0, 0, 1);
  const double rho_d = 0.2, rho_s = 0.05, intensity = 5;
  auto ward = [](const Vector3d& nn, const Vector3d& wi, const Vector3d& wo, double a) {
    const double ci = nn.dot(wi), co = nn.dot(wo);
    if (!(ci > 0) || !(co > 0)) return 0.0;
    const Vector3d h = (wi + wo).normalized();
    const double ch = nn.dot(h), tan2 = (1 - ch * ch) / (ch * ch);
    return std::exp(-tan2 / (a * a)) / (4 * kPi * a * a * std::sqrt(ci * co));
  };
  std::vector<PixelRecord> out;
  for (int i = 0; i < 12000; ++i) {
    const bool grazing = i % 2 == 1;
    const double theta = (grazing ? 70.0 : 30.0) * kPi / 180;
    // A point near where the lamp's light arrives at `theta`, seen from near its mirror view.
    const double d = std::tan(theta) * (0.9 + 0.2 * u(rng));
    const double phi = 2 * kPi * u(rng);
    const Vector3d p(d * std::cos(phi), d * std::sin(phi), 0);
    const double dist = (lamp - p).norm();
    const Vector3d wi = (lamp - p) / dist;
    Vector3d wo = (2 * n.dot(wi) * n - wi);
    wo += Vector3d(0.15 * g(rng), 0.15 * g(rng), 0.0);
    if (i % 3 == 2) {  // a third of the pixels off the highlight: the plate's diffuse albedo
      const double el = (25 + 60 * u(rng)) * kPi / 180, az = 2 * kPi * u(rng);
      wo = Vector3d(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
    }
    wo.z() = std::max(0.05, wo.z());
    wo.normalize();
    const double e = intensity * n.dot(wi) / (dist * dist);
    const double c = std::min(1.0, (wi + wo).norm() / 2), f0 = 0.04;
    const double weight = fresnel_truth ? 1 + (1 / f0 - 1) * std::pow(1 - c, 5) : 1.0;
    const double truth = rho_d / kPi * e + rho_s * weight * ward(n, wi, wo, truth_alpha) * e;
    const double model = rho_d / kPi * e + model_rho_s * ward(n, wi, wo, model_alpha) * e;
    const int x = int(u(rng) * 160), y = int(u(rng) * 120);
    PixelRecord r = test::OneLightRecord(grazing ? 1 : 0, x, y, 0, p, n, wo,
                                         Vector3f::Constant(float(rho_d)), wi, e, dist);
    for (int k = 0; k < 3; ++k) {
      r.sim[k] = float(model);
      r.recorded[k] = float(truth * (1 + 0.01 * g(rng)));
    }
    out.push_back(r);
  }
  return out;
}

CandidateResult PlateCandidate(bool fresnel, const std::vector<PixelRecord>& records,
                               double model_rho_s, double model_alpha, bool solved = true) {
  Scene model;
  Material m;
  m.name = "plate";
  m.brdf = BrdfModel::kWard;
  m.rho_d = Vector3d::Constant(0.2);
  m.rho_s = Vector3d::Constant(model_rho_s);
  m.alpha = model_alpha;
  model.materials.push_back(m);
  const Json declared = Json::object();
  int num_cells = 0;
  const std::vector<int> cells = RecordCells(model, records, 0.05, &num_cells);
  const ResidualFitter f(records, cells, num_cells, solved, 8);
  return LobeChange({model, declared, solved}, f, 0, fresnel);
}

// Materials given (ρs and α as true, the truth Fresnel-weighted at index 1.5, F0 = 0.04): the
// weight's change has one shape at every index, which sets only its scale, so the index is read
// from the fitted scale, with the amplitude the refit applies (1). (Picked from a list, every
// index fitted alike and rounding chose: 1.33 or 1.5 from one build to the next.)
TEST(LobeChangeTest, FresnelIndexWithMaterialsGivenIsTheFittedScale) {
  const std::vector<PixelRecord> records = PlateRecords(true, 0.15, 0.05, 0.15, 3);
  const CandidateResult c = PlateCandidate(true, records, 0.05, 0.15, false);
  ASSERT_TRUE(c.valid) << c.note;
  EXPECT_NEAR(c.params["ior"].get<double>(), 1.5, 0.02);
  EXPECT_NEAR(c.params["amplitude"].get<double>(), 1.0, 1e-3);
  EXPECT_GT(c.Gain(), 0.5);  // the weight is all of the residual but the photos' 1 % noise
}

// Fresnel-weighted truth (ior 1.5), and the plain lobe a solver fitted over both views (ρs 30 %
// high, α as true: it splits the difference between the views): fresnel is found, with the
// index, although a plain re-fit of ρs and α also lowers the error.
TEST(LobeChangeTest, FresnelIsFoundBeyondThePlainLobesRefit) {
  const std::vector<PixelRecord> records = PlateRecords(true, 0.15, 0.065, 0.15, 1);
  const CandidateResult c = PlateCandidate(true, records, 0.065, 0.15);
  ASSERT_TRUE(c.valid) << c.note;
  std::printf("fresnel: ior %.2f, rho_s factor %.3f, alpha %.3f, gain %.3f, z %.1f\n",
              c.params["ior"].get<double>(), c.params["amplitude"].get<double>(),
              c.params["alpha_refit"].get<double>(), c.Gain(), c.z);
  EXPECT_GE(c.params["ior"].get<double>(), 1.33);
  EXPECT_LE(c.params["ior"].get<double>(), 2.0);
  EXPECT_GT(c.Gain(), 0.05);
  EXPECT_LE(c.Gain(), 1.0);
  EXPECT_NEAR(c.params["amplitude"].get<double>(), 0.05 / 0.065, 0.03);  // ρs back to the truth
}

// A plain lobe whose ρs and α are merely off (the truth plain Ward, ρs 0.05, α 0.18; the model
// ρs 0.06, α 0.15): a re-fit of the same lobe explains it, and neither fresnel nor the other lobe
// shape is credited with it (without the comparison both fit, with ρs factors 0.44-0.61).
TEST(LobeChangeTest, AMisfittedPlainLobeIsNotFresnel) {
  const std::vector<PixelRecord> records = PlateRecords(false, 0.18, 0.06, 0.15, 2);
  // Measured: both explain no more than the plain lobe re-fitted (its α 0.188).
  for (bool fresnel : {true, false}) {
    const CandidateResult c = PlateCandidate(fresnel, records, 0.06, 0.15);
    EXPECT_FALSE(c.valid) << c.effect << " " << c.params.dump() << " gain " << c.Gain();
    EXPECT_NE(c.note.find("re-fitted"), std::string::npos) << c.note;
  }
}

// A glossy ball reflects the room more than the lamps: its lobe's change shows where the room is
// bright (bench/RESULTS.md session 23: the sphere's Ward-GMD lobe, predicted from the lamp's
// reflection alone, 1-2 %; measured −59 % held out). Records of the plate lit by no lamp (one
// dim light sample far from any highlight) and by a room whose one side is bright, its light as
// PixelRecord::room samples (uniform over the hemisphere); the photos show the room reflected by
// a Ward-GMD lobe, the model by a Ward lobe of the same ρs and α: specular_lobe_shape fits it at
// amplitude 1, with the materials given. Without the room's samples there is nothing to fit.
TEST(LobeChangeTest, TheRoomsReflectionCounts) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0, 1);
  std::normal_distribution<double> g(0, 1);
  const Vector3d n(0, 0, 1);
  const double rho_d = 0.2, rho_s = 0.05, alpha = 0.15;
  auto room = [](const Vector3d& wi) { return wi.x() > 0.3 ? 4.0 : 0.2; };
  std::vector<PixelRecord> records;
  for (int i = 0; i < 6000; ++i) {
    const double el = (30 + 55 * u(rng)) * kPi / 180, az = 2 * kPi * u(rng);
    const Vector3d wo(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
    const Vector3d p(2 * u(rng) - 1, 2 * u(rng) - 1, 0);
    const Vector3d lamp_dir = Vector3d(-0.9, 0, 0.2).normalized();  // off every highlight
    PixelRecord r = test::OneLightRecord(i % 4, int(160 * u(rng)), int(120 * u(rng)), 0, p, n, wo,
                                         Vector3f::Constant(float(rho_d)), lamp_dir, 0.01, 3);
    double ward = 0, gmd = 0, diffuse = 0.01 * rho_d / kPi;
    for (int k = 0; k < 64; ++k) {
      const Vector3d wi = SampleUniformHemisphere(Eigen::Vector2d(u(rng), u(rng)));
      const double e = room(wi) * wi.z() * 2 * kPi / 64;  // L·cos/(pdf·n), pdf = 1/2π
      RecordLightSample ls;
      ls.wi = wi.cast<float>();
      ls.irradiance = Vector3f::Constant(float(e));
      r.room.push_back(ls);
      ward += rho_s * SpecularFactor<double>(BrdfModel::kWard, alpha, alpha, wo, wi) * e;
      gmd += rho_s * SpecularFactor<double>(BrdfModel::kWardGmd, alpha, alpha, wo, wi) * e;
      diffuse += rho_d / kPi * e;
    }
    for (int c = 0; c < 3; ++c) {
      r.sim[c] = float(diffuse + ward);
      r.recorded[c] = float((diffuse + gmd) * (1 + 0.005 * g(rng)));
    }
    records.push_back(r);
  }
  const CandidateResult c = PlateCandidate(false, records, rho_s, alpha, false);
  ASSERT_TRUE(c.valid) << c.note;
  EXPECT_EQ(c.params["to"], "ward_gmd");
  EXPECT_NEAR(c.params["amplitude"].get<double>(), 1.0, 0.05);
  EXPECT_GT(c.Gain(), 0.5);
  for (PixelRecord& r : records) r.room.clear();
  EXPECT_FALSE(PlateCandidate(false, records, rho_s, alpha, false).valid);
}

// The order a step refits its candidates in (RankForTrials): the seed-117 baseline's three best
// predictions (two lights' intensities at 74 %, the lamp's profile at 30 %) refit the profile
// second; otherwise best predicted first, and the weak, insignificant or invalid left out.
CandidateResult Predicted(const std::string& effect, double gain, double z,
                          const std::string& light = "") {
  CandidateResult c;
  c.effect = effect;
  c.valid = true;
  c.held_before = 1.0;
  c.held_after = 1.0 - gain;
  c.z = z;
  if (!light.empty()) c.params["light"] = light;
  return c;
}

std::vector<std::string> Order(std::vector<CandidateResult>& cands) {
  std::vector<std::string> out;
  for (const CandidateResult* c : RankForTrials(cands, 0.01, 1.5)) out.push_back(c->Key());
  return out;
}

TEST(RankForTrialsTest, TheBestOfAnotherEffectIsRefittedSecond) {
  std::vector<CandidateResult> cands = {Predicted("ambient_light", 0.12, 3.0),
                                        Predicted("light_intensity", 0.741, 14.0, "lamp"),
                                        Predicted("light_emission_profile", 0.30, 9.0, "lamp"),
                                        Predicted("light_intensity", 0.739, 13.0, "lamp2")};
  EXPECT_EQ(Order(cands),
            (std::vector<std::string>{"light_intensity:lamp", "light_emission_profile:lamp",
                                      "light_intensity:lamp2", "ambient_light"}));
}

TEST(RankForTrialsTest, OtherwiseBestPredictedFirst) {
  std::vector<CandidateResult> cands = {
      Predicted("vignetting", 0.2, 3.0), Predicted("light_intensity", 0.5, 9.0, "lamp"),
      Predicted("light_intensity", 0.1, 2.0, "lamp2"), Predicted("ambient_light", 0.3, 4.0)};
  EXPECT_EQ(Order(cands), (std::vector<std::string>{"light_intensity:lamp", "ambient_light",
                                                    "vignetting", "light_intensity:lamp2"}));
  // All of one effect: nothing to move up.
  std::vector<CandidateResult> same = {Predicted("specular_lobe_shape", 0.2, 3.0),
                                       Predicted("specular_lobe_shape", 0.4, 3.0)};
  same[0].params["region"] = "floor";
  same[1].params["region"] = "glossy_box";
  EXPECT_EQ(Order(same), (std::vector<std::string>{"specular_lobe_shape:glossy_box",
                                                   "specular_lobe_shape:floor"}));
}

TEST(RankForTrialsTest, WeakInsignificantAndInvalidAreLeftOut) {
  std::vector<CandidateResult> cands = {
      Predicted("vignetting", 0.005, 3.0), Predicted("ambient_light", 0.3, 1.0),
      Predicted("camera_response", 0.2, 2.0), Predicted("exposure_scale", 0.4, 5.0)};
  cands[3].valid = false;
  EXPECT_EQ(Order(cands), (std::vector<std::string>{"camera_response"}));
}

// A fit that explains more than the residual holds (predicted gain above 100 %: the camera
// response fitted with an exponent of −0.18 on a capture with a true 0.8) is a fit failure:
// not tried, and said so.
TEST(RankForTrialsTest, AFitThatExplainsMoreThanTheResidualIsAFailure) {
  std::vector<CandidateResult> cands = {Predicted("camera_response", 1.01, 40.0),
                                        Predicted("vignetting", 0.2, 3.0)};
  EXPECT_EQ(Order(cands), (std::vector<std::string>{"vignetting"}));
  EXPECT_FALSE(cands[0].valid);
  EXPECT_NE(cands[0].note.find("fit failure"), std::string::npos) << cands[0].note;
}

}  // namespace
}  // namespace igi
