#pragma once
// The solver stages' inputs built by hand, for testing a stage alone: observations of a 1 m
// Lambertian square "floor" (z = 0, seen from +z) lit by one point light, under a known
// irradiance, taken by two photos (even and odd observations). No photo is read and nothing is
// gathered or fitted.
#include <functional>
#include <random>
#include <string>

#include "solver/inverse/light_model.h"
#include "solver/inverse/material_estimate.h"
#include "solver/inverse/observation_set.h"
#include "solver/inverse/patches.h"
#include "solver/inverse/solve_options.h"
#include "tests/solver/test_scenes.h"

namespace igi::test {

struct SquareStage {
  recon::Scene scene;
  solver::SolveOptions options;
  solver::PatchSet patches;  // of 0.1 m
  solver::MaterialEstimate materials;
  solver::ObservationSet obs;
  solver::LightModel light;

  // `n` observations at points drawn uniformly over the square (seeded by `seed`), each with the
  // radiance radiance(u, v, rng) in every channel (u, v in [0, 1] across the square), every one a
  // fit sample, and the light model's irradiance `irradiance` everywhere (no specular term).
  SquareStage(const std::string& name, int n, double irradiance, unsigned seed,
              const std::function<double(double u, double v, std::mt19937& rng)>& radiance) {
    const auto dir = TempSceneDir(name);
    WriteText(dir / "square.obj", SquareObj("floor", 0.5));
    WriteJsonFile(
        dir / "scene.json",
        Json{{"format", "igi-scene"},
             {"version", 1},
             {"geometry", Json::array({Json{{"file", "square.obj"}}})},
             {"materials", {{"floor", {{"brdf", "lambert"}}}}},
             {"lights", {{"l", {{"type", "point"}, {"position", {0, 0, 2}}, {"intensity", 1}}}}},
             {"lightings", {{"L", {"l"}}}},
             {"cameras", Json::object()},
             {"photos", Json::array()}});
    scene = recon::LoadScene(dir / "scene.json");
    patches = solver::BuildPatches(scene.mesh, 0.1);
    materials = solver::MaterialEstimate::FromScene(scene, patches);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u01(0.0, 1.0);
    light.lightings.resize(1);
    light.lightings[0].active = true;
    for (int i = 0; i < n; ++i) {
      // A point of the square, uniform: the triangle by area, barycentrics uniform in it.
      const int tri = u01(rng) < 0.5 ? 0 : 1;
      double b1 = u01(rng), b2 = u01(rng);
      if (b1 + b2 > 1) b1 = 1 - b1, b2 = 1 - b2;
      const auto& t = scene.mesh.triangles[tri];
      const Eigen::Vector3f p0 = scene.mesh.positions[t[0]], p1 = scene.mesh.positions[t[1]],
                            p2 = scene.mesh.positions[t[2]];
      const Eigen::Vector3f p = p0 + float(b1) * (p1 - p0) + float(b2) * (p2 - p0);
      solver::Observation o;
      o.photo = i % 2;
      o.triangle = tri;
      o.b1 = float(b1);
      o.b2 = float(b2);
      o.region = 0;
      o.patch = patches.PatchOf(tri, b1, b2);
      o.position = p;
      o.normal = Eigen::Vector3f(0, 0, 1);
      o.view = Eigen::Vector3f(0, 0, 1);
      o.radiance = Eigen::Vector3f::Constant(float(radiance(p.x() + 0.5, p.y() + 0.5, rng)));
      light.lightings[0].obs.push_back(i);
      obs.items.push_back(o);
    }
    obs.in_fit.assign(n, 1);
    materials[0].observations = n;
    light.e.assign(n, Eigen::Vector3d::Constant(irradiance));
    light.t.assign(n, Eigen::Vector3d::Zero());
    light.incident.resize(n);
  }
};

}  // namespace igi::test
