// bench_solve_truth CAPTURE [key=value ...]: solves an igi-synth capture (CAPTURE/scene.json)
// and prints every solved region's stage-1 and final ρd, ρs, α against CAPTURE/truth.json
// (relative errors, %), and each albedo map's PSNR against the true texture over all texels and
// over the texels some photo sees. Keys: threads, stride, texel (m), refine, held (0/1), rays,
// step, bounce (0/1), smooth (m), acc (smoothing_accuracy), joint (0/1/2: independent, joint,
// joint_albedo), refine_rays (stage 2's path-traced directions per observation), seed, dump;
// spp is not a key (the capture's). For experiments on the solver's accuracy; not a test.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>

#include "recon/scene.h"
#include "solver/inverse/albedo_map.h"
#include "solver/inverse/solve.h"
#include "solver/render/ray_scene.h"
#include "tools/common/image.h"
#include "tools/common/json.h"
#include "tools/common/strings.h"

namespace fs = std::filesystem;

// The estimate resampled at the truth's texels, the truth, and (estimate − truth)·10 + 0.5 (grey
// where equal, black where unseen), as PNGs in the current folder; prints the mean difference.
void DumpComparison(const igi::Image& mine, const igi::Image& seen, const igi::Image& want) {
  igi::Image est(want.width, want.height, 3), err(want.width, want.height, 3);
  double bias = 0;
  int n = 0;
  for (int y = 0; y < want.height; ++y) {
    for (int x = 0; x < want.width; ++x) {
      const Eigen::Vector2d uv((x + 0.5) / want.width, 1.0 - (y + 0.5) / want.height);
      const Eigen::Vector3d v = igi::render::SampleTexture(mine, uv);
      const double s = igi::render::SampleTexture(seen, uv)[0];
      for (int c = 0; c < 3; ++c) {
        est.at(x, y, c) = float(v[c]);
        const double d = v[c] - want.at(x, y, c);
        err.at(x, y, c) = s >= 1 ? float(std::clamp(0.5 + 10 * d, 0.0, 1.0)) : 0.f;
        if (s >= 1) bias += d, ++n;
      }
    }
  }
  std::printf("mean difference over the seen texels %+.4f\n", bias / std::max(1, n));
  igi::WriteImage("bench_solve_truth_estimate.png", est);
  igi::WriteImage("bench_solve_truth_truth.png", want);
  igi::WriteImage("bench_solve_truth_error.png", err);
}

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr,
                 "usage: bench_solve_truth CAPTURE [threads=2 stride=2 texel=0 refine=1 held=1 "
                 "high=100000]\n");
    return 2;
  }
  const fs::path capture = argv[1];
  igi::solver::SolveOptions o;
  o.num_threads = 2;
  o.refine_iterations = 1;
  o.show_progress = false;
  bool dump = false;  // dump=1: writes bench_solve_truth_{estimate,truth,error}.png in the cwd
  for (int i = 2; i < argc; ++i) {
    const std::string arg = argv[i];
    const size_t eq = arg.find('=');
    const std::string key = arg.substr(0, eq);
    const double v = std::stod(arg.substr(eq + 1));
    if (key == "threads")
      o.num_threads = int(v);
    else if (key == "stride")
      o.pixel_stride = int(v);
    else if (key == "texel")
      o.texel_size_m = v;
    else if (key == "refine")
      o.refine_iterations = int(v);
    else if (key == "held")
      o.held_out_albedo = v != 0;
    else if (key == "high")  // SolveOptions::max_highlight_samples
      o.max_highlight_samples = int(v);
    else if (key == "rays")
      o.indirect_rays = int(v);
    else if (key == "refine_rays")
      o.refine_rays = int(v);
    else if (key == "final_rays")
      o.refine_final_rays = int(v);
    else if (key == "seed")
      o.seed = uint64_t(v);
    else if (key == "dump")
      dump = v != 0;
    else if (key == "step")
      o.refine_albedo_step = v;
    else if (key == "joint")  // 1: refine_update kJoint, 2: kJointAlbedo, 0: kIndependent
      o.refine_update = v == 2   ? igi::solver::RefineUpdate::kJointAlbedo
                        : v != 0 ? igi::solver::RefineUpdate::kJoint
                                 : igi::solver::RefineUpdate::kIndependent;
    else if (key == "bounce")
      o.specular_bounces = v != 0;
    else if (key == "smooth")
      o.smoothing_radius_m = v;
    else if (key == "acc")  // adaptive smoothing's factor (SolveOptions::smoothing_accuracy)
      o.smoothing_accuracy = v;
    else {
      std::fprintf(stderr, "unknown key %s\n", key.c_str());
      return 2;
    }
  }
  const auto start = std::chrono::steady_clock::now();
  const igi::recon::Scene scene = igi::recon::LoadScene(capture / "scene.json");
  const fs::path out =
      fs::temp_directory_path() / ("bench_solve_truth_" + std::to_string(::getpid()));
  const igi::solver::SolveSummary s = igi::solver::Solve(scene, o, out);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const igi::Json truth = igi::ReadJsonFile(capture / "truth.json")["materials"];
  auto rel = [](double a, double b) { return 100.0 * (a - b) / b; };
  std::printf("solved in %.1f s, texel %.4f m\n", seconds, s.texel_size_m);
  std::printf("%-14s %-6s %7s %7s %7s %7s %7s  %s\n", "region", "stage", "rd_r%", "rd_g%", "rd_b%",
              "rs%", "a%", "albedo");
  for (const igi::solver::RegionSolution& r : s.regions) {
    if (r.status != igi::solver::RegionStatus::kSolved || !truth.contains(r.name)) continue;
    const igi::Json& t = truth[r.name];
    for (int stage = 1; stage <= 2; ++stage) {
      const igi::solver::RegionFitResult& f = stage == 1 ? r.stage1 : r.stage2;
      std::printf("%-14s %-6d", r.name.c_str(), stage);
      for (int c = 0; c < 3; ++c)
        std::printf(" %+7.2f", rel(f.rho_d[c], t["rho_d"][c].get<double>()));
      if (t.contains("rho_s")) {
        std::printf(" %+7.2f %+7.2f", rel(f.rho_s.mean(), t["rho_s"].get<double>()),
                    rel(f.alpha, t["alpha"].get<double>()));
      } else {
        std::printf(" %7s %7s", "", "");
      }
      std::printf("  %s", std::string(igi::solver::AlbedoModelName(f.albedo_model)).c_str());
      if (stage == 2) std::printf("  %d obs", r.observations);
      std::printf("\n");
    }
    if (r.albedo_map && t.contains("rho_d_map")) {
      const igi::Image want = igi::ReadImage(capture / t["rho_d_map"].get<std::string>(), 3);
      double peak = 0;
      for (float v : want.pixels) peak = std::max(peak, double(v));
      const igi::solver::AlbedoComparison all =
          igi::solver::CompareAlbedoMaps(*r.albedo_map, nullptr, want, peak);
      const igi::solver::AlbedoComparison seen =
          igi::solver::CompareAlbedoMaps(*r.albedo_map, &*r.albedo_map_seen, want, peak);
      if (dump) DumpComparison(*r.albedo_map, *r.albedo_map_seen, want);
      {  // region means over the texels some photo sees (area means: the floor's UVs are affine)
        Eigen::Vector3d sum_t = Eigen::Vector3d::Zero(), sum_e = sum_t;
        int n = 0;
        for (int y = 0; y < want.height; ++y) {
          for (int x = 0; x < want.width; ++x) {
            const Eigen::Vector2d uv((x + 0.5) / want.width, 1.0 - (y + 0.5) / want.height);
            if (igi::render::SampleTexture(*r.albedo_map_seen, uv)[0] < 1) continue;
            sum_e += igi::render::SampleTexture(*r.albedo_map, uv);
            for (int c = 0; c < 3; ++c) sum_t[c] += want.at(x, y, c);
            ++n;
          }
        }
        const Eigen::Vector3d mt = sum_t / n, me = sum_e / n;
        const Eigen::Vector3d full(t["rho_d"][0].get<double>(), t["rho_d"][1].get<double>(),
                                   t["rho_d"][2].get<double>());
        std::printf(
            "%s over the seen texels: true mean %+.2f %% of the whole texture's, map mean "
            "%+.2f %%, fit's rho_d %+.2f %% of the seen true mean\n",
            r.name.c_str(), 100 * (mt.mean() / full.mean() - 1), 100 * (me.mean() / mt.mean() - 1),
            100 * (r.stage1.rho_d.mean() / mt.mean() - 1));
        // The truth over the texels SeenTexelMean takes.
        const Eigen::Vector3d mn = igi::solver::TextureMeanOverSeenTexels(want, *r.albedo_map_seen);
        std::printf(
            "%s: scene.json's rho_d %+.2f %+.2f %+.2f %% of the truth over the map's seen texels\n",
            r.name.c_str(), rel(r.final_params.rho_d[0], mn[0]),
            rel(r.final_params.rho_d[1], mn[1]), rel(r.final_params.rho_d[2], mn[2]));
        std::printf("%s: scene.json's rho_d (%s) %+.2f %+.2f %+.2f %% of the seen true mean\n",
                    r.name.c_str(), r.rho_d_from_map ? "the map's seen mean" : "the fit's",
                    rel(r.final_params.rho_d[0], mt[0]), rel(r.final_params.rho_d[1], mt[1]),
                    rel(r.final_params.rho_d[2], mt[2]));
      }
      for (int r_erode : {2, 4}) {  // away from unseen texels and the region's border
        igi::Image eroded = *r.albedo_map_seen;
        const igi::Image& m = *r.albedo_map_seen;
        for (int y = 0; y < m.height; ++y) {
          for (int x = 0; x < m.width; ++x) {
            bool ok = true;
            for (int dy = -r_erode; dy <= r_erode && ok; ++dy) {
              for (int dx = -r_erode; dx <= r_erode && ok; ++dx) {
                const int xi = x + dx, yi = y + dy;
                ok = xi >= 0 && yi >= 0 && xi < m.width && yi < m.height && m.at(xi, yi, 0) > 0.5f;
              }
            }
            eroded.at(x, y, 0) = ok ? 1.f : 0.f;
          }
        }
        const igi::solver::AlbedoComparison e =
            igi::solver::CompareAlbedoMaps(*r.albedo_map, &eroded, want, peak);
        std::printf(
            "  %d texels away from unseen texels and the border: PSNR %.2f dB over %.0f %%\n",
            r_erode, e.psnr_db, 100 * e.compared);
      }
      std::printf(
          "%s albedo map %dx%d: PSNR %.2f dB (all), %.2f dB over the %.0f %% seen "
          "(rms %.4f, peak %.3f)\n",
          r.name.c_str(), r.albedo_map->width, r.albedo_map->height, all.psnr_db, seen.psnr_db,
          100 * seen.compared, seen.rms, peak);
    }
  }
  std::error_code ec;
  fs::remove_all(out, ec);
  return 0;
}
