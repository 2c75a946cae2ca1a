// bench_solve_truth CAPTURE [key=value ...]: solves an igi-synth capture (CAPTURE/scene.json)
// and prints every solved region's stage-1 and final ρd, ρs, α against CAPTURE/truth.json
// (relative errors, %), and each albedo map's PSNR against the true texture over all texels and
// over the texels some photo sees. Keys: threads, stride, texel (m), refine, held (0/1), spp
// is not a key (the capture's). For issue 7's experiments; not a test.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>

#include "recon/scene.h"
#include "solver/albedo_map.h"
#include "solver/solve.h"
#include "tools/common/image.h"
#include "tools/common/json.h"
#include "tools/common/strings.h"

namespace fs = std::filesystem;

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: bench_solve_truth CAPTURE [threads=2 stride=2 texel=0 refine=1 held=1]\n");
    return 2;
  }
  const fs::path capture = argv[1];
  igi::SolveOptions o;
  o.num_threads = 2;
  o.refine_iterations = 1;
  o.show_progress = false;
  for (int i = 2; i < argc; ++i) {
    const std::string arg = argv[i];
    const size_t eq = arg.find('=');
    const std::string key = arg.substr(0, eq);
    const double v = std::stod(arg.substr(eq + 1));
    if (key == "threads") o.num_threads = int(v);
    else if (key == "stride") o.pixel_stride = int(v);
    else if (key == "texel") o.texel_size_m = v;
    else if (key == "refine") o.refine_iterations = int(v);
    else if (key == "held") o.held_out_albedo = v != 0;
    else if (key == "rays") o.indirect_rays = int(v);
    else {
      std::fprintf(stderr, "unknown key %s\n", key.c_str());
      return 2;
    }
  }
  const auto start = std::chrono::steady_clock::now();
  const igi::Scene scene = igi::LoadScene(capture / "scene.json");
  const fs::path out = fs::temp_directory_path() / ("bench_solve_truth_" + std::to_string(::getpid()));
  const igi::SolveSummary s = igi::Solve(scene, o, out);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const igi::Json truth = igi::ReadJsonFile(capture / "truth.json")["materials"];
  auto rel = [](double a, double b) { return 100.0 * (a - b) / b; };
  std::printf("solved in %.1f s, texel %.4f m\n", seconds, s.texel_size_m);
  std::printf("%-14s %-6s %7s %7s %7s %7s %7s  %s\n", "region", "stage", "rd_r%", "rd_g%", "rd_b%",
              "rs%", "a%", "albedo");
  for (const igi::RegionSolution& r : s.regions) {
    if (r.status != "solved" || !truth.contains(r.name)) continue;
    const igi::Json& t = truth[r.name];
    for (int stage = 1; stage <= 2; ++stage) {
      const igi::RegionFitResult& f = stage == 1 ? r.stage1 : r.stage2;
      std::printf("%-14s %-6d", r.name.c_str(), stage);
      for (int c = 0; c < 3; ++c) std::printf(" %+7.2f", rel(f.rho_d[c], t["rho_d"][c].get<double>()));
      if (t.contains("rho_s")) {
        std::printf(" %+7.2f %+7.2f", rel(f.rho_s.mean(), t["rho_s"].get<double>()),
                    rel(f.alpha, t["alpha"].get<double>()));
      } else {
        std::printf(" %7s %7s", "", "");
      }
      std::printf("  %s\n", f.albedo_model.c_str());
    }
    if (r.albedo_map && t.contains("rho_d_map")) {
      const igi::Image want = igi::ReadImage(capture / t["rho_d_map"].get<std::string>(), 3);
      double peak = 0;
      for (float v : want.pixels) peak = std::max(peak, double(v));
      const igi::AlbedoComparison all = igi::CompareAlbedoMaps(*r.albedo_map, nullptr, want, peak);
      const igi::AlbedoComparison seen =
          igi::CompareAlbedoMaps(*r.albedo_map, &*r.albedo_map_seen, want, peak);
      std::printf("%s albedo map %dx%d: PSNR %.2f dB (all), %.2f dB over the %.0f %% seen "
                  "(rms %.4f, peak %.3f)\n",
                  r.name.c_str(), r.albedo_map->width, r.albedo_map->height, all.psnr_db,
                  seen.psnr_db, 100 * seen.compared, seen.rms, peak);
    }
  }
  std::error_code ec;
  fs::remove_all(out, ec);
  return 0;
}
