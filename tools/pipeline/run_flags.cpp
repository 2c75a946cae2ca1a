#include "tools/pipeline/run_flags.h"

namespace igi::pipeline {

void AddRunFlags(CLI::App& app, RunFlags* flags) {
  RunFlags& f = *flags;
  app.add_option("--scene", f.scene, "scene.json: geometry, materials, lights, lightings");
  app.add_flag("--demo", f.demo, "Generate a synthetic capture (igi-synth) and run the chain");
  app.add_flag("--hdr-photos", f.run.hdr_photos,
               "Photos are radiance maps and the scene has cameras and photos: solve directly");
  app.add_flag("--skip-diagnose", f.run.skip_diagnose, "Skip the diagnosis stage");
  app.add_option("--solve-arg", f.run.solve_args, "Argument passed to igi-solve (repeatable)")
      ->allow_extra_args(false);
  app.add_option("--register-arg", f.run.register_args,
                 "Argument passed to igi-register (repeatable)")
      ->allow_extra_args(false);
  app.add_option("--diagnose-spp", f.run.diagnose_spp, "igi-diagnose --spp (0 = its default)");
  app.add_option("--radiance-scale", f.run.radiance_scale,
                 "Absolute calibration: the HDR maps are this many times the radiance in the "
                 "scene's units (1 = absolute already)")
      ->capture_default_str();
  app.add_option("--diagnose-arg", f.run.diagnose_args,
                 "Argument passed to igi-diagnose (repeatable)")
      ->allow_extra_args(false);
  app.add_option("--report-spp", f.run.report_spp, "Samples per pixel of the report's renders")
      ->capture_default_str();
  app.add_option("--report-photos", f.run.report_photos, "Photos re-rendered in the report")
      ->capture_default_str();
  app.add_option("--report-lightings", f.run.report_lightings, "Lightings of the relit renders")
      ->capture_default_str();
  app.add_option("--report-megapixels", f.run.report_megapixels,
                 "The report's renders and photo figures at most this many megapixels (block "
                 "means of the photos; 0 = their size)")
      ->capture_default_str();
  app.add_option("--camera", f.camera,
                 "camera.json (intrinsics, vignetting) instead of PHOTOS_DIR/camera.json");
  app.add_option("--lights", f.lights,
                 "lights.json (igi-calib lights) instead of PHOTOS_DIR/lights.json");
  app.add_option("--colour", f.colour,
                 "colour.json (igi-calib colour) instead of PHOTOS_DIR/colour.json");
  app.add_option("--bin-dir", f.bin_dir, "Folder of the igi executables (default: igi-run's)");
  app.add_option("--demo-cameras", f.demo_options.cameras, "--demo: cameras")
      ->capture_default_str();
  app.add_option("--demo-ceiling-cameras", f.demo_options.ceiling_cameras,
                 "--demo: cameras looking up at the ceiling, besides --demo-cameras (posed from "
                 "surveyed targets)")
      ->capture_default_str();
  app.add_option("--demo-marker-noise", f.demo_options.marker_noise_px,
                 "--demo: standard deviation (px) of the noise on the control points' pixels")
      ->capture_default_str();
  app.add_option("--demo-width", f.demo_options.width, "--demo: photo width")
      ->capture_default_str();
  app.add_option("--demo-height", f.demo_options.height, "--demo: photo height")
      ->capture_default_str();
  app.add_option("--demo-spp", f.demo_options.spp, "--demo: render samples per pixel")
      ->capture_default_str();
  app.add_option("--demo-calibration", f.demo_choices.calibration,
                 "--demo: the HDR maps' absolute scale: measured (given, as a lab calibration), "
                 "reference (solved from the matte box, its reflectance given) or none")
      ->capture_default_str();
}

RunResult RunFromFlags(const RunFlags& flags, const std::filesystem::path& photos,
                       const std::filesystem::path& out, int threads) {
  RunOptions o = flags.run;
  o.photos_dir = photos;
  o.camera = flags.camera;
  o.colour = flags.colour;
  o.lights = flags.lights;
  o.scene = flags.scene;
  o.out = out;
  o.bin_dir = flags.bin_dir;
  o.num_threads = threads;
  RunResult result;
  result.demo = flags.demo;
  if (!flags.demo) {
    result.run = RunPipeline(o);
    return result;
  }
  DemoOptions demo = flags.demo_options;
  demo.out = out;
  demo.bin_dir = flags.bin_dir;
  demo.skip_diagnose = o.skip_diagnose;
  demo.num_threads = threads;
  if (!o.solve_args.empty()) demo.solve_args = o.solve_args;
  if (!o.diagnose_args.empty()) demo.diagnose_args = o.diagnose_args;
  demo.SetChoices(flags.demo_choices);
  DemoSummary d = RunDemo(demo);
  result.run = std::move(d.run);
  result.demo_summary = std::move(d.summary);
  result.table = std::move(d.table);
  return result;
}

Json RunSummaryJson(const RunSummary& summary) {
  Json stages = Json::array();
  for (const StageOutcome& s : summary.stages) {
    stages.push_back({{"stage", s.stage},
                      {"status", s.status},
                      {"seconds", s.seconds},
                      {"cpu_seconds", s.cpu_seconds}});
  }
  return {{"stages", stages},
          {"partial", summary.partial},
          {"partial_lines", summary.partial_lines},
          {"report", summary.report.string()},
          {"solved_scene", summary.solved_scene.string()},
          {"seconds", summary.seconds}};
}

}  // namespace igi::pipeline
