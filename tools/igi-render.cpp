// igi-render: renders any camera of a scene under any of its lightings with the path tracer,
// to a linear OpenEXR in the scene's radiance units (docs/scene-format.md).
#include <spdlog/spdlog.h>

#include "recon/scene.h"
#include "solver/render/render.h"
#include "tools/common/cli.h"
#include "tools/common/error.h"
#include "tools/common/strings.h"

int main(int argc, char** argv) {
  CLI::App app{"Render a camera of a scene under one of its lightings (linear EXR)", "igi-render"};
  igi::CommonFlags flags;
  igi::AddCommonFlags(app, &flags);
  std::string scene_path, camera_name, lighting_name, out_path;
  igi::render::RenderOptions options;
  bool half = false;
  app.add_option("scene", scene_path, "scene.json")->required();
  app.add_option("--camera", camera_name, "Camera name (a key of cameras)")->required();
  app.add_option("--lighting", lighting_name, "Lighting name (a key of lightings)")->required();
  app.add_option("--out", out_path, "Output image (.exr)")->required();
  app.add_option("--spp", options.spp, "Paths per pixel")->capture_default_str();
  app.add_option("--seed", options.seed, "Random seed (same seed, same image)")->capture_default_str();
  app.add_option("--width", options.width, "Output width (0 = the camera's)");
  app.add_option("--height", options.height, "Output height (0 = the camera's)");
  app.add_option("--max-bounces", options.max_bounces, "Path length cap")->capture_default_str();
  app.add_flag("--half", half, "Write half floats instead of 32-bit floats");
  return igi::RunMain(app, flags, argc, argv, [&] {
    // Everything is validated before any work or writing.
    if (igi::ToLower(std::filesystem::path(out_path).extension().string()) != ".exr") {
      throw igi::InputError(igi::DescribeProblem(out_path, "--out", "", "must end in .exr"));
    }
    options.Validate();
    igi::recon::SceneLoadOptions load;
    load.require_complete_materials = true;
    load.check_images = false;  // photos are not needed to render
    const igi::recon::Scene scene = igi::recon::LoadScene(scene_path, load);
    const int camera = scene.FindCamera(camera_name);
    if (camera < 0) {
      throw igi::InputError(igi::DescribeProblem(scene_path, "--camera", camera_name,
                                                 "no camera of that name in the scene"));
    }
    const int lighting = scene.FindLighting(lighting_name);
    if (lighting < 0) {
      throw igi::InputError(igi::DescribeProblem(scene_path, "--lighting", lighting_name,
                                                 "no lighting of that name in the scene"));
    }
    const igi::render::Renderer renderer(scene, lighting);
    igi::render::RenderSummary summary;
    igi::Image image = renderer.Render(scene.cameras[camera], options, &summary);
    image.metadata["igi:scene"] = scene.file.string();
    image.metadata["igi:camera"] = camera_name;
    image.metadata["igi:lighting"] = lighting_name;
    image.metadata["igi:spp"] = int64_t(options.spp);
    image.metadata["igi:seed"] = int64_t(options.seed);
    image.metadata["igi:units"] = std::string("radiance W/(sr m^2), linear");
    igi::WriteImageOptions write;
    write.type = half ? igi::PixelType::kHalf : igi::PixelType::kFloat;
    write.compression = "zip";
    igi::WriteImage(out_path, image, write);
    spdlog::info("{}x{}, {} spp: {:.1f} s, {:.2f} Mrays/s", image.width, image.height, options.spp,
                 summary.seconds, summary.RaysPerSecond() * 1e-6);
    return 0;
  });
}
