// Experiment (run by hand; figures in bench/RESULTS.md, "the floor's rho_s with 64-spp photos"):
// the igi-synth floor's stage-1 lobe fit taken apart against truth.
//   build/bench/floor_probe CAPTURE_DIR [noisy]   (synthesises CAPTURE_DIR when absent)
//   env: PROBE_SEED, PROBE_SPP (synthesis), PROBE_SEL (0: off-highlight test with the patch's
//        albedo, 1: the region's mean, 2: the true texture), PROBE_REF=1 (reference radiance and
//        irradiance of a subset of samples with many paths), PROBE_OUT (CSV of the fit samples).
// Prints the solver's floor rho_s / alpha, then rho_s at the true alpha by least squares over the
// fit samples with held-out albedos built from: A the solver's current lobe, B the true lobe, C
// the true texture times E (exact data: the texel blur only), per held-out texel size and
// off-highlight threshold; "joint": rho_s fitted through the held samples' lobe too.
#include <fmt/format.h>

#include <cstdio>
#include <filesystem>
#include <map>

#include "recon/scene.h"
#include "solver/inverse/held_out_albedo.h"
#include "solver/inverse/solve_internal.h"
#include "solver/inverse/texel_splat.h"
#include "solver/render/ray_scene.h"
#include "solver/render/render.h"
#include "solver/synth/synthesize.h"
#include "tools/common/json.h"
#include "tools/common/parallel.h"

using namespace igi;
namespace fs = std::filesystem;

