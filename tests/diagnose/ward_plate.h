#pragma once
// A glossy plate for the lobe effects' unit tests (anisotropic_reflection, specular_reflection):
// a Ward plate (normal +z) under a point light, and residual records whose photo holds a true
// lobe (stretched along a tangent, or isotropic of another roughness) and whose model holds the
// declared one.

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "recon/scene.h"
#include "solver/diagnose/pixel_records.h"
#include "solver/render/brdf.h"
#include "solver/render/sampling.h"
#include "tests/diagnose/one_light_record.h"
#include "tools/common/json.h"

namespace igi::test::ward_plate {

inline constexpr double kRhoS = 0.08, kAlpha = 0.05;
inline const Eigen::Vector3d kRhoD(0.1, 0.2, 0.5);

// The plate's model: region "plate", a Ward lobe of kRhoS and kAlpha over ρd kRhoD.
inline recon::Scene PlateScene() {
  recon::Scene s;
  recon::Material m;
  m.name = "plate";
  m.brdf = recon::BrdfModel::kWard;
  m.rho_d = kRhoD;
  m.rho_s = Eigen::Vector3d::Constant(kRhoS);
  m.alpha = kAlpha;
  s.materials.push_back(m);
  return s;
}

// The plate's declared document: its material, every value given.
inline Json PlateDocument() {
  return Json{
      {"materials",
       {{"plate",
         {{"brdf", "ward"}, {"rho_d", {0.1, 0.2, 0.5}}, {"rho_s", kRhoS}, {"alpha", kAlpha}}}}}};
}

// Specular factor of a Ward lobe on the plate (normal +z) with tangent at `angle` in the xy plane.
inline double Lobe(recon::BrdfModel model, double ax, double ay, double angle,
                   const Eigen::Vector3d& wo, const Eigen::Vector3d& wi) {
  const render::Frame f = render::Frame::FromNormalTangent(
      Eigen::Vector3d::UnitZ(), Eigen::Vector3d(std::cos(angle), std::sin(angle), 0));
  return render::SpecularFactor<double>(model, ax, ay, f.ToLocal(wo), f.ToLocal(wi));
}

// Records of a plate under a point light, seen with half vectors spread around the normal (as
// several cameras around a highlight would see it). The photo has the true lobe (anisotropic
// with tangent at 25°, or isotropic with another alpha); the model the declared ward lobe.
// true_ax/true_ay (when > 0) replace the true lobe's roughnesses (anisotropic: along the 25°
// tangent and across it; isotropic: true_ax).
inline std::vector<diagnose::PixelRecord> PlateRecords(bool anisotropic, uint64_t seed,
                                                       double true_ax = 0, double true_ay = 0) {
  using Eigen::Vector3d;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  std::normal_distribution<double> g(0, 1);
  const Vector3d light(0, 0, 2);
  const double intensity = 30, angle = 25 * render::kPi / 180;
  std::vector<diagnose::PixelRecord> out;
  while (out.size() < 6000) {
    const Vector3d p(u(rng), u(rng), 0);
    const double d = (light - p).norm();
    const Vector3d wi = (light - p) / d;
    const Vector3d h = Vector3d(0.15 * g(rng), 0.15 * g(rng), 1).normalized();
    const Vector3d wo = 2 * h.dot(wi) * h - wi;
    if (!(wo.z() > 0.1)) continue;
    const double e = intensity * wi.z() / (d * d);
    const int n = int(out.size());
    diagnose::PixelRecord r = OneLightRecord(n % 4, (n / 4) % 160, (n / 640) % 120, 0, p,
                                             Vector3d::UnitZ(), wo, kRhoD.cast<float>(), wi, e, d);
    const double s_model = Lobe(recon::BrdfModel::kWard, kAlpha, kAlpha, 0, wo, wi);
    const double ax = true_ax > 0 ? true_ax : anisotropic ? 0.03 : 0.08;
    const double ay = anisotropic ? (true_ay > 0 ? true_ay : 0.15) : ax;
    const double s_true = anisotropic ? Lobe(recon::BrdfModel::kWardAniso, ax, ay, angle, wo, wi)
                                      : Lobe(recon::BrdfModel::kWard, ax, ax, 0, wo, wi);
    for (int c = 0; c < 3; ++c) {
      const double diffuse = kRhoD[c] / render::kPi * e;
      r.sim[c] = float(diffuse + kRhoS * s_model * e);
      const double truth = diffuse + kRhoS * s_true * e;
      r.recorded[c] = float(truth * (1 + 0.01 * g(rng)));  // 1 % photo noise
    }
    out.push_back(r);
  }
  return out;
}

}  // namespace igi::test::ward_plate
