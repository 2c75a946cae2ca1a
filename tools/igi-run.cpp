// igi-run: end to end from a folder of photos (docs/run.md).
//   igi-run PHOTOS_DIR --scene scene.json --out DIR
//   igi-run --hdr-photos --scene scene.json --out DIR     (photos and cameras in the scene)
//   igi-run --demo --out DIR                              (a synthetic capture, then the chain)
// Stages: response -> HDR -> registration -> solve -> diagnose -> report, each in DIR/NN-name/
// with a marker; a rerun resumes from the first unfinished stage (tools/pipeline/pipeline.h).
#include <cstdio>

#include "tools/common/cli.h"
#include "tools/pipeline/run_flags.h"

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
  std::string photos, out;
  app.add_option("photos", photos, "PHOTOS_DIR (layout below)");
  app.add_option("--out", out, "Output folder (stages resume from it)")->required();
  igi::pipeline::RunFlags f;
  igi::pipeline::AddRunFlags(app, &f);
  return igi::RunMain(app, flags, argc, argv, [&]() -> int {
    const igi::pipeline::RunResult r = igi::pipeline::RunFromFlags(f, photos, out, flags.threads);
    PrintSummary(r.run);
    if (r.demo) {
      std::printf("recovered parameters beside the truth (%s/demo_summary.json):\n", out.c_str());
      for (const std::string& line : r.table) std::printf("  %s\n", line.c_str());
    }
    if (r.run.partial) throw igi::PartialError(r.run.partial_lines);
    return 0;
  });
}
