// bench_render_image SCENE CAMERA LIGHTING SPP SEED THREADS OUT.exr: one igi render, timed like
// Cycles' render call in cycles_room.py (the Renderer's construction — Embree scene build,
// materials — plus Render(); scene.json parsing excluded). Prints "IGI_RENDER_SECONDS s" and
// "IGI_RENDER_MRAYS_PER_S r". For run_cycles_bench.sh.
#include <chrono>
#include <cstdio>
#include <string>

#include "recon/scene.h"
#include "solver/render/render.h"
#include "tools/common/image.h"

int main(int argc, char** argv) {
  if (argc != 8) {
    std::fprintf(stderr,
                 "usage: bench_render_image SCENE CAMERA LIGHTING SPP SEED THREADS OUT.exr\n");
    return 2;
  }
  try {
    igi::recon::SceneLoadOptions load;
    load.require_complete_materials = true;
    load.check_images = false;
    const igi::recon::Scene scene = igi::recon::LoadScene(argv[1], load);
    const int camera = scene.FindCamera(argv[2]);
    const int lighting = scene.FindLighting(argv[3]);
    if (camera < 0 || lighting < 0) throw igi::InputError("unknown camera or lighting");
    igi::render::RenderOptions options;
    options.spp = std::stoi(argv[4]);
    options.seed = std::stoull(argv[5]);
    options.num_threads = std::stoi(argv[6]);
    options.show_progress = false;
    const auto start = std::chrono::steady_clock::now();
    const igi::render::Renderer renderer(scene, lighting);
    igi::render::RenderSummary summary;
    const igi::Image image = renderer.Render(scene.cameras[camera], options, &summary);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    igi::WriteImageOptions write;
    write.type = igi::PixelType::kFloat;
    igi::WriteImage(argv[7], image, write);
    std::printf("IGI_RENDER_SECONDS %.4f\nIGI_RENDER_MRAYS_PER_S %.3f\n", seconds,
                summary.RaysPerSecond() * 1e-6);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_render_image: %s\n", e.what());
    return 1;
  }
  return 0;
}
