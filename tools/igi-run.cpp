// igi-run: end to end from a folder of photos (docs/run.md).
//   igi-run PHOTOS_DIR --scene scene.json --out DIR
//   igi-run --hdr-photos --scene scene.json --out DIR     (photos and cameras in the scene)
//   igi-run --demo --out DIR                              (a synthetic capture, then the chain)
// Stages: response -> HDR -> registration -> solve -> diagnose -> report, each in DIR/NN-name/
// with a marker; a rerun resumes from the first unfinished stage (tools/pipeline/pipeline.h).
#include <cstdio>

#include "tools/common/cli.h"
#include "tools/pipeline/demo.h"
#include "tools/pipeline/pipeline.h"

namespace {

constexpr const char* kLayout = R"(
PHOTOS_DIR layout (one sub-folder per photo):
  PHOTOS_DIR/NAME_LIGHTING/   LIGHTING = a lighting of scene.json (suffix may be left out when
                              the scene has one lighting); NAME_LIGHTING names the photo and
                              its camera. It holds one of:
      an LDR bracket          00.png 01.png ... (PNG/JPEG/TIFF) + exposures.txt (one time per
                              line, file-name order; without it EXIF exposure times are read)
      raw files               *.dng *.cr2 *.nef ... decoded linearly (no response needed)
      one radiance map        *.exr or *.hdr, used as it is
      a capture               manifest.jsonl of igi-capture (merged with igi-hdr --manifest)
  PHOTOS_DIR/camera.json      optional camera calibration (or --camera): its intrinsics
                              (igi-calib intrinsics) go to registration, its vignetting
                              (igi-calib vignetting) is divided out of every photo
  PHOTOS_DIR/colour.json      optional colour matrix (igi-calib colour, or --colour) applied
                              to every photo
  PHOTOS_DIR/lights.json      optional calibrated lights (igi-calib lights, or --lights):
                              they replace the scene's lights of the same names
  PHOTOS_DIR/markers.json     optional control points (igi-markers) for registration
Output: DIR/01-response 02-hdr 03-register 04-solve 05-diagnose 06-report (renders, exports),
DIR/report.html.
Exit codes: 0 ok, 1 a stage failed (named; finished stages kept), 2 bad input (nothing
written), 3 partial (e.g. photos that did not register).)";

