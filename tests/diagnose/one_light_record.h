#pragma once
// A residual sample lit by one light (light 0), for the candidates' unit tests: its pixel (held
// out by the diagnosis's default rule on 8-px blocks), surface point and the light's sample.
// sim and recorded are left to the caller.

#include <Eigen/Core>
#include <utility>

#include "recon/scene_document.h"
#include "solver/diagnose/effect.h"
#include "solver/diagnose/pixel_records.h"
#include "solver/inverse/photo_model.h"
#include "tools/common/json.h"

namespace igi::test {

inline diagnose::PixelRecord OneLightRecord(
    int photo, int x, int y, int region, const Eigen::Vector3d& position,
    const Eigen::Vector3d& normal, const Eigen::Vector3d& view, const Eigen::Vector3f& albedo,
    const Eigen::Vector3d& wi, double irradiance, double distance) {
  diagnose::PixelRecord r;
  r.photo = photo;
  r.x = x;
  r.y = y;
  r.held_out = solver::PixelHoldout{0.25, 8, 3}.HeldOut(photo, x, y);
  r.region = region;
  r.position = position.cast<float>();
  r.normal = normal.cast<float>();
  r.view = view.cast<float>();
  r.albedo = albedo;
  diagnose::RecordLightSample ls;
  ls.light = 0;
  ls.wi = wi.cast<float>();
  ls.irradiance = Eigen::Vector3f::Constant(float(irradiance));
  ls.distance = float(distance);
  r.lights.push_back(ls);
  return r;
}

// Candidate `c` written into `doc` by its effect (Effect::Write).
inline void WriteCandidate(const diagnose::CandidateResult& c, Json* doc) {
  recon::SceneDocument written(std::move(*doc));
  diagnose::FindEffect(diagnose::MakeEffects(), c.effect)->Write(c, &written);
  *doc = std::move(written).json();
}

}  // namespace igi::test
