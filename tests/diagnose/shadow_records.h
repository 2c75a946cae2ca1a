#pragma once
// A shadow for the effects' unit tests, rendered by the renderer: a Lambertian floor under a
// black square blocker, lit by a point lamp or a sphere lamp of the same intensity, and residual
// records of the floor whose photo and model are path-traced from two such scenes. Shared by the
// light_source_extent, light_intensity and ambient_light tests.

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <random>
#include <vector>

#include "recon/scene.h"
#include "solver/diagnose/pixel_records.h"
#include "solver/inverse/photo_model.h"
#include "solver/render/ray_scene.h"
#include "solver/render/render.h"
#include "solver/render/sampling.h"

namespace igi::test::shadow {

// Adds the quad `v` (counter-clockwise seen from its front) of region `region` to `mesh`.
inline void AddQuad(recon::TriangleMesh* mesh, const std::array<Eigen::Vector3f, 4>& v,
                    int region) {
  const Eigen::Vector3f n = (v[1] - v[0]).cross(v[2] - v[0]).normalized();
  const int base = int(mesh->positions.size());
  for (const Eigen::Vector3f& p : v) {
    mesh->positions.push_back(p);
    mesh->normals.push_back(n);
  }
  mesh->triangles.emplace_back(base, base + 1, base + 2);
  mesh->triangles.emplace_back(base, base + 2, base + 3);
  mesh->triangle_region.push_back(region);
  mesh->triangle_region.push_back(region);
}

inline constexpr double kIntensity = 20;  // the lamp's, W/sr
inline const Eigen::Vector3d kLamp(0.3, 0.2, 2.0);

// A lambert floor (4 m square) under a black square blocker at 0.8 m, lit by a point lamp or a
// sphere lamp of the same intensity.
inline recon::Scene ShadowScene(double radius) {
  using Eigen::Vector3f;
  recon::Scene s;
  AddQuad(&s.mesh, {Vector3f(-2, -2, 0), Vector3f(2, -2, 0), Vector3f(2, 2, 0), Vector3f(-2, 2, 0)},
          0);
  AddQuad(&s.mesh,
          {Vector3f(-0.4f, -0.4f, 0.8f), Vector3f(0.4f, -0.4f, 0.8f), Vector3f(0.4f, 0.4f, 0.8f),
           Vector3f(-0.4f, 0.4f, 0.8f)},
          1);
  s.mesh.region_names = {"floor", "blocker"};
  recon::Material floor;
  floor.name = "floor";
  floor.rho_d = Eigen::Vector3d(0.5, 0.4, 0.3);
  recon::Material blocker;
  blocker.name = "blocker";
  blocker.brdf = recon::BrdfModel::kBlack;
  s.materials = {floor, blocker};
  recon::Light lamp;
  lamp.name = "lamp";
  if (radius > 0) {
    lamp.type = recon::LightType::kSphere;
    lamp.center = kLamp;
    lamp.radius = radius;
    lamp.radiance = Eigen::Vector3d::Constant(kIntensity / (render::kPi * radius * radius));
  } else {
    lamp.position = kLamp;
    lamp.intensity = Eigen::Vector3d::Constant(kIntensity);
  }
  s.lights = {lamp};
  s.lightings = {recon::Lighting{"L0", {0}}};
  recon::Photo photo;
  photo.lighting = 0;
  s.photos = {photo};
  return s;
}

// Records of the floor points of an n × n grid over [-1.5, 1.5]² that `eye` sees, the photo
// path-traced from `truth` (`photo_spp` paths, 1 % noise), the model from `model`.
inline std::vector<diagnose::PixelRecord> FloorGridRecords(const recon::Scene& model,
                                                           const recon::Scene& truth,
                                                           const Eigen::Vector3d& eye, int n,
                                                           int photo_spp, int sim_spp) {
  const render::Renderer photo(truth, 0), sim(model, 0);
  std::mt19937_64 rng(5);
  std::normal_distribution<double> g(0, 1);
  std::vector<diagnose::PixelRecord> out;
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector3d p(-1.5 + 3.0 * (i + 0.5) / n, -1.5 + 3.0 * (j + 0.5) / n, 0);
      const Eigen::Vector3d dir = (p - eye).normalized();
      const std::optional<render::RayHit> hit = sim.rays().Intersect(eye, dir);
      if (!hit || std::abs(hit->t - (p - eye).norm()) > 1e-3) continue;  // hidden from the eye
      diagnose::PixelRecord r;
      r.x = 2 * i;
      r.y = 2 * j;
      r.held_out = solver::PixelHoldout{0.25, 8, 3}.HeldOut(0, r.x, r.y);
      r.region = 0;
      r.position = p.cast<float>();
      r.normal = Eigen::Vector3f::UnitZ();
      r.view = (-dir).cast<float>();
      r.albedo = model.materials[0].rho_d->cast<float>();
      const uint64_t seed = uint64_t(j * n + i);
      r.recorded = photo.Radiance(eye, dir, photo_spp, seed).cast<float>();
      r.recorded *= float(1 + 0.01 * g(rng));  // 1 % photo noise
      r.sim = sim.Radiance(eye, dir, sim_spp, seed + 7).cast<float>();
      out.push_back(r);
    }
  }
  return out;
}

// Floor records seen from a camera above the blocker's side, the photo rendered with a sphere
// lamp of `true_radius` (0: the declared point) with 1 % noise, the model with the point lamp.
inline std::vector<diagnose::PixelRecord> ShadowRecords(const recon::Scene& model,
                                                        double true_radius) {
  return FloorGridRecords(model, ShadowScene(true_radius), Eigen::Vector3d(0, -3, 3), 60,
                          true_radius > 0 ? 256 : 4, 4);
}

}  // namespace igi::test::shadow
