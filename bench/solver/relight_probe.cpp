// Experiment (run by hand; figures in bench/RESULTS.md): where the relit (L1) error of the solved
// igi-synth room sits, as solve_truth_test measures it (cam0, 8x8-pixel blocks), per region.
//   build/bench/relight_probe CAPTURE_DIR OUT_DIR   env: PROBE_HELD=0/1 (held_out_albedo),
//   PROBE_REFINE=N (refinement rounds, default 1), PROBE_BOUNCE=0/1 (specular_bounces),
//   PROBE_STEP=S (refine_albedo_step), PROBE_UPDATE=joint|independent (refine_update),
//   PROBE_RAYS=N (refine_rays), PROBE_SEED=N (the solver's seed),
//   PROBE_REUSE=1 (render OUT_DIR/scene.json without solving again), PROBE_TEXEL=M (texel_size_m),
//   PROBE_STRIDE=N (pixel_stride)
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>

#include "recon/scene.h"
#include "solver/inverse/solve.h"
#include "solver/render/ray_scene.h"
#include "solver/render/render.h"
#include "tools/common/json.h"
#include "tools/common/parallel.h"

using namespace igi;
namespace fs = std::filesystem;

int main(int argc, char** argv) {
  const fs::path dir = argv[1];
  const fs::path out = argv[2];
  SetDefaultThreads(2);
  const recon::Scene scene = recon::LoadScene(dir / "scene.json");
  solver::SolveOptions o;
  o.refine_iterations = 1;
  o.num_threads = 2;
  o.show_progress = false;
  if (const char* e = std::getenv("PROBE_HELD")) o.held_out_albedo = std::string(e) == "1";
  if (const char* e = std::getenv("PROBE_REFINE")) o.refine_iterations = std::atoi(e);
  if (const char* e = std::getenv("PROBE_BOUNCE")) o.specular_bounces = std::string(e) == "1";
  if (const char* e = std::getenv("PROBE_STEP")) o.refine_albedo_step = std::atof(e);
  if (const char* e = std::getenv("PROBE_UPDATE"))
    o.refine_update = solver::RefineUpdateFromName(e).value();
  if (const char* e = std::getenv("PROBE_RAYS")) o.refine_rays = std::atoi(e);
  if (const char* e = std::getenv("PROBE_SEED")) o.seed = std::strtoull(e, nullptr, 10);
  if (const char* e = std::getenv("PROBE_TEXEL")) o.texel_size_m = std::atof(e);
  if (const char* e = std::getenv("PROBE_STRIDE")) o.pixel_stride = std::atoi(e);
  const bool reuse = std::getenv("PROBE_REUSE") != nullptr && fs::exists(out / "scene.json");
  if (!reuse) {
    const solver::SolveSummary s = solver::Solve(scene, o, out);
    solver::WriteSolveOutputs(s, o, out);
    for (const solver::RegionSolution& r : s.regions) {
      std::printf(
          "%-14s stage1 rho_d %.4f %.4f %.4f rho_s %.4f alpha %.4f | stage2 rho_d %.4f %.4f %.4f "
          "rho_s %.4f alpha %.4f\n",
          r.name.c_str(), r.stage1.rho_d[0], r.stage1.rho_d[1], r.stage1.rho_d[2],
          r.stage1.rho_s.mean(), r.stage1.alpha, r.stage2.rho_d[0], r.stage2.rho_d[1],
          r.stage2.rho_d[2], r.stage2.rho_s.mean(), r.stage2.alpha);
    }
  }
  const recon::Scene solved = recon::LoadScene(out / "scene.json");
  const recon::Scene true_scene = recon::LoadScene(dir / "truth" / "scene.json");
  render::Renderer model(solved, solved.FindLighting("L1"));
  render::Renderer reference(true_scene, true_scene.FindLighting("L1"));
  render::RenderOptions ro;
  ro.spp = 64;
  ro.show_progress = false;
  ro.seed = 101;
  const recon::Camera& cam = solved.cameras[solved.FindCamera("cam0")];
  const Image validation = ReadImage(dir / "validation" / "cam0_L1.exr", 3);
  const Image mine = model.Render(cam, ro);
  const Image again = reference.Render(true_scene.cameras[true_scene.FindCamera("cam0")], ro);
  // Region of each block's centre pixel.
  const render::RayScene geo(true_scene, 0);
  std::map<std::string, std::array<double, 5>> per;  // err², floor², signed err, want, count
  double num = 0, num_f = 0, den = 0;
  for (int by = 0; by + 8 <= validation.height; by += 8) {
    for (int bx = 0; bx + 8 <= validation.width; bx += 8) {
      const std::optional<render::SurfaceHit> hit = geo.TraceSurface(
          cam.CenterInWorld(), cam.WorldRayFromImg(Eigen::Vector2d(bx + 4, by + 4)));
      const std::string name = hit ? true_scene.materials[hit->region].name : "none";
      for (int c = 0; c < 3; ++c) {
        double w = 0, g = 0, a = 0;
        for (int y = by; y < by + 8; ++y) {
          for (int x = bx; x < bx + 8; ++x) {
            w += validation.at(x, y, c) / 64.0;
            g += mine.at(x, y, c) / 64.0;
            a += again.at(x, y, c) / 64.0;
          }
        }
        auto& v = per[name];
        v[0] += (g - w) * (g - w), v[1] += (a - w) * (a - w), v[2] += g - w, v[3] += w, v[4] += 1;
        num += (g - w) * (g - w), num_f += (a - w) * (a - w), den += w * w;
      }
    }
  }
  std::printf("relit cam0/L1: model %.4f floor %.4f beyond %.4f\n", std::sqrt(num / den),
              std::sqrt(num_f / den), std::sqrt(std::max(0.0, num - num_f) / den));
  for (const auto& [name, v] : per) {
    std::printf(
        "  %-14s blocks %4.0f  share of err² %5.1f %% (floor's %5.1f %%)  mean signed err %+.2f "
        "%%\n",
        name.c_str(), v[4] / 3, 100 * v[0] / num, 100 * v[1] / num_f, 100 * v[2] / v[3]);
  }
  return 0;
}
