// Sampling the lighting's emitters from a shading point, and the matching pdfs for MIS.
#include <algorithm>
#include <cmath>
#include <limits>

#include "solver/render/render_internal.h"

namespace igi::render {
namespace {

// Picks a triangle by area and a uniform point on it; returns the point, its front normal and
// the triangle's index.
int SampleTriangle(const TriangleEmitter& e, const Eigen::Vector3d& u, Eigen::Vector3d* point,
                   Eigen::Vector3d* normal) {
  const double target = u[0] * e.total_area;
  int t = static_cast<int>(std::upper_bound(e.cdf.begin(), e.cdf.end(), target) - e.cdf.begin());
  t = std::min(t, static_cast<int>(e.cdf.size()) - 1);
  const Eigen::Vector3d b = SampleUniformTriangle(Eigen::Vector2d(u[1], u[2]));
  *point = b[0] * e.v0[t] + b[1] * e.v1[t] + b[2] * e.v2[t];
  *normal = (e.v1[t] - e.v0[t]).cross(e.v2[t] - e.v0[t]).normalized();
  return t;
}

}  // namespace

LightSample RenderScene::SampleLight(int index, const Eigen::Vector3d& point,
                                        const Eigen::Vector3d& u) const {
  const RenderLight& rl = lights[index];
  const recon::Light* light = rl.light;
  LightSample s;
  switch (rl.type) {
    case recon::LightType::kPoint:
    case recon::LightType::kSpot: {
      const Eigen::Vector3d to_light = light->position - point;
      s.distance = to_light.norm();
      if (!(s.distance > 0)) return s;
      s.wi = to_light / s.distance;
      double relative = 1.0;
      if (rl.type == recon::LightType::kSpot) {
        const Eigen::Vector3d out = rl.spot_frame.transpose() * (-s.wi);  // light -> point
        const double theta = std::acos(std::clamp(out.z(), -1.0, 1.0));
        relative = light->profile.Relative(theta, std::atan2(out.y(), out.x()));
      }
      s.value = light->intensity * (relative / (s.distance * s.distance));
      s.pdf = 1.0;
      s.delta = true;
      return s;
    }
    case recon::LightType::kDirectional:
      s.wi = -light->direction;
      s.distance = std::numeric_limits<double>::infinity();
      s.value = light->irradiance;
      s.pdf = 1.0;
      s.delta = true;
      return s;
    case recon::LightType::kSphere: {
      const SphereSample ss = SampleSphereFromPoint(point, light->center, light->radius,
                                                    Eigen::Vector2d(u[0], u[1]));
      if (!(ss.pdf > 0)) return s;
      s.wi = ss.direction;
      s.distance = ss.distance;
      s.value = light->radiance;
      s.pdf = ss.pdf;
      return s;
    }
    case recon::LightType::kArea: {
      Eigen::Vector3d p, n;
      const int t = SampleTriangle(rl.triangles, u, &p, &n);
      const Eigen::Vector3d to_light = p - point;
      const double d2 = to_light.squaredNorm();
      s.distance = std::sqrt(d2);
      if (!(s.distance > 0)) return s;
      s.wi = to_light / s.distance;
      const double cos_light = -n.dot(s.wi);  // front side faces the shading point
      if (!(cos_light > 0)) return s;
      s.value = rl.triangles.radiance[t];
      s.pdf = d2 / (cos_light * rl.triangles.total_area);
      return s;
    }
    case recon::LightType::kAmbient: {
      // Uniform directions; no distance: the ambient light is never occluded. Treated as a
      // delta light for MIS (no BRDF-sampled ray ever reaches it). The path tracer does not
      // call this (it evaluates ambient light exactly at each vertex, render.cpp AddAmbient);
      // the solver's gather (gather.cpp) does, an unbiased but noisy estimate.
      s.wi = SampleUniformSphere(Eigen::Vector2d(u[0], u[1]));
      s.distance = 0;
      s.value = light->radiance;
      s.pdf = UniformSpherePdf();
      s.delta = true;
      return s;
    }
  }
  return s;
}

double RenderScene::LightPdf(int index, const Eigen::Vector3d& point,
                                const Eigen::Vector3d& dir, const Eigen::Vector3d& hit_point,
                                const Eigen::Vector3d& hit_normal) const {
  const RenderLight& rl = lights[index];
  if (rl.type == recon::LightType::kSphere) {
    return SphereFromPointPdf(point, rl.light->center, rl.light->radius, dir);
  }
  if (rl.type != recon::LightType::kArea) return 0.0;
  const double cos_light = -hit_normal.dot(dir);
  if (!(cos_light > 0)) return 0.0;
  return (hit_point - point).squaredNorm() / (cos_light * rl.triangles.total_area);
}

}  // namespace igi::render
