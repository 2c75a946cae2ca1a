#pragma once
// The box room's photos rendered from its truth (tests/e2e/box_room.h): for solver tests that
// build the room in a folder, render its true scene and solve the declared one.

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "recon/scene.h"
#include "solver/render/render.h"
#include "tools/common/image.h"

namespace igi::test::box_room {

// Renders dir/truth.json (complete materials) through `cameras` under lighting L0 into
// dir/photos/<camera>.exr at `spp` paths per pixel.
inline void RenderTruthPhotos(const std::filesystem::path& dir,
                              const std::vector<std::string>& cameras, int spp, uint64_t seed) {
  recon::SceneLoadOptions lo;
  lo.require_complete_materials = true;
  lo.check_images = false;
  const recon::Scene truth = recon::LoadScene(dir / "truth.json", lo);
  const render::Renderer renderer(truth, truth.FindLighting("L0"));
  render::RenderOptions ro;
  ro.spp = spp;
  ro.seed = seed;
  ro.num_threads = 2;
  ro.show_progress = false;
  for (const std::string& cam : cameras) {
    WriteImage(dir / "photos" / (cam + ".exr"),
               renderer.Render(truth.cameras[truth.FindCamera(cam)], ro));
  }
}

}  // namespace igi::test::box_room
