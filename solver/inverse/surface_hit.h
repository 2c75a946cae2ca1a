#pragma once
// Internal to igi_solver: the first scene surface along a ray, with its shading frame, through the
// render library's Embree scene of one lighting (solver/render/render_internal.h).

#include <Eigen/Core>
#include <optional>

#include "solver/render/render_internal.h"

namespace igi {

struct SurfaceHit {
  int triangle = -1;
  double b1 = 0, b2 = 0;  // barycentrics of vertices 1 and 2
  double t = 0;
  int region = -1;  // index into Scene::materials
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d n_geo = Eigen::Vector3d::UnitZ();  // face normal, on the ray origin's side
  Eigen::Vector3d n_s = Eigen::Vector3d::UnitZ();    // shading normal, on the same side
  bool front = true;  // the ray arrived on the face's front (counter-clockwise) side
};

// The first surface of the scene mesh along origin + t·dir (dir unit). nullopt when the ray
// escapes or first meets a light's own geometry (sphere or area emitter).
std::optional<SurfaceHit> TraceSurface(const Renderer::Impl& scene, const Eigen::Vector3d& origin,
                                       const Eigen::Vector3d& dir);

}  // namespace igi
