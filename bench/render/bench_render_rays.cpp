// bench_render_rays: ray throughput of igi's path tracer (igi::Renderer) against a minimal path
// tracer on raw Embree (rtcIntersect1/rtcOccluded1) tracing the same kind and about the same
// number of rays on the same scene, same thread count, in the same process. Runs alternate
// (igi, raw, igi, raw, ...) so that load from other processes hits both alike; the medians are
// compared. "Rays" = closest-hit queries + shadow (any-hit) queries, on both sides.
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "bench/render/raw_embree_tracer.h"
#include "recon/scene.h"
#include "solver/render/render.h"
#include "tools/common/cli.h"
#include "tools/common/error.h"
#include "tools/common/parallel.h"

namespace {

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// Materials the scene leaves unknown (solver inputs) get a grey Lambertian value so that the
// scene renders; the benchmark is about rays, not appearance.
void CompleteMaterials(igi::recon::Scene* scene) {
  for (igi::recon::Material& m : scene->materials) {
    if (m.MissingForRendering().empty()) continue;
    m.brdf = igi::recon::BrdfModel::kLambert;
    m.rho_d = Eigen::Vector3d::Constant(0.5);
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Rays per second: igi's renderer vs raw Embree, same scene and run",
               "bench_render_rays"};
  igi::CommonFlags flags;
  igi::AddCommonFlags(app, &flags);
  std::string scene_path = std::string(IGI_SHARED_DATA_DIR) + "/reference/radiance_room/scene.json";
  std::string camera_name, lighting_name;
  int spp = 16, reps = 3;
  bool embree_spheres = false;
  std::string lobe;
  app.add_option("--scene", scene_path, "scene.json")->capture_default_str();
  app.add_option("--lobe", lobe,
                 "Every material with an isotropic lobe takes this model, its values kept (e.g. "
                 "ggx against ward_gmd: the lobe's cost in rays per second)");
  app.add_option("--camera", camera_name, "Camera (default: the first)");
  app.add_option("--lighting", lighting_name, "Lighting (default: the first)");
  app.add_option("--spp", spp, "Paths per pixel")->capture_default_str();
  app.add_option("--reps", reps, "Runs of each side (medians reported)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_flag("--embree-spheres", embree_spheres,
               "Raw side: sphere lights as Embree point-spheres in its scene (default: "
               "intersected analytically after rtcIntersect1, as igi does)");
  return igi::RunMain(app, flags, argc, argv, [&] {
    igi::recon::SceneLoadOptions load;
    load.check_images = false;
    igi::recon::Scene scene = igi::recon::LoadScene(scene_path, load);
    CompleteMaterials(&scene);
    if (!lobe.empty()) {
      const std::optional<igi::recon::BrdfModel> model = igi::recon::BrdfModelFromName(lobe);
      if (!model || !igi::recon::HasSpecularLobe(*model) || igi::recon::IsAnisotropic(*model)) {
        throw igi::InputError("--lobe " + lobe + ": must be an isotropic model with a lobe");
      }
      for (igi::recon::Material& m : scene.materials) {
        if (igi::recon::HasSpecularLobe(m.brdf) && !igi::recon::IsAnisotropic(m.brdf)) {
          m.brdf = *model;
        }
      }
    }
    const int camera = camera_name.empty() ? 0 : scene.FindCamera(camera_name);
    const int lighting = lighting_name.empty() ? 0 : scene.FindLighting(lighting_name);
    if (camera < 0 || lighting < 0) throw igi::InputError("unknown --camera or --lighting");
    const int threads = igi::ResolveThreads(flags.threads);

    const igi::render::Renderer renderer(scene, lighting);
    const igi::bench::RawEmbreeTracer raw(scene, lighting, embree_spheres);
    igi::render::RenderOptions options;
    options.spp = spp;
    options.num_threads = threads;
    options.show_progress = false;
    igi::bench::RawTraceOptions raw_options;
    raw_options.spp = spp;
    raw_options.num_threads = threads;
    raw_options.rr_start_bounce = options.rr_start_bounce;
    raw_options.max_bounces = options.max_bounces;

    std::printf("scene %s, camera %s, lighting %s: %zu triangles, %dx%d, %d spp, %d threads\n",
                scene_path.c_str(), scene.cameras[camera].name.c_str(),
                scene.lightings[lighting].name.c_str(), scene.mesh.num_triangles(),
                scene.cameras[camera].width, scene.cameras[camera].height, spp, threads);
    std::printf("%-4s %-6s %12s %10s %10s\n", "rep", "side", "rays", "seconds", "Mrays/s");
    std::vector<double> igi_rate, raw_rate;
    uint64_t igi_rays = 0, raw_rays = 0, raw_shadow = 0;
    for (int r = 0; r < reps; ++r) {
      igi::render::RenderSummary s;
      options.seed = uint64_t(r);
      renderer.Render(scene.cameras[camera], options, &s);
      igi_rate.push_back(s.RaysPerSecond());
      igi_rays = s.rays;
      std::printf("%-4d %-6s %12llu %10.3f %10.3f\n", r, "igi", (unsigned long long)s.rays,
                  s.seconds, s.RaysPerSecond() * 1e-6);
      raw_options.seed = uint64_t(r) + 1;
      const igi::bench::RawTraceSummary rs = raw.Trace(scene.cameras[camera], raw_options);
      raw_rate.push_back(rs.RaysPerSecond());
      raw_rays = rs.rays;
      raw_shadow = rs.shadow_rays;
      std::printf("%-4d %-6s %12llu %10.3f %10.3f\n", r, "embree", (unsigned long long)rs.rays,
                  rs.seconds, rs.RaysPerSecond() * 1e-6);
      std::fflush(stdout);
    }
    const double igi_median = Median(igi_rate), raw_median = Median(raw_rate);
    std::printf("rays per camera ray: igi %.3f, raw Embree %.3f (%.3f of them shadow rays)\n",
                double(igi_rays) /
                    (double(scene.cameras[camera].width) * scene.cameras[camera].height * spp),
                double(raw_rays) /
                    (double(scene.cameras[camera].width) * scene.cameras[camera].height * spp),
                double(raw_shadow) /
                    (double(scene.cameras[camera].width) * scene.cameras[camera].height * spp));
    std::vector<double> paired;  // each igi run against the raw run right after it
    double lo = 1e300, hi = 0;
    for (size_t i = 0; i < igi_rate.size(); ++i) {
      paired.push_back(igi_rate[i] / raw_rate[i]);
      lo = std::min(lo, paired.back());
      hi = std::max(hi, paired.back());
    }
    std::printf(
        "median Mrays/s: igi %.3f, raw Embree %.3f; igi/raw = %.1f %% (median of paired "
        "runs %.1f %%, min %.1f %%, max %.1f %%)\n",
        igi_median * 1e-6, raw_median * 1e-6, 100.0 * igi_median / raw_median,
        100.0 * Median(paired), 100.0 * lo, 100.0 * hi);
    return 0;
  });
}
