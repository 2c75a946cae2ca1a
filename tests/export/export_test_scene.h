#pragma once
// Scenes for the export tests: the shared radiance_room reference (real RADIANCE data) and a
// synthetic scene with one of every material mapping and light type (known truth).
#include <filesystem>
#include <string>

#include "recon/scene.h"

namespace igi::test {

inline std::filesystem::path RadianceRoomDir() {
  return std::filesystem::path(IGI_SHARED_DATA_DIR) / "reference" / "radiance_room";
}

inline recon::Scene LoadRadianceRoom() {
  recon::SceneLoadOptions load;
  load.require_complete_materials = true;
  load.check_images = false;
  return recon::LoadScene(RadianceRoomDir() / "scene.json", load);
}

// Adds a unit quad at height z (two CCW triangles facing +z) of region `region`.
inline void AddQuad(recon::TriangleMesh* mesh, int region, float z) {
  const int base = int(mesh->positions.size());
  for (auto [x, y] : {std::pair{0.f, 0.f}, {1.f, 0.f}, {1.f, 1.f}, {0.f, 1.f}}) {
    mesh->positions.emplace_back(x, y, z);
    mesh->normals.emplace_back(0.f, 0.f, 1.f);
    mesh->uvs.emplace_back(x, y);
  }
  mesh->triangles.emplace_back(base, base + 1, base + 2);
  mesh->triangles.emplace_back(base, base + 2, base + 3);
  mesh->triangle_region.insert(mesh->triangle_region.end(), 2, region);
}

// Materials: lambert, ward_gmd with ρs ∝ ρd (-> metal), ward (1992), ward_gmd_aniso, emitter.
// Lights: point, spot (cone), directional, sphere, area; one lighting "all" with every light.
// One PINHOLE camera with an off-centre principal point.
inline recon::Scene SyntheticScene() {
  recon::Scene scene;
  scene.file = "synthetic/scene.json";
  auto add = [&](recon::Material m) {
    scene.mesh.region_names.push_back(m.name);
    AddQuad(&scene.mesh, int(scene.materials.size()), float(scene.materials.size()));
    scene.materials.push_back(std::move(m));
  };
  recon::Material m;
  m.name = "matte", m.brdf = recon::BrdfModel::kLambert, m.rho_d = Eigen::Vector3d(0.5, 0.4, 0.3);
  add(m);
  m = {}, m.name = "gold", m.brdf = recon::BrdfModel::kWardGmd;
  m.rho_d = Eigen::Vector3d(0.4, 0.2, 0.1), m.rho_s = Eigen::Vector3d(0.2, 0.1, 0.05);
  m.alpha = 0.2;
  add(m);
  m = {}, m.name = "old_ward", m.brdf = recon::BrdfModel::kWard;
  m.rho_d = Eigen::Vector3d(0.3, 0.3, 0.3), m.rho_s = Eigen::Vector3d::Constant(0.04);
  m.alpha = 0.1;
  add(m);
  m = {}, m.name = "brushed", m.brdf = recon::BrdfModel::kWardGmdAniso;
  m.rho_d = Eigen::Vector3d(0.1, 0.1, 0.1), m.rho_s = Eigen::Vector3d::Constant(0.1);
  m.alpha_x = 0.05, m.alpha_y = 0.3, m.tangent = Eigen::Vector3d::UnitX();
  add(m);
  m = {}, m.name = "glow", m.brdf = recon::BrdfModel::kEmitter,
  m.radiance = Eigen::Vector3d(5, 5, 5);
  add(m);

  recon::Light l;
  l.name = "bulb", l.type = recon::LightType::kPoint, l.position = {0.5, 0.5, 3};
  l.intensity = {10, 10, 10};
  scene.lights.push_back(l);
  l = {}, l.name = "spot", l.type = recon::LightType::kSpot, l.position = {0.5, 0.5, 3};
  l.direction = {0, 0, -1}, l.intensity = {20, 20, 20};
  l.profile.kind = recon::SpotProfile::Kind::kCone, l.profile.inner_deg = 20,
  l.profile.outer_deg = 30;
  scene.lights.push_back(l);
  l = {}, l.name = "sun", l.type = recon::LightType::kDirectional, l.direction = {0, 0, -1};
  l.irradiance = {3, 3, 3};
  scene.lights.push_back(l);
  l = {}, l.name = "lamp", l.type = recon::LightType::kSphere, l.center = {0.5, 0.5, 2.5};
  l.radius = 0.1, l.radiance = {100, 100, 100};
  scene.lights.push_back(l);
  l = {}, l.name = "panel", l.type = recon::LightType::kArea, l.radiance = {50, 50, 50};
  l.mesh.region_names.push_back("panel");
  AddQuad(&l.mesh, 0, 4.0f);
  scene.lights.push_back(l);
  scene.lightings.push_back({"all", {0, 1, 2, 3, 4}});

  recon::Camera camera;
  camera.name = "cam";
  camera.width = 200, camera.height = 100;
  camera.params = {100, 100, 110, 45};
  camera.cam_from_world.translation = {0, 0, 5};
  scene.cameras.push_back(camera);
  return scene;
}

}  // namespace igi::test
