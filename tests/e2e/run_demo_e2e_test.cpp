// igi-run --demo end to end: igi-synth writes an unposed capture of its
// textured room (LDR brackets through a gamma response), igi-run recovers the response, merges
// the HDR maps, registers the photos (COLMAP, with control points and the known intrinsics),
// solves and writes the report. Checked:
// - the recovered parameters against truth.json, after the photometric scale k (the HDR maps'
//   free constant, see tools/pipeline/demo.h), within stated tolerances;
// - the ceiling seen (4 cameras look up, posed from the surveyed targets) and solved; every photo
//   registered, its pose near the true camera;
// - resuming: with 05-diagnose (skipped here) deleted, a rerun keeps 00-04 (markers
//   byte-identical, "kept") and redoes 05 onwards (06-report after it too; deleting 04-solve
//   instead would cost another 6 min of CPU for the same check);
// - report.html in headless Chromium: no console errors, every <img> decoded, a screenshot
//   that is not blank.
// Several minutes on 2 shared cores: LABELS slow.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <map>
#include <regex>

#include "tests/e2e/chromium_check.h"
#include "tests/e2e/run.h"
#include "tests/temp_dir.h"
#include "tools/common/atomic_file.h"
#include "tools/common/image.h"
#include "tools/common/json.h"

