// igi-info: validates a scene.json and prints what it holds (regions, lights, lightings,
// cameras, photos), like OpenImageIO's iinfo for images. Every problem found is printed, one line
// each, and the exit code is 2.
#include <cstdio>

#include "recon/scene.h"
#include "tools/common/cli.h"

namespace {

void PrintSummary(const igi::recon::Scene& scene) {
  std::printf("scene %s\n", scene.file.c_str());
  std::printf("geometry: %zu file(s), %zu vertices, %zu triangles, uvs %s\n",
              scene.geometry_files.size(), scene.mesh.positions.size(),
              scene.mesh.num_triangles(), scene.mesh.has_uvs() ? "yes" : "no");
  std::vector<size_t> triangles(scene.materials.size(), 0);
  for (int r : scene.mesh.triangle_region) ++triangles[r];
  for (size_t i = 0; i < scene.materials.size(); ++i) {
    const igi::recon::Material& m = scene.materials[i];
    const auto missing = m.MissingForRendering();
    std::string unknowns;
    for (const auto& k : missing) unknowns += (unknowns.empty() ? "" : ",") + k;
    std::printf("material %-16s %-15s %7zu triangles  unknown: %s\n", m.name.c_str(),
                std::string(igi::recon::BrdfModelName(m.brdf)).c_str(), triangles[i],
                unknowns.empty() ? "-" : unknowns.c_str());
  }
  for (const igi::recon::Light& l : scene.lights) {
    std::printf("light %-16s %s\n", l.name.c_str(),
                std::string(igi::recon::LightTypeName(l.type)).c_str());
  }
  for (const igi::recon::Lighting& l : scene.lightings) {
    std::string names;
    for (int i : l.lights) names += (names.empty() ? "" : ", ") + scene.lights[i].name;
    std::printf("lighting %-13s [%s]\n", l.name.c_str(), names.c_str());
  }
  for (const igi::recon::Camera& c : scene.cameras) {
    const Eigen::Vector3d center = c.CenterInWorld();
    std::printf("camera %-15s %s %dx%d f=%.2f,%.2f centre=(%.3f, %.3f, %.3f)\n", c.name.c_str(),
                std::string(igi::recon::CameraModelName(c.model)).c_str(), c.width, c.height,
                c.focal_x_px(), c.focal_y_px(), center.x(), center.y(), center.z());
  }
  for (const igi::recon::Photo& p : scene.photos) {
    std::printf("photo %s camera=%s lighting=%s mask=%s\n", p.file.filename().c_str(),
                scene.cameras[p.camera].name.c_str(), scene.lightings[p.lighting].name.c_str(),
                p.mask ? p.mask->filename().c_str() : "-");
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Validate a scene.json and print what it holds", "igi-info"};
  igi::CommonFlags flags;
  igi::AddCommonFlags(app, &flags, /*computes=*/false);
  std::string scene_path;
  bool for_render = false;
  bool no_images = false;
  app.add_option("scene", scene_path, "scene.json to check")->required();
  app.add_flag("--render", for_render, "Also require every material value rendering needs");
  app.add_flag("--no-images", no_images, "Do not open photos, masks and textures");
  return igi::RunMain(app, flags, argc, argv, [&] {
    igi::recon::SceneLoadOptions options;
    options.require_complete_materials = for_render;
    options.check_images = !no_images;
    const igi::recon::Scene scene = igi::recon::LoadScene(scene_path, options);
    PrintSummary(scene);
    return 0;
  });
}
