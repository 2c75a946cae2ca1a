#pragma once
// A room for the effects' unit tests: a Lambertian floor (z = 0, |x|, |y| < 3) and wall (x = 3,
// |y| < 3, 0 < z < 2.5) under a point lamp 2.5 m above the floor's centre, and residual records
// drawn on them with known truth. Shared by the emission-profile, exposure, response and
// vignetting tests and the driver's (effect_test.cpp).

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "recon/scene.h"
#include "solver/diagnose/pixel_records.h"
#include "solver/render/sampling.h"
#include "tests/diagnose/one_light_record.h"

namespace igi::test::room {

inline constexpr double kRho = 0.5;        // every surface's ρd (Lambert)
inline constexpr double kIntensity = 8.0;  // the lamp's peak intensity, W/sr
inline constexpr double kBounce = 0.03;  // light after a bounce (the same in the model and photos)
inline const Eigen::Vector3d kLamp(0, 0, 2.5);

// The room's model: regions "floor" (0) and "wall" (1), the point lamp "lamp" of kIntensity at
// kLamp, and one lighting "L0" of it. No photos.
inline recon::Scene RoomModel() {
  recon::Scene s;
  for (const char* name : {"floor", "wall"}) {
    recon::Material m;
    m.name = name;
    m.brdf = recon::BrdfModel::kLambert;
    m.rho_d = Eigen::Vector3d::Constant(kRho);
    s.materials.push_back(m);
  }
  recon::Light lamp;
  lamp.name = "lamp";
  lamp.type = recon::LightType::kPoint;
  lamp.position = kLamp;
  lamp.intensity = Eigen::Vector3d::Constant(kIntensity);
  s.lights.push_back(lamp);
  s.lightings.push_back(recon::Lighting{"L0", {0}});
  return s;
}

// A point on the floor (z = 0, |x|, |y| < 3) or a wall (x = 3, |y| < 3, 0 < z < 2.5), seen along
// its normal, lit by a point light of kIntensity at `light`: the unit direction toward the
// light, its distance and the irradiance.
struct RoomPoint {
  Eigen::Vector3d p, n, wi;
  double d = 0, e = 0;
};
inline RoomPoint DrawRoomPoint(std::mt19937_64& rng, bool wall, const Eigen::Vector3d& light) {
  std::uniform_real_distribution<double> u(0, 1);
  RoomPoint q;
  q.p = wall ? Eigen::Vector3d(3, 6 * u(rng) - 3, 2.5 * u(rng))
             : Eigen::Vector3d(6 * u(rng) - 3, 6 * u(rng) - 3, 0);
  q.n = wall ? Eigen::Vector3d(-1, 0, 0) : Eigen::Vector3d(0, 0, 1);
  q.d = (light - q.p).norm();
  q.wi = (light - q.p) / q.d;
  q.e = kIntensity * std::max(0.0, q.wi.dot(q.n)) / (q.d * q.d);
  return q;
}

// RoomModel with the 4 photos of RoomRecords, cam0-3 under the lamp (lighting 0).
inline recon::Scene RoomModelWithPhotos() {
  recon::Scene s = RoomModel();
  for (int j = 0; j < 4; ++j) {
    recon::Photo ph;
    ph.file = "cam" + std::to_string(j) + "_L0.exr";
    ph.lighting = 0;
    s.photos.push_back(ph);
  }
  return s;
}

// Record i of the room: on the floor for even i, on the wall for odd, in photo i % 4, lit by the
// lamp (its point in *q); its sim and recorded values are the caller's.
inline diagnose::PixelRecord RoomRecordAt(int i, std::mt19937_64& rng, RoomPoint* q) {
  const bool wall = i % 2 == 1;
  *q = DrawRoomPoint(rng, wall, kLamp);
  return OneLightRecord(i % 4, (i / 4) % 160, (i / 640) % 120, wall ? 1 : 0, q->p, q->n, q->n,
                        Eigen::Vector3f::Constant(float(kRho)), q->wi, q->e, q->d);
}

// Records on the floor (z = 0, |x|, |y| < 3) and a wall (x = 3, |y| < 3, 0 < z < 2.5), the view
// straight along the normal, alternating floor and wall, in photos 0-3. The photo: the lamp's
// direct light times peak·cos^power of the angle from −z, plus the bounce term scaled as the
// light's flux (peak / (2·(power + 1)) of the isotropic lamp's: the spot sends nothing above its
// horizon), through the response v = (u/ref)^exponent·ref (ref 0.05), 1 % noise.
inline std::vector<diagnose::PixelRecord> RoomRecords(double power, double exponent, uint64_t seed,
                                                      double peak = 1.0) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::normal_distribution<double> g(0, 1);
  const double ref = 0.05;
  std::vector<diagnose::PixelRecord> out;
  for (int i = 0; i < 8000; ++i) {
    RoomPoint q;
    diagnose::PixelRecord r = RoomRecordAt(i, rng, &q);
    const double direct = kRho / render::kPi * q.e;
    const double cos_axis = q.wi.z();  // cos of the angle from −z of the direction lamp → point
    const double truth = peak * direct * std::pow(std::max(0.0, cos_axis), power) +
                         kBounce * peak / (2 * (power + 1));
    const double recorded = ref * std::pow(truth / ref, exponent);
    for (int c = 0; c < 3; ++c) {
      r.sim[c] = float(direct + kBounce);
      r.recorded[c] = float(recorded * (1 + 0.01 * g(rng)));
    }
    out.push_back(r);
  }
  return out;
}

