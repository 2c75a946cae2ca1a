#pragma once
// A glossy plate for the lobe-change effects' unit tests (fresnel, specular_lobe_shape: the fit
// LobeChange): residual records of a plate under a point lamp, seen near the mirror views of its
// highlight, and the LobeChange candidate on them.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "recon/scene.h"
#include "solver/diagnose/candidates.h"
#include "solver/diagnose/effects/effects.h"
#include "solver/diagnose/pixel_records.h"
#include "solver/diagnose/residual_fit.h"
#include "solver/render/sampling.h"
#include "tests/diagnose/one_light_record.h"
#include "tools/common/json.h"

namespace igi::test::lobe_plate {

// The lobe candidates with the materials solved (the refit re-solves ρs and α): a glossy plate
// under a point lamp 1 m above it, seen on the mirror views of its highlight at 30° and at 70°
// from the normal, and a third of its pixels off the highlight. The photos follow the true lobe
// (Fresnel-weighted or not, α `truth_alpha`); the model is a plain Ward lobe whose ρs and α a
// solver fitted over both views (`model_rho_s`, `model_alpha`).
inline std::vector<diagnose::PixelRecord> PlateRecords(bool fresnel_truth, double truth_alpha,
                                                       double model_rho_s, double model_alpha,
                                                       uint64_t seed) {
  using Eigen::Vector3d;
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
    return std::exp(-tan2 / (a * a)) / (4 * render::kPi * a * a * std::sqrt(ci * co));
  };
  std::vector<diagnose::PixelRecord> out;
  for (int i = 0; i < 12000; ++i) {
    const bool grazing = i % 2 == 1;
    const double theta = (grazing ? 70.0 : 30.0) * render::kPi / 180;
    // A point near where the lamp's light arrives at `theta`, seen from near its mirror view.
    const double d = std::tan(theta) * (0.9 + 0.2 * u(rng));
    const double phi = 2 * render::kPi * u(rng);
    const Vector3d p(d * std::cos(phi), d * std::sin(phi), 0);
    const double dist = (lamp - p).norm();
    const Vector3d wi = (lamp - p) / dist;
    Vector3d wo = (2 * n.dot(wi) * n - wi);
    wo += Vector3d(0.15 * g(rng), 0.15 * g(rng), 0.0);
    if (i % 3 == 2) {  // a third of the pixels off the highlight: the plate's diffuse albedo
      const double el = (25 + 60 * u(rng)) * render::kPi / 180, az = 2 * render::kPi * u(rng);
      wo = Vector3d(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
    }
    wo.z() = std::max(0.05, wo.z());
    wo.normalize();
    const double e = intensity * n.dot(wi) / (dist * dist);
    const double c = std::min(1.0, (wi + wo).norm() / 2), f0 = 0.04;
    const double weight = fresnel_truth ? 1 + (1 / f0 - 1) * std::pow(1 - c, 5) : 1.0;
    const double truth =
        rho_d / render::kPi * e + rho_s * weight * ward(n, wi, wo, truth_alpha) * e;
    const double model = rho_d / render::kPi * e + model_rho_s * ward(n, wi, wo, model_alpha) * e;
    const int x = int(u(rng) * 160), y = int(u(rng) * 120);
    diagnose::PixelRecord r = OneLightRecord(grazing ? 1 : 0, x, y, 0, p, n, wo,
                                             Eigen::Vector3f::Constant(float(rho_d)), wi, e, dist);
    for (int k = 0; k < 3; ++k) {
      r.sim[k] = float(model);
      r.recorded[k] = float(truth * (1 + 0.01 * g(rng)));
    }
    out.push_back(r);
  }
  return out;
}

// The LobeChange candidate (fresnel when `fresnel`, specular_lobe_shape otherwise) of the plate,
// modelled as a Ward lobe of `model_rho_s` and `model_alpha`, on `records` (the albedo nuisance
// on when `solved`).
inline diagnose::CandidateResult PlateCandidate(bool fresnel,
                                                const std::vector<diagnose::PixelRecord>& records,
                                                double model_rho_s, double model_alpha,
                                                bool solved = true) {
  recon::Scene model;
  recon::Material m;
  m.name = "plate";
  m.brdf = recon::BrdfModel::kWard;
  m.rho_d = Eigen::Vector3d::Constant(0.2);
  m.rho_s = Eigen::Vector3d::Constant(model_rho_s);
  m.alpha = model_alpha;
  model.materials.push_back(m);
  const Json declared = Json::object();
  int num_cells = 0;
  const std::vector<int> cells = diagnose::RecordCells(model, records, 0.05, &num_cells);
  const diagnose::ResidualFitter f(records, cells, num_cells, solved, 8);
  return diagnose::LobeChange({model, declared, solved}, f, 0, fresnel);
}

}  // namespace igi::test::lobe_plate