void PrintSummary(const igi::pipeline::RunSummary& s) {
  for (const auto& st : s.stages) {
    std::printf("  %-12s %-8s %6.1f s  %6.1f s CPU\n", st.stage.c_str(), st.status.c_str(),
                st.seconds, st.cpu_seconds);
  }
  std::printf("report: %s\nsolved scene: %s\n%.1f s\n", s.report.c_str(), s.solved_scene.c_str(),
              s.seconds);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "igi-run: end to end from a folder of photos (response, HDR, registration, "
      "solve, diagnose, report)",
      "igi-run"};
  app.footer(kLayout);
  igi::CommonFlags flags;
  igi::AddCommonFlags(app, &flags, /*computes=*/true);
  igi::pipeline::RunOptions o;
  igi::pipeline::DemoOptions demo;
  // --demo's choice flags as typed; SetChoices parses them into `demo` and validates it.
  igi::pipeline::DemoChoiceFlags demo_choices;
  bool run_demo = false;
  std::string photos, scene, out, bin, camera, colour, lights;
  app.add_option("photos", photos, "PHOTOS_DIR (layout below)");
  app.add_option("--scene", scene, "scene.json: geometry, materials, lights, lightings");
  app.add_option("--out", out, "Output folder (stages resume from it)")->required();
  app.add_flag("--demo", run_demo, "Generate a synthetic capture (igi-synth) and run the chain");
  app.add_flag("--hdr-photos", o.hdr_photos,
               "Photos are radiance maps and the scene has cameras and photos: solve directly");
  app.add_flag("--skip-diagnose", o.skip_diagnose, "Skip the diagnosis stage");
  app.add_option("--solve-arg", o.solve_args, "Argument passed to igi-solve (repeatable)")
      ->allow_extra_args(false);
  app.add_option("--register-arg", o.register_args, "Argument passed to igi-register (repeatable)")
      ->allow_extra_args(false);
  app.add_option("--diagnose-spp", o.diagnose_spp, "igi-diagnose --spp (0 = its default)");
  app.add_option("--radiance-scale", o.radiance_scale,
                 "Absolute calibration: the HDR maps are this many times the radiance in the "
                 "scene's units (1 = absolute already)")
      ->capture_default_str();
  app.add_option("--diagnose-arg", o.diagnose_args, "Argument passed to igi-diagnose (repeatable)")
      ->allow_extra_args(false);
  app.add_option("--report-spp", o.report_spp, "Samples per pixel of the report's renders")
      ->capture_default_str();
  app.add_option("--report-photos", o.report_photos, "Photos re-rendered in the report")
      ->capture_default_str();
  app.add_option("--report-lightings", o.report_lightings, "Lightings of the relit renders")
      ->capture_default_str();
  app.add_option("--report-megapixels", o.report_megapixels,
                 "The report's renders and photo figures at most this many megapixels (block "
                 "means of the photos; 0 = their size)")
      ->capture_default_str();
  app.add_option("--camera", camera,
                 "camera.json (intrinsics, vignetting) instead of PHOTOS_DIR/camera.json");
  app.add_option("--lights", lights,
                 "lights.json (igi-calib lights) instead of PHOTOS_DIR/lights.json");
  app.add_option("--colour", colour,
                 "colour.json (igi-calib colour) instead of PHOTOS_DIR/colour.json");
  app.add_option("--bin-dir", bin, "Folder of the igi executables (default: igi-run's)");
  app.add_option("--demo-cameras", demo.cameras, "--demo: cameras")->capture_default_str();
  app.add_option("--demo-ceiling-cameras", demo.ceiling_cameras,
                 "--demo: cameras looking up at the ceiling, besides --demo-cameras (posed from "
                 "surveyed targets)")
      ->capture_default_str();
  app.add_option("--demo-marker-noise", demo.marker_noise_px,
                 "--demo: standard deviation (px) of the noise on the control points' pixels")
      ->capture_default_str();
  app.add_option("--demo-width", demo.width, "--demo: photo width")->capture_default_str();
  app.add_option("--demo-height", demo.height, "--demo: photo height")->capture_default_str();
  app.add_option("--demo-spp", demo.spp, "--demo: render samples per pixel")->capture_default_str();
  app.add_option("--demo-calibration", demo_choices.calibration,
                 "--demo: the HDR maps' absolute scale: measured (given, as a lab calibration), "
                 "reference (solved from the matte box, its reflectance given) or none")
      ->capture_default_str();
  return igi::RunMain(app, flags, argc, argv, [&]() -> int {
    o.photos_dir = photos;
    o.camera = camera;
    o.colour = colour;
    o.lights = lights;
    o.scene = scene;
    o.out = out;
    o.bin_dir = bin;
    o.num_threads = flags.threads;
    igi::pipeline::RunSummary summary;
    if (run_demo) {
      demo.out = out;
      demo.bin_dir = bin;
      demo.skip_diagnose = o.skip_diagnose;
      demo.num_threads = flags.threads;
      if (!o.solve_args.empty()) demo.solve_args = o.solve_args;
      if (!o.diagnose_args.empty()) demo.diagnose_args = o.diagnose_args;
      demo.SetChoices(demo_choices);
      const igi::pipeline::DemoSummary d = igi::pipeline::RunDemo(demo);
      summary = d.run;
      PrintSummary(summary);
      std::printf("recovered parameters beside the truth (%s/demo_summary.json):\n", out.c_str());
      for (const std::string& line : d.table) std::printf("  %s\n", line.c_str());
    } else {
      summary = igi::pipeline::RunPipeline(o);
      PrintSummary(summary);
    }
    if (summary.partial) throw igi::PartialError(summary.partial_lines);
    return 0;
  });
}