int main(int argc, char** argv) {
  const fs::path dir = argc > 1 ? argv[1] : "/tmp/wts/clean";
  const bool noisy = argc > 2 && std::string(argv[2]) == "noisy";
  if (!fs::exists(dir / "scene.json")) {
    synth::SynthOptions so;
    so.out = dir;
    so.spp = std::getenv("PROBE_SPP") ? std::atoi(std::getenv("PROBE_SPP")) : 64;
    if (noisy) so.noise = synth::NoiseModel::kRealistic;
    if (std::getenv("PROBE_SEED")) so.seed = std::atoi(std::getenv("PROBE_SEED"));
    synth::Synthesize(so);
  }
  SetDefaultThreads(2);
  const recon::Scene scene = recon::LoadScene(dir / "scene.json");
  solver::SolveOptions options;
  options.refine_iterations = 0;
  options.num_threads = 2;
  if (const char* e = std::getenv("PROBE_HELD")) options.held_out_albedo = std::string(e) == "1";
  solver::SolverState s(scene, options);
  s.Prepare();
  s.GatherAll();
  s.RunStage1();
  const Json truth = ReadJsonFile(dir / "truth.json")["materials"];
  const int floor = scene.FindMaterial("floor");
  const Image tex = ReadImage(dir / truth["floor"]["rho_d_map"].get<std::string>(), 3);
  const double rs_true = truth["floor"]["rho_s"].get<double>();
  const double a_true = truth["floor"]["alpha"].get<double>();
  const solver::MaterialState& m = s.materials[floor];
  std::printf("sigma rho_s %.4f sigma alpha %.4f\n", m.last_fit.sigma_rho_s,
              m.last_fit.sigma_alpha);
  std::printf("texel %.4f m, floor fit rho_s %.4f (%+.1f %%) alpha %.4f (%+.1f %%) model %s\n",
              s.summary.texel_size_m, m.params.rho_s.mean(),
              100 * (m.params.rho_s.mean() / rs_true - 1), m.params.alpha,
              100 * (m.params.alpha / a_true - 1),
              std::string(solver::AlbedoModelName(m.last_fit.albedo_model)).c_str());
  // Held-out albedo variants: A as the solver (current params), B with the true lobe
  // subtracted and the true model deciding off-highlight, C the true texture times E (blur only).
  std::vector<Eigen::Vector3d> t_true(s.obs.size(), Eigen::Vector3d::Zero());
  for (size_t i = 0; i < s.obs.size(); ++i) {
    const solver::Observation& o = s.obs[i];
    if (o.region != floor) continue;
    const Eigen::Vector3d wo =
        s.materials.LocalFrame(floor, o.normal.cast<double>()).ToLocal(o.view.cast<double>());
    for (const solver::IncidentLocal& inc : s.light.incident[i]) {
      const double w = solver::LobeWeight(m.params.model, a_true, a_true, m.params.ior, wo,
                                          inc.Wi().cast<double>())
                           .scale;
      if (w > 0) t_true[i] += w * inc.Value().cast<double>();
    }
  }
  auto uv_of = [&](const solver::Observation& o) {
    const Eigen::Vector3i& t = scene.mesh.triangles[o.triangle];
    return Eigen::Vector2d(((1.0f - o.b1 - o.b2) * scene.mesh.uvs[t[0]] +
                            o.b1 * scene.mesh.uvs[t[1]] + o.b2 * scene.mesh.uvs[t[2]])
                               .cast<double>());
  };
  {
    // Per off-highlight sample: the albedo error pi(L - rs T)/E - R, by photo and by spec share.
    std::map<std::string, std::array<double, 3>> bins;
    for (size_t i = 0; i < s.obs.size(); ++i) {
      const solver::Observation& o = s.obs[i];
      if (o.region != floor) continue;
      const Eigen::Vector3d r = render::SampleTexture(tex, uv_of(o));
      const Eigen::Vector3d spec = rs_true * t_true[i];
      const double share =
          spec.mean() / (r.cwiseProduct(s.light.e[i]).mean() / render::kPi + spec.mean());
      const Eigen::Vector3d err =
          (render::kPi * (o.radiance.cast<double>() - spec)).cwiseQuotient(s.light.e[i]) - r;
      const int b = share < 0.01 ? 0 : share < 0.03 ? 1 : share < 0.1 ? 2 : share < 0.2 ? 3 : 4;
      for (std::string key :
           {fmt::format("photo {} share<{}", o.photo, b), fmt::format("all share<{}", b),
            fmt::format("photo {} fit {}", o.photo, int(s.obs.in_fit[i]))}) {
        auto& v = bins[key];
        v[0] += err.mean() * s.light.e[i].mean();
        v[1] += r.mean() * s.light.e[i].mean();
        v[2] += 1;
      }
    }
    for (const auto& [k, v] : bins)
      std::printf("%-22s n %6.0f  albedo error (E-weighted) %+.2f %%\n", k.c_str(), v[2],
                  100 * v[0] / v[1]);
  }
  if (std::getenv("PROBE_REF")) {
    // Reference radiance (pixel centre, many paths) and irradiance for a subset of floor samples.
    const recon::Scene truth_scene = recon::LoadScene(dir / "truth" / "scene.json");
    const render::Renderer ref(truth_scene, truth_scene.FindLighting("L0"));
    const render::RayScene& ls = *s.lighting_scenes[0];
    std::vector<size_t> subset;
    for (size_t i = 0; i < s.obs.size(); i += 13) {
      if (s.obs[i].region == floor) subset.push_back(i);
    }
    std::vector<std::array<double, 8>> res(subset.size());
    ParallelFor(
        0, int64_t(subset.size()),
        [&](int64_t k) {
          const size_t i = subset[k];
          const solver::Observation& o = s.obs[i];
          const recon::Camera& cam = scene.cameras[scene.photos[o.photo].camera];
          const Eigen::Vector3d c = cam.CenterInWorld();
          const Eigen::Vector3d dir = cam.WorldRayFromImg(
              Eigen::Vector2d(o.x + 0.5, std::min(o.y + 1, cam.height - 1) + 0.5));
          (void)dir;
          const Eigen::Vector3d dir2 = (o.position.cast<double>() - c).normalized();
          const Eigen::Vector3d lref = ref.Radiance(c, dir2, 4096, 77 + i);
          solver::GatherQuery q;
          q.position = o.position.cast<double>();
          const Eigen::Vector3d fn = scene.mesh.FaceNormal(o.triangle).cast<double>();
          q.n_geo = fn.dot(o.view.cast<double>()) >= 0 ? fn : -fn;
          q.n_s = o.normal.cast<double>();
          solver::PatchSet none;
          solver::GatherOptions go;
          go.light_samples = 1024;
          go.indirect_rays = 0;
          go.num_threads = 1;
          go.seed = 99 + i;
          (void)ls;
          const solver::GatherSet g = solver::Gather(ls, s.patches, {q}, go);
          Eigen::Vector3d eind = Eigen::Vector3d::Zero();
          render::Pcg32 rng(5 + i, 3);
          for (const solver::WeightedDirection& d :
               solver::HemisphereDirections(q, 2048, 0.2, rng)) {
            eind += d.weight * ref.ReflectedRadiance(q.position + q.n_geo * ls.ray_epsilon(), d.wi,
                                                     1, 1000 * i + 17);
          }
          const Eigen::Vector3d eref = g.points[0].e_direct.cast<double>() + eind;
          const Eigen::Vector3d r = render::SampleTexture(tex, uv_of(o));
          const Eigen::Vector3d model =
              r.cwiseProduct(s.light.e[i]) / render::kPi + rs_true * t_true[i];
          const Eigen::Vector3d model_ref =
              r.cwiseProduct(eref) / render::kPi + rs_true * t_true[i];
          res[k] = {lref.mean(),
                    model.mean(),
                    model_ref.mean(),
                    s.light.e[i].mean(),
                    eref.mean(),
                    s.light.e_direct[i].mean(),
                    double(g.points[0].e_direct.mean()),
                    (rs_true * t_true[i]).mean()};
        },
        2, 1);
    double sl = 0, sm = 0, smr = 0, se = 0, ser = 0, sd = 0, sdr = 0, sp = 0;
    for (const auto& v : res)
      sl += v[0], sm += v[1], smr += v[2], se += v[3], ser += v[4], sd += v[5], sdr += v[6],
          sp += v[7];
    std::printf(
        "reference over %zu floor samples: L_ref/model(gathered E) %.4f, L_ref/model(ref E) %.4f, "
        "E_gath/E_ref %.4f, Edir_gath/Edir_ref %.4f, spec share %.3f\n",
        res.size(), sl / sm, sl / smr, se / ser, sd / sdr, sp / sl);
    FILE* rf = std::fopen("/tmp/wts/ref.csv", "w");
    for (size_t k = 0; k < res.size(); ++k) {
      const solver::Observation& o = s.obs[subset[k]];
      std::fprintf(rf, "%d,%d,%d", o.photo, o.x, o.y);
      for (double x : res[k]) std::fprintf(rf, ",%g", x);
      std::fprintf(rf, ",%g\n", double(o.radiance.mean()));
    }
    std::fclose(rf);
  }
  struct Acc {
    Eigen::Vector3d n = Eigen::Vector3d::Zero(), d = n, l = n, e = n, t = n;
    double w = 0, wf = 0;
  };
  const int sel_mode = std::getenv("PROBE_SEL") ? std::atoi(std::getenv("PROBE_SEL")) : 0;
  for (double texel : {s.summary.texel_size_m}) {
    solver::AtlasOptions ao;
    ao.texel_size_m = texel;
    const solver::RegionAtlas atlas = solver::BuildRegionAtlas(scene.mesh, floor, ao);
    const int64_t nt = int64_t(atlas.width) * atlas.height;
    for (double thr : {0.1, 0.2, 0.3}) {
      std::string line = fmt::format("texel {:.4f} thr {:.2f}:", texel, thr);
      for (int var = 0; var < 3; ++var) {
        solver::HeldOutAlbedo held(atlas);
        std::unordered_map<int64_t, Acc> tot, per;
        for (size_t i = 0; i < s.obs.size(); ++i) {
          const solver::Observation& o = s.obs[i];
          if (o.region != floor) continue;
          const Eigen::Vector3d l = o.radiance.cast<double>();
          const Eigen::Vector3d spec =
              var == 0 ? Eigen::Vector3d(m.params.rho_s.cwiseProduct(s.light.t[i]))
                       : Eigen::Vector3d(rs_true * t_true[i]);
          const Eigen::Vector3d alb = sel_mode == 0   ? s.materials.PatchAlbedo(s.patches, o.patch)
                                      : sel_mode == 1 ? Eigen::Vector3d(m.params.rho_d)
                                                      : render::SampleTexture(tex, uv_of(o));
          const Eigen::Vector3d diffuse = alb.cwiseProduct(s.light.e[i]) / render::kPi;
          const bool off = !(spec.array() > thr * (diffuse + spec).array()).any();
          const Eigen::Vector3d numer =
              var == 2
                  ? Eigen::Vector3d(render::SampleTexture(tex, uv_of(o)).cwiseProduct(s.light.e[i]))
                  : Eigen::Vector3d(render::kPi * (l - spec));
          if (off) held.Add(o.photo, o.triangle, o.b1, o.b2, numer, s.light.e[i]);
          const solver::TexelSplat sp = solver::BilinearTexelSplat(atlas, o.triangle, o.b1, o.b2);
          for (int k = 0; k < 4; ++k) {
            const double w = sp.weight[k];
            if (!(w > 0)) continue;
            const int64_t key = int64_t(sp.y[k]) * atlas.width + sp.x[k];
            for (Acc* a : {&tot[key], &per[o.photo * nt + key]}) {
              if (off) a->n += w * numer, a->d += w * s.light.e[i], a->w += w;
              if (s.obs.in_fit[i]) {
                // the fit side: the observed radiance (var 2: the true texture's diffuse + true
                // lobe)
                const Eigen::Vector3d lv =
                    var == 2 ? Eigen::Vector3d(numer / render::kPi + rs_true * t_true[i]) : l;
                a->l += w * lv, a->e += w * s.light.e[i], a->t += w * t_true[i], a->wf += w;
              }
            }
          }
        }
        double num = 0, den = 0;
        for (size_t i = 0; i < s.obs.size(); ++i) {
          const solver::Observation& o = s.obs[i];
          if (o.region != floor || !s.obs.in_fit[i]) continue;
          const Eigen::Vector3d h = held.At(o.photo, o.triangle, o.b1, o.b2);
          if (!h.allFinite()) continue;
          const Eigen::Vector3d lv =
              var == 2 ? Eigen::Vector3d(
                             render::SampleTexture(tex, uv_of(o)).cwiseProduct(s.light.e[i]) /
                                 render::kPi +
                             rs_true * t_true[i])
                       : Eigen::Vector3d(o.radiance.cast<double>());
          for (int c = 0; c < 3; ++c) {
            num += (lv[c] - h[c] * s.light.e[i][c] / render::kPi) * t_true[i][c];
            den += t_true[i][c] * t_true[i][c];
          }
        }
        double num2 = 0, den2 = 0;
        int used = 0;
        for (const auto& [key, a] : per) {
          if (a.wf < 0.25) continue;
          const Acc& t = tot[key % nt];
          const double hw = t.w - a.w;
          if (hw < 0.5) continue;
          const Eigen::Vector3d hn = t.n - a.n, hd = t.d - a.d;
          if (!(hd.minCoeff() > 0)) continue;
          ++used;
          for (int c = 0; c < 3; ++c) {
            const double alb = hn[c] / hd[c];
            const double lbar = a.l[c] / a.wf, ebar = a.e[c] / a.wf, tbar = a.t[c] / a.wf;
            num2 += a.wf * (lbar - alb * ebar / render::kPi) * tbar;
            den2 += a.wf * tbar * tbar;
          }
        }
        if (var < 2) {
          // Joint: held albedo without the lobe (h0) and the held samples' lobe (tau per unit
          // rho_s).
          solver::HeldOutAlbedo h0(atlas), tau(atlas);
          for (size_t i = 0; i < s.obs.size(); ++i) {
            const solver::Observation& o = s.obs[i];
            if (o.region != floor) continue;
            const Eigen::Vector3d spec =
                var == 0 ? Eigen::Vector3d(m.params.rho_s.cwiseProduct(s.light.t[i]))
                         : Eigen::Vector3d(rs_true * t_true[i]);
            const Eigen::Vector3d alb =
                sel_mode == 0 ? s.materials.PatchAlbedo(s.patches, o.patch) : m.params.rho_d;
            const Eigen::Vector3d diffuse = alb.cwiseProduct(s.light.e[i]) / render::kPi;
            if ((spec.array() > thr * (diffuse + spec).array()).any()) continue;
            h0.Add(o.photo, o.triangle, o.b1, o.b2, render::kPi * o.radiance.cast<double>(),
                   s.light.e[i]);
            tau.Add(o.photo, o.triangle, o.b1, o.b2, render::kPi * t_true[i], s.light.e[i]);
          }
          double n3 = 0, d3 = 0;
          for (size_t i = 0; i < s.obs.size(); ++i) {
            const solver::Observation& o = s.obs[i];
            if (o.region != floor || !s.obs.in_fit[i]) continue;
            const Eigen::Vector3d h = h0.At(o.photo, o.triangle, o.b1, o.b2),
                                  tu = tau.At(o.photo, o.triangle, o.b1, o.b2);
            if (!h.allFinite() || !tu.allFinite()) continue;
            for (int c = 0; c < 3; ++c) {
              const double a = s.light.e[i][c] / render::kPi;
              const double u = o.radiance[c] - h[c] * a, v = t_true[i][c] - tu[c] * a;
              n3 += u * v, d3 += v * v;
            }
          }
          line += fmt::format("  joint {:+.1f} %", 100 * (n3 / d3 / rs_true - 1));
        }
        line +=
            fmt::format("  {}: point {:+.1f} % texel {:+.1f} % ({})", "ABC"[var],
                        100 * (num / den / rs_true - 1), 100 * (num2 / den2 / rs_true - 1), used);
      }
      std::printf("%s\n", line.c_str());
    }
  }
  // Dump the floor's fit samples.
  const char* out_path = std::getenv("PROBE_OUT");
  FILE* f = std::fopen(out_path ? out_path : "/tmp/wts/floor_samples.csv", "w");
  std::fprintf(f,
               "photo,x,y,u,v,L0,L1,L2,E0,E1,E2,T_true,T_fit,held0,held1,held2,true0,true1,"
               "true2,patch0,patch1,patch2,Edir0\n");
  for (size_t i = 0; i < s.obs.size(); ++i) {
    const solver::Observation& o = s.obs[i];
    if (o.region != floor || !s.obs.in_fit[i]) continue;
    const Eigen::Vector3i& t = scene.mesh.triangles[o.triangle];
    const Eigen::Vector2d uv = ((1.0f - o.b1 - o.b2) * scene.mesh.uvs[t[0]] +
                                o.b1 * scene.mesh.uvs[t[1]] + o.b2 * scene.mesh.uvs[t[2]])
                                   .cast<double>();
    const Eigen::Vector3d wo =
        s.materials.LocalFrame(floor, o.normal.cast<double>()).ToLocal(o.view.cast<double>());
    double tt = 0, tf = 0;
    for (const solver::IncidentLocal& inc : s.light.incident[i]) {
      const double w1 = solver::LobeWeight(m.params.model, a_true, a_true, m.params.ior, wo,
                                           inc.Wi().cast<double>())
                            .scale;
      const double w2 = solver::LobeWeight(m.params.model, m.params.alpha, m.params.alpha,
                                           m.params.ior, wo, inc.Wi().cast<double>())
                            .scale;
      if (w1 > 0) tt += w1 * inc.Value().cast<double>().mean();
      if (w2 > 0) tf += w2 * inc.Value().cast<double>().mean();
    }
    const Eigen::Vector3d tr = render::SampleTexture(tex, uv);
    const Eigen::Vector3d pa = s.materials.PatchAlbedo(s.patches, o.patch);
    const Eigen::Vector3d& h = s.materials.held_rho_d[i];
    std::fprintf(f, "%d,%d,%d,%.6f,%.6f,%g,%g,%g,%g,%g,%g,%g,%g,%g,%g,%g,%g,%g,%g,%g,%g,%g,%g\n",
                 o.photo, o.x, o.y, uv.x(), uv.y(), o.radiance[0], o.radiance[1], o.radiance[2],
                 s.light.e[i][0], s.light.e[i][1], s.light.e[i][2], tt, tf, h[0], h[1], h[2], tr[0],
                 tr[1], tr[2], pa[0], pa[1], pa[2], s.light.e_direct[i].mean());
  }
  std::fclose(f);
  return 0;
}