// The room with a second point lamp "lamp2" of kIntensity at kLamp2 in lighting "L1", and 8
// photos: cam0-3 under the lamp (photos 0-3), cam0-3 under lamp2 (photos 4-7).
inline const Eigen::Vector3d kLamp2(-1, 1, 2.2);
inline recon::Scene TwoLightingRoomModel() {
  recon::Scene model = RoomModel();
  recon::Light lamp2 = model.lights[0];
  lamp2.name = "lamp2";
  lamp2.position = kLamp2;
  model.lights.push_back(lamp2);
  model.lightings.push_back(recon::Lighting{"L1", {1}});
  for (int j = 0; j < 8; ++j) {
    recon::Photo ph;
    ph.file = "cam" + std::to_string(j % 4) + "_L" + std::to_string(j / 4) + ".exr";
    ph.lighting = j / 4;
    model.photos.push_back(ph);
  }
  return model;
}

// 16 000 records of TwoLightingRoomModel's photos (photo i % 8, floor and wall in turns of 8),
// each lit by its photo's lamp; the model's value is the lamp's direct light plus the bounce
// term, the photo that value times `scale(photo)` with 1 % noise.
inline std::vector<diagnose::PixelRecord> TwoLightingRoomRecords(
    uint64_t seed, const std::function<double(int)>& scale) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0, 1);
  std::vector<diagnose::PixelRecord> records;
  for (int i = 0; i < 16000; ++i) {
    const bool wall = (i / 8) % 2 == 1;
    const int photo = i % 8;
    const RoomPoint q = DrawRoomPoint(rng, wall, photo < 4 ? kLamp : kLamp2);
    diagnose::PixelRecord r =
        OneLightRecord(photo, (i / 16) % 160, (i / 2560) % 120, wall ? 1 : 0, q.p, q.n, q.n,
                       Eigen::Vector3f::Constant(float(kRho)), q.wi, q.e, q.d);
    r.lights[0].light = photo < 4 ? 0 : 1;
    const double sim = kRho / render::kPi * q.e + kBounce;
    for (int c = 0; c < 3; ++c) {
      r.sim[c] = float(sim);
      r.recorded[c] = float(sim * scale(photo) * (1 + 0.01 * g(rng)));
    }
    records.push_back(r);
  }
  return records;
}

}  // namespace igi::test::room