namespace igi {
namespace {

namespace fs = std::filesystem;
using test::Quote;
using test::RunTool;

// Tolerances on top of the solver's own (docs/solve.md: 1-7 % on igi-synth rooms from true poses and
// true radiance): the demo's photos are 8 spp renders, 3 brackets of 8 bits merged with a
// recovered response (about 1 % in radiance), COLMAP poses refined with the control points, and
// the HDR maps' absolute scale solved from the matte box (the demo's default
// --demo-calibration reference; the matte box's material is given and left out of the
// comparison). Measured with the ceiling seen by no photo (calibration "measured"):
// ρd −7.5..+14 %, ρs −0.6 % / −0.3 % / −8.3 %, α +0.2..+4 %; "reference" solved the scale
// −13.3 %. Measured with 2 ceiling cameras posed from the surveyed targets, after k:
// "reference" (k = 1.030, the scale solved −3.1 %): ρd −9.4..+4.7 % (wall_x4 −9.4 %, the ceiling
// −0.9 %), ρs −6.3..+1.6 %, α −1.5..+1.6 %; "measured" (k = 1.009): ρd −8.4..+5.6 %, ρs
// −2.0..+4.9 %, α −1.7..+1.1 % except the floor's broad faint lobe (ρs 0.04, α 0.15 on a
// textured floor): +16.4 % (+1.6 % with "reference": weakly determined). A textured region's true
// ρd is its texture's mean over the surface the photos see (tools/pipeline/demo.h SeenTrueAlbedo), not
// over the whole texture: on the same solve that takes wall_x4 from −7.7 % to −5.1 % and the glossy
// objects from +3.2 / +4.9 % to +1.8 / +0.0 %; every other region within 2.7 % (solve from every
// third pixel, as the demo now does: the same within 1.5 points). Regions no photo sees
// ("unobserved") and lobes whose highlight no photo shows ("no_highlight") are reported by
// igi-solve and not compared. With every photo registered (bench/RESULTS.md "End to end"), the
// truth over the solved maps' seen texels and the glossy box and sphere mapped (their texture is
// finer than the solver's patches): ρd −0.6..+1.25 % (wall_y4 +1.1 and +1.25 %: half of wall_x4,
// unseen, is brighter than its seen half), ρs −3.1..+0.2 % and −2.5..−0.5 %, α −0.7..+3.3 % and
// −0.7..+1.1 %, k 1.001 and 0.999. The bounds keep about twice that: an error several times larger
// fails. With bench/solver/run_demo_split.sh (the solve repeated from the true poses and the true
// radiance): ρd −0.4..+0.2 % but wall_y4 +1.2 % (the solver's on this capture: +1.4 % from the true
// radiance), the floor's faint lobe ρs −6.6 % and α −5.1 %. That spread of the floor's lobe was the
// fit's sample draw (keyed by the observation's index, redrawn by any change to an earlier photo),
// not the registration; every highlight sample fitted and 4 ceiling cameras: ρd −0.7..+0.8 %
// (wall_y4 +0.8 %), ρs and α −3.4..+0.5 %, poses within 0.069° and 2.4 mm.
constexpr double kRhoDTolerance = 0.03;  // region-mean albedo after k (seen part)
// Specular reflectance after k and lobe width (scale-free): COLMAP's poses differ slightly run to
// run, which moves the floor's narrow highlight by about a pixel between views (measured up to
// +4.5 % on the floor's α with another solve of the same capture).
constexpr double kRhoSTolerance = 0.08;
constexpr double kAlphaTolerance = 0.08;
// The ceiling, seen by the 2 cameras that look up (measured −0.9 % after k with "reference",
// −1.0 % with "measured", +0.0 % and +0.3 % in two other solves; 40 % low when no photo saw it
// and it kept a placeholder).
constexpr double kCeilingRhoDTolerance = 0.03;
// Registration against the true cameras: the targets, 0.1° and 0.5 % of the scene's size (the
// room's 6.4 m diagonal: 32 mm; held here to 0.2 %, 12.8 mm). Measured with exact control points:
// COLMAP's poses within 0.011° and 0.6 mm, the ceiling cameras within 1e-4°; with the demo's
// 0.1 px of noise on them: every photo within 0.085° and 5.4 mm (cam2; the ceiling
// cameras, posed from about 13 targets alone, and the markers anchor the joint refinement).
constexpr double kRotationToleranceDeg = 0.1;
constexpr double kPositionToleranceM = 0.002 * 6.4;
// The HDR maps' scale solved from the matte box against the true one (measured −3.1 %; −13.3 %
// when the ceiling was unseen).
constexpr double kSolvedScaleTolerance = 0.06;

double Seconds(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

TEST(RunDemoE2eTest, RecoversTruthResumesAndReportLoads) {
  const fs::path dir = test::UniqueTempDir("igi_run_demo");
  const fs::path out = dir / "demo";
  const std::string args = "--demo --out " + Quote(out.string()) +
                           " --skip-diagnose --threads 2 --demo-cameras 16 --demo-width 480"
                           " --demo-height 360 --demo-spp 8";
  auto t0 = std::chrono::steady_clock::now();
  auto r = RunTool("igi-run", args);
  std::printf("demo: %.0f s\n%s", Seconds(t0), r.out.c_str());
  ASSERT_TRUE(r.exit_code == 0 || r.exit_code == 3) << r.err;

  // Parameters against the truth.
  const Json summary = ReadJsonFile(out / "demo_summary.json");
  const double k = summary["photometric_scale_k"].get<double>();
  EXPECT_GT(k, 0.0);
  std::map<std::string, std::string> status;
  std::map<std::string, double> observations;
  std::map<std::string, Json> paper;
  double all_observations = 0;
  const Json report = ReadJsonFile(out / "04-solve" / "report.json");  // kept alive for the loop
  for (const Json& g : report.at("regions")) {
    const std::string name = g.at("name").get<std::string>();
    status[name] = g.contains("status") ? g.at("status").get<std::string>() : "";
    observations[name] = g.value("observations", 0.0);
    all_observations += observations[name];
    if (g.contains("paper")) paper[name] = g["paper"];
  }
  int checked = 0;
  for (const Json& region : summary["regions"]) {
    const std::string name = region["region"].get<std::string>();
    if (status[name] == "unobserved") continue;
    // A region seen in a sliver of one photo (measured: the ceiling at the edge of the close-up
    // posed from its markers, +22 %) is solved but not held to the bounds; printed.
    if (observations[name] < 0.02 * all_observations) {
      std::printf("not compared: %s (%.0f observations of %.0f)\n", name.c_str(),
                  observations[name], all_observations);
      continue;
    }
    auto check = [&](const char* key, double tol) {
      if (!region.contains(key)) return;
      if (status[name] == "no_highlight" && std::string(key) != "rho_d") return;
      // A lobe the solver itself reports as undetermined (relative sigma over 10 %; measured:
      // wall_y4's highlight at a photo's edge, rho_s +102 %) is printed, not held to the bounds.
      const std::string sigma_key = std::string("sigma_") + key;
      const Json value = paper[name].value(key, Json());
      const Json first = value.is_array() && !value.empty() ? value[0] : value;
      if (std::string(key) != "rho_d" && paper[name].contains(sigma_key) &&
          paper[name][sigma_key].is_number() && first.is_number()) {
        const double v = first.get<double>();
        const double sigma = paper[name][sigma_key].get<double>();
        if (v > 0 && sigma > 0.1 * v) {
          std::printf("not compared: %s %s (sigma %.3g of %.3g)\n", name.c_str(), key, sigma, v);
          return;
        }
      }
      const double e = region[key]["relative_error"].get<double>();
      EXPECT_LT(std::abs(e), tol) << name << " " << key;
      ++checked;
    };
    check("rho_d", kRhoDTolerance);
    check("rho_s", kRhoSTolerance);
    check("alpha", kAlphaTolerance);
  }
  EXPECT_GE(checked, 10);

  // The ceiling seen and solved (not a placeholder): a region with its own observations, its
  // albedo near the truth.
  EXPECT_EQ(status["ceiling"], "solved");
  EXPECT_GE(observations["ceiling"], 0.02 * all_observations);
  bool ceiling_compared = false;
  for (const Json& region : summary["regions"]) {
    if (region["region"] != "ceiling" || !region.contains("rho_d")) continue;
    ceiling_compared = true;
    EXPECT_LT(std::abs(region["rho_d"]["relative_error"].get<double>()), kCeilingRhoDTolerance);
  }
  EXPECT_TRUE(ceiling_compared);

  // Every photo registered (the cameras that look up included), each pose near the truth.
  const Json& poses = summary.at("poses");
  EXPECT_EQ(poses["photos"].get<int>(), 20);  // 16 cameras + 4 looking up, one lighting
  EXPECT_EQ(poses["registered"], poses["photos"]);
  int looking_up = 0;
  for (const Json& c : poses["cameras"]) {
    looking_up += c["looks_up"].get<bool>();
    EXPECT_LT(c["rotation_error_deg"].get<double>(), kRotationToleranceDeg) << c["photo"];
    EXPECT_LT(c["position_error_m"].get<double>(), kPositionToleranceM) << c["photo"];
  }
  EXPECT_GE(looking_up, 4);

  // The photos' scale solved from the reference (the default calibration).
  ASSERT_EQ(summary["calibration"], "reference");
  ASSERT_TRUE(summary.contains("solved_radiance_scale_error"));
  EXPECT_LT(std::abs(summary["solved_radiance_scale_error"].get<double>()), kSolvedScaleTolerance);

  // Resume: 05-diagnose deleted; 00-04 kept (markers unchanged), 05-06 redone.
  std::map<std::string, std::string> markers;
  for (const char* s : {"00-capture", "01-response", "02-hdr", "03-register", "04-solve"}) {
    markers[s] = ReadFileToString(out / s / "stage.json");
  }
  fs::remove_all(out / "05-diagnose");
  t0 = std::chrono::steady_clock::now();
  r = RunTool("igi-run", args);
  std::printf("resumed run: %.0f s\n%s", Seconds(t0), r.out.c_str());
  ASSERT_TRUE(r.exit_code == 0 || r.exit_code == 3) << r.err;
  for (const auto& [s, text] : markers) {
    EXPECT_EQ(ReadFileToString(out / s / "stage.json"), text) << s << " was redone";
  }
  for (const char* s : {"00-capture", "01-response", "02-hdr", "03-register", "04-solve"}) {
    EXPECT_TRUE(std::regex_search(r.out, std::regex(std::string(s) + " +kept"))) << s << r.out;
  }
  EXPECT_TRUE(std::regex_search(r.out, std::regex("05-diagnose +skipped"))) << r.out;
  EXPECT_TRUE(std::regex_search(r.out, std::regex("06-report +(done|partial)"))) << r.out;
  EXPECT_TRUE(fs::exists(out / "05-diagnose" / "stage.json"));

  // The report in headless Chromium.
  const test::PageCheck page = test::CheckPageInChromium(out / "report.html", dir / "chromium");
  ASSERT_TRUE(page.chromium_found)
      << "chromium is not installed: the report test needs it (scripts/setup.sh installs it; "
         "Debian: apt-get install chromium)";
  EXPECT_TRUE(page.console_errors.empty()) << page.console_errors.front();
  // 4 photos x (photo, render, residual) + relit renders under L0 and L1.
  EXPECT_GE(page.image_widths.size(), 14u);
  for (size_t i = 0; i < page.image_widths.size(); ++i) {
    EXPECT_GT(page.image_widths[i], 0) << "image " << i << " not decoded";
  }
  const Image shot = ReadImage(page.screenshot, 3);
  double mean = 0, var = 0;
  for (float v : shot.pixels) mean += v;
  mean /= double(shot.pixels.size());
  for (float v : shot.pixels) var += (v - mean) * (v - mean);
  EXPECT_GT(std::sqrt(var / double(shot.pixels.size())), 0.05) << "blank screenshot";
  fs::remove_all(dir);
}

}  // namespace
}  // namespace igi
