// Experiment (run by hand; figures in bench/RESULTS.md, "The ceiling's +1.5 % on converged
// photos"): where a region's stage-1 albedo bias comes from, against the true scene.
//   build/bench/ceiling_probe CAPTURE [region=ceiling] [stride=2] [every=4] [ref_rays=1024]
//       [paths=8] [pixel_paths=256] [spec_rays=32] [smooth=0] [patch=0] [bounce=1]
//       [stage2=0] [seed2=1] [round=1] [variants=REGION,REGION...] [model_maps=DIR]
// Runs stage 1 on an igi-synth capture (2 threads; smooth, patch: SolveOptions' smoothing radius
// and patch size, 0 = auto; bounce: SolveOptions::specular_bounces) and, for every `every`-th
// observation of `region`, compares:
//  (a) the gathered irradiance (direct; indirect raw and smoothed) with a reference irradiance of
//      the TRUE scene (truth/scene.json) at the same point: `ref_rays` cosine-weighted rays, each
//      the true reflected radiance (one path);
//  (b) on the gather's own indirect rays: the radiance the solver takes for the patch each ray
//      hits (the photos' mean over the patch's observations, or ρd·E/π where no photo sees it)
//      against the true reflected radiance along the same ray (`paths` paths), split by the hit
//      region and by how many observations the hit patch has; "+spec_ind": with the glossy hit's
//      true specular reflection of the indirect light added (`spec_rays` lobe rays, 0 = off);
//      and the irradiance at the centres of the unseen patches the rays meet against a reference;
//  (d) the photo's pixel against ρd_true·E_ref/π at the pixel centre's point, against a
//      `pixel_paths`-path render of the true scene through the pixel centre, and against one
//      box-filtered over the pixel (4×4 strata, as a photo records; per channel, with the
//      standard error of the ratio from the rows' scatter);
//  (e) stage2=N > 0: stage 2's gathering (SolverState::IncidentFromRenderer, N rays, seed seed2,
//      refinement round `round`) over the true scene and over the stage-1 model, against the same
//      reference, with the five observations whose gathered E_ind is the largest multiple of
//      their reference (a firefly shows as one far above the rest); per region named in
//      `variants`, also the model with that region as the truth has it (and without its map).
// Prints the ratios and the albedo πΣL/ΣE with each irradiance. model_maps=DIR: only writes the
// stage-1 model's albedo maps (those the refinement renders) into DIR.
#include <fmt/format.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <map>
#include <string>

#include "recon/scene.h"
#include "solver/inverse/refine_stage.h"
#include "solver/inverse/solve_internal.h"
#include "solver/render/ray_scene.h"
#include "solver/render/render.h"
#include "tools/common/json.h"
#include "tools/common/parallel.h"

using namespace igi;
namespace fs = std::filesystem;

namespace {

struct Sum {
  Eigen::Vector3d a = Eigen::Vector3d::Zero(), b = Eigen::Vector3d::Zero();
  double n = 0;
  void Add(const Eigen::Vector3d& x, const Eigen::Vector3d& y) { a += x, b += y, n += 1; }
  double Ratio() const { return a.sum() / b.sum(); }
};

struct Row {
  Eigen::Vector3d e_dir, e_ind_raw, e_ind_smooth, e_ind_ref, l_photo, l_pixel_ref, l_pixel_box;
  std::map<std::string, Sum> by;  // key -> (Σ w·L_model, Σ w·L_true) on the gather's own rays
};

std::string Bucket(int count) {
  return count == 0 ? "unseen" : count < 4 ? "1-3 obs" : count < 16 ? "4-15 obs" : "16+ obs";
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr,
                 "usage: ceiling_probe CAPTURE [region= stride= every= ref_rays= paths=]\n");
    return 2;
  }
  const fs::path dir = argv[1];
  std::map<std::string, std::string> kv = {
      {"region", "ceiling"}, {"stride", "2"},        {"every", "4"},    {"ref_rays", "1024"},
      {"paths", "8"},        {"pixel_paths", "256"}, {"smooth", "0"},   {"patch", "0"},
      {"spec_rays", "32"},   {"bounce", "1"},        {"stage2", "0"},   {"seed2", "1"},
      {"round", "1"},        {"variants", ""},       {"model_maps", ""}};
  for (int i = 2; i < argc; ++i) {
    const std::string a = argv[i];
    const size_t eq = a.find('=');
    if (eq == std::string::npos || !kv.count(a.substr(0, eq))) {
      std::fprintf(stderr, "unknown argument %s\n", a.c_str());
      return 2;
    }
    kv[a.substr(0, eq)] = a.substr(eq + 1);
  }
  std::setvbuf(stdout, nullptr, _IOLBF, 0);  // each line as it is printed
  SetDefaultThreads(2);
  const recon::Scene scene = recon::LoadScene(dir / "scene.json");
  solver::SolveOptions options;
  options.refine_iterations = 0;
  options.num_threads = 2;
  options.show_progress = false;
  options.pixel_stride = std::stoi(kv["stride"]);
  options.smoothing_radius_m = std::stod(kv["smooth"]);
  options.patch_size_m = std::stod(kv["patch"]);
  options.specular_bounces = kv["bounce"] != "0";
  solver::SolverState s(scene, options);
  s.Prepare();
  s.GatherAll();
  s.RunStage1();
  if (!kv["model_maps"].empty()) {
    // The stage-1 model's albedo maps (the ones the refinement renders), into that folder.
    std::vector<solver::RegionAtlas> atlases;
    std::vector<Image> maps;
    fs::create_directories(kv["model_maps"]);
    const recon::Scene model = s.CompleteScene(&atlases, &maps, kv["model_maps"]);
    for (size_t r = 0; r < model.materials.size(); ++r) {
      if (!model.materials[r].rho_d_map) continue;
      std::printf("model map %s\n", model.materials[r].rho_d_map->c_str());
      // The region's observations of the largest red albedo πL/E: what makes a map's outliers.
      std::vector<std::pair<double, size_t>> top;
      for (size_t i = 0; i < s.obs.size(); ++i) {
        if (s.obs[i].region != int(r)) continue;
        top.emplace_back(render::kPi * s.obs[i].radiance[0] / s.light.e[i][0], i);
      }
      std::sort(top.rbegin(), top.rend());
      for (size_t k = 0; k < 8 && k < top.size(); ++k) {
        const size_t i = top[k].second;
        const solver::Observation& o = s.obs[i];
        std::printf(
            "  albedo %.2f photo %d px (%.0f, %.0f) size %d pos (%.3f %.3f %.3f) L (%.4g %.4g "
            "%.4g) "
            "E_dir (%.4g %.4g %.4g) E (%.4g %.4g %.4g)\n",
            top[k].first, o.photo, double(o.x), double(o.y), o.size, o.position.x(), o.position.y(),
            o.position.z(), o.radiance[0], o.radiance[1], o.radiance[2], s.light.e_direct[i][0],
            s.light.e_direct[i][1], s.light.e_direct[i][2], s.light.e[i][0], s.light.e[i][1],
            s.light.e[i][2]);
      }
    }
    return 0;
  }
  const int region = scene.FindMaterial(kv["region"]);
  const Json truth = ReadJsonFile(dir / "truth.json")["materials"];
  const Eigen::Vector3d rho_true(truth[kv["region"]]["rho_d"][0].get<double>(),
                                 truth[kv["region"]]["rho_d"][1].get<double>(),
                                 truth[kv["region"]]["rho_d"][2].get<double>());
  const Eigen::Vector3d rho_fit = s.materials[region].params.rho_d;
  std::printf(
      "%s: stage-1 rho_d %+.2f %+.2f %+.2f %% (%s), patch %.4f m\n", kv["region"].c_str(),
      100 * (rho_fit[0] / rho_true[0] - 1), 100 * (rho_fit[1] / rho_true[1] - 1),
      100 * (rho_fit[2] / rho_true[2] - 1),
      std::string(solver::AlbedoModelName(s.materials[region].last_fit.albedo_model)).c_str(),
      s.summary.patch_size_m);
  const recon::Scene truth_scene = recon::LoadScene(dir / "truth" / "scene.json");
  const int lighting = 0;
  const render::Renderer ref(truth_scene, lighting);
  const solver::LightingState& st = s.light.lightings[lighting];
  std::vector<int> count(s.patches.size(), 0);
  for (int i : st.obs) ++count[s.obs[i].patch];
  std::vector<int> subset;
  int seen = 0;
  for (int i : st.obs) {
    if (s.obs[i].region == region && seen++ % std::stoi(kv["every"]) == 0) subset.push_back(i);
  }
  const int ref_rays = std::stoi(kv["ref_rays"]), paths = std::stoi(kv["paths"]);
  const int pixel_paths = std::stoi(kv["pixel_paths"]);
  const int spec_rays = std::stoi(kv["spec_rays"]);
  std::vector<Row> rows(subset.size());
  const auto start = std::chrono::steady_clock::now();
  ParallelFor(
      0, int64_t(subset.size()),
      [&](int64_t k) {
        const int i = subset[k];
        const solver::Observation& o = s.obs[i];
        Row& row = rows[k];
        row.e_dir = s.light.e_direct[i];
        row.e_ind_raw = s.light.e_indirect[i];
        row.e_ind_smooth = s.light.e[i] - s.light.e_direct[i];
        row.l_photo = o.radiance.cast<double>();
        const double eps = s.lighting_scenes[lighting]->ray_epsilon();
        solver::GatherQuery q;
        q.position = o.position.cast<double>();
        const Eigen::Vector3d fn = scene.mesh.FaceNormal(o.triangle).cast<double>();
        q.n_geo = fn.dot(o.view.cast<double>()) >= 0 ? fn : -fn;
        q.n_s = o.normal.cast<double>();
        render::Pcg32 rng(1000 + i, 7);
        row.e_ind_ref.setZero();
        int ray = 0;
        for (const solver::WeightedDirection& d :
             solver::HemisphereDirections(q, ref_rays, 0.2, rng)) {
          row.e_ind_ref += d.weight * ref.ReflectedRadiance(q.position + q.n_geo * eps, d.wi, 1,
                                                            uint64_t(i) * 65536 + ray++);
        }
        const solver::GatherPoint& gp = st.gather.points[s.light.point[i]];
        for (int j = gp.indirect_begin; j < gp.indirect_end; ++j) {
          const solver::IndirectSample& is = st.gather.indirect[j];
          const Eigen::Vector3d wi = is.wi.cast<double>();
          const Eigen::Vector3d l_true =
              ref.ReflectedRadiance(q.position + q.n_geo * eps, wi, paths, uint64_t(j) * 977 + 5);
          const Eigen::Vector3d l_model =
              is.patch < 0 ? Eigen::Vector3d::Zero()
                           : solver::IndirectRadiance(s.patches, s.materials, st, is);
          const std::string hit =
              is.patch < 0 ? "none" : scene.materials[s.patches.patch_region[is.patch]].name;
          const std::string b = is.patch < 0 ? "none" : Bucket(count[is.patch]);
          // The glossy hit's specular reflection of the indirect light toward the point, which the
          // model's patch radiance leaves out: Σ over lobe directions of ρs·S·W·L_true.
          Eigen::Vector3d l_spec_ind = Eigen::Vector3d::Zero();
          if (is.patch >= 0) {
            const int hr = s.patches.patch_region[is.patch];
            const solver::MaterialState& hm = s.materials[hr];
            const std::optional<render::SurfaceHit> h =
                s.lighting_scenes[lighting]->TraceSurface(q.position + q.n_geo * eps, wi);
            if (h && recon::HasSpecularLobe(hm.params.model) && spec_rays > 0) {
              solver::GatherQuery hq;
              hq.position = h->position;
              hq.n_geo = h->n_geo;
              hq.n_s = h->n_s;
              hq.view = -wi;
              hq.lobe = true;
              const render::Frame frame = s.materials.LocalFrame(hr, h->n_s);
              const Eigen::Vector3d wo = frame.ToLocal(-wi);
              render::Pcg32 r2(j * 3 + 1, 11);
              int m = 0;
              for (const solver::WeightedDirection& d2 :
                   solver::HemisphereDirections(hq, spec_rays, 0.2, r2)) {
                const double sw =
                    solver::LobeWeight(hm.params.model, hm.params.AlphaX(), hm.params.AlphaY(),
                                       hm.params.ior, wo, frame.ToLocal(d2.wi))
                        .scale;
                if (!(sw > 0)) continue;
                l_spec_ind += sw * d2.weight *
                              ref.ReflectedRadiance(h->position + h->n_geo * eps, d2.wi, 1,
                                                    uint64_t(j) * 4099 + m++)
                                  .cwiseProduct(hm.params.rho_s);
              }
            }
          }
          row.by["+spec_ind all"].Add(is.weight * (l_model + l_spec_ind), is.weight * l_true);
          if (is.patch >= 0) {
            row.by["+spec_ind hit " + scene.materials[s.patches.patch_region[is.patch]].name].Add(
                is.weight * (l_model + l_spec_ind), is.weight * l_true);
          }
          row.by["all"].Add(is.weight * l_model, is.weight * l_true);
          row.by["hit " + hit + " " + b].Add(is.weight * l_model, is.weight * l_true);
          row.by["hit " + hit].Add(is.weight * l_model, is.weight * l_true);
          row.by["patch " + b].Add(is.weight * l_model, is.weight * l_true);
        }
        const recon::Camera& cam = scene.cameras[scene.photos[o.photo].camera];
        row.l_pixel_ref = ref.Radiance(cam.CenterInWorld(),
                                       cam.WorldRayFromImg(Eigen::Vector2d(o.x + 0.5, o.y + 0.5)),
                                       pixel_paths, uint64_t(i) * 31 + 3);
        // The same paths spread over the pixel (4×4 strata): the box filter a photo records.
        row.l_pixel_box.setZero();
        for (int cell = 0; cell < 16; ++cell) {
          const Eigen::Vector2d px(o.x + (cell % 4 + 0.5) / 4, o.y + (cell / 4 + 0.5) / 4);
          row.l_pixel_box += ref.Radiance(cam.CenterInWorld(), cam.WorldRayFromImg(px),
                                          std::max(1, pixel_paths / 16),
                                          uint64_t(i) * 31 + 5 + uint64_t(cell) * 7919) /
                             16.0;
        }
      },
      2, 1);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  // Totals, per photo and overall.
  std::map<std::string, std::array<Eigen::Vector3d, 7>> tot;
  std::map<std::string, Sum> rays;
  for (size_t k = 0; k < rows.size(); ++k) {
    const Row& r = rows[k];
    for (const std::string& key :
         {std::string("all"), fmt::format("photo {}", s.obs[subset[k]].photo)}) {
      auto it = tot.find(key);
      if (it == tot.end()) {
        std::array<Eigen::Vector3d, 7> zero;
        zero.fill(Eigen::Vector3d::Zero());
        it = tot.emplace(key, zero).first;
      }
      auto& t = it->second;
      const std::array<Eigen::Vector3d, 7> v = {r.e_dir,      r.e_ind_raw, r.e_ind_smooth,
                                                r.e_ind_ref,  r.l_photo,   r.l_pixel_ref,
                                                r.l_pixel_box};
      for (int c = 0; c < 7; ++c) t[c] += v[c];
    }
    for (const auto& [key, sum] : r.by) {
      Sum& a = rays[key];
      a.a += sum.a, a.b += sum.b, a.n += sum.n;
    }
  }
  std::printf("%zu samples (every %s-th of %d), %.1f s wall for the references\n", rows.size(),
              kv["every"].c_str(), seen, seconds);
  for (auto& [key, t] : tot) {
    const Eigen::Vector3d e_g = t[0] + t[2], e_ref = t[0] + t[3];
    const Eigen::Vector3d rho_g = render::kPi * t[4].cwiseQuotient(e_g);
    const Eigen::Vector3d rho_r = render::kPi * t[4].cwiseQuotient(e_ref);
    const Eigen::Vector3d rho_pix = render::kPi * t[5].cwiseQuotient(e_ref);
    std::printf(
        "%-8s E_dir/E %.3f | E_ind smoothed/ref %.4f raw/ref %.4f | E_gathered/E_ref %.4f | "
        "L_photo/L_pixel_ref %.4f | L_photo/(rho E_ref/pi) %.4f\n"
        "         rho = pi SumL/SumE: gathered E %+.2f %%, reference E %+.2f %%, pixel-ref L and "
        "ref E %+.2f %%\n",
        key.c_str(), t[0].sum() / e_ref.sum(), t[2].sum() / t[3].sum(), t[1].sum() / t[3].sum(),
        e_g.sum() / e_ref.sum(), t[4].sum() / t[5].sum(),
        t[4].sum() / (rho_true.cwiseProduct(e_ref) / render::kPi).sum(),
        100 * (rho_g.mean() / rho_true.mean() - 1), 100 * (rho_r.mean() / rho_true.mean() - 1),
        100 * (rho_pix.mean() / rho_true.mean() - 1));
    // The standard error of L_photo/L_pixel_box (both noisy renders) from the rows' scatter.
    Eigen::Vector3d se = Eigen::Vector3d::Zero();
    const Eigen::Vector3d ratio = t[4].cwiseQuotient(t[6]);
    for (size_t k = 0; k < rows.size(); ++k) {
      if (key != "all" && key != fmt::format("photo {}", s.obs[subset[k]].photo)) continue;
      const Eigen::Vector3d d = rows[k].l_photo - ratio.cwiseProduct(rows[k].l_pixel_box);
      se += d.cwiseProduct(d);
    }
    se = se.cwiseSqrt().cwiseQuotient(t[6]);
    std::printf("         L_photo/L_pixel_box standard error %.4f %.4f %.4f\n", se[0], se[1],
                se[2]);
    std::printf(
        "         per channel: L_photo/L_pixel_box %.4f %.4f %.4f | L_pixel_box/L_pixel_ref %.4f "
        "%.4f %.4f\n",
        t[4][0] / t[6][0], t[4][1] / t[6][1], t[4][2] / t[6][2], t[6][0] / t[5][0],
        t[6][1] / t[5][1], t[6][2] / t[5][2]);
  }
  if (kv["stage2"] != "0") {
    // (e) stage 2's gathering (the path tracer over a scene, RenderIncident in
    // solver/inverse/refine_stage.h) at the same points, over the true scene and over the stage-1
    // model the refinement renders.
    const fs::path tmp =
        fs::temp_directory_path() / ("ceiling_probe_" + std::to_string(::getpid()));
    fs::create_directories(tmp);
    std::vector<solver::RegionAtlas> atlases;
    std::vector<Image> maps;
    const recon::Scene model = s.CompleteScene(&atlases, &maps, tmp);
    s.options.refine_rays = std::stoi(kv["stage2"]);
    s.options.seed = std::stoull(kv["seed2"]);
    // The scenes rendered: the true scene, the stage-1 model, and the model with one region at a
    // time as the truth has it (which region's model sends the difference), or without its map.
    std::vector<std::pair<std::string, recon::Scene>> variants = {{"true scene", truth_scene},
                                                                  {"stage-1 model", model}};
    for (size_t r = 0; r < model.materials.size(); ++r) {
      if (kv["variants"].find(model.materials[r].name) == std::string::npos) continue;
      recon::Scene one = model;
      one.materials[r] = truth_scene.materials[r];
      variants.emplace_back("model, " + model.materials[r].name + " true", std::move(one));
      if (model.materials[r].rho_d_map) {
        recon::Scene flat = model;
        flat.materials[r].rho_d_map.reset();
        flat.materials[r].rho_d = s.materials[r].params.rho_d;
        variants.emplace_back("model, " + model.materials[r].name + " without its map",
                              std::move(flat));
      }
    }
    for (const auto& [name, scene_v] : variants) {
      solver::RenderIncident(s.Stage(), scene_v, s.RayEpsilons(), s.materials,
                             std::stoull(kv["round"]), &s.light);
      Eigen::Vector3d sum = Eigen::Vector3d::Zero(), ref_sum = sum;
      for (size_t k = 0; k < rows.size(); ++k) {
        sum += s.light.e_indirect[subset[k]];
        ref_sum += rows[k].e_ind_ref;
      }
      std::printf("stage 2's E_ind over the %s / reference (true scene): %.4f %.4f %.4f\n",
                  name.c_str(), sum[0] / ref_sum[0], sum[1] / ref_sum[1], sum[2] / ref_sum[2]);
    }
    std::error_code ec;
    fs::remove_all(tmp, ec);
  }
  std::printf("the gather's own rays: model radiance / true radiance (share of the true E_ind)\n");
  const double all_true = rays["all"].b.sum();
  for (const auto& [key, a] : rays) {
    std::printf("  %-22s %.4f  (%5.1f %%, %6.0f rays)\n", key.c_str(), a.Ratio(),
                100 * a.b.sum() / all_true, a.n);
  }
  // (b) the patches no photo sees that the point's rays meet: the solver's irradiance at their
  // centres (direct and indirect) against a reference of the true scene there.
  std::map<int, int> hits;
  for (int i : subset) {
    const solver::GatherPoint& gp = st.gather.points[s.light.point[i]];
    for (int j = gp.indirect_begin; j < gp.indirect_end; ++j) {
      const int q = st.gather.indirect[j].patch;
      if (q >= 0 && count[q] == 0) ++hits[q];
    }
  }
  std::vector<int> unseen;
  for (const auto& [q, n] : hits) unseen.push_back(q);
  std::vector<std::array<double, 5>> pe(unseen.size());
  const render::RayScene& ls = *s.lighting_scenes[lighting];
  ParallelFor(
      0, int64_t(unseen.size()),
      [&](int64_t k) {
        const int q = unseen[k];
        solver::GatherQuery gq;
        gq.position = s.patches.center[q].cast<double>();
        gq.n_geo = scene.mesh.FaceNormal(s.patches.patch_triangle[q]).cast<double>();
        gq.n_s = s.patches.normal[q].cast<double>();
        render::Pcg32 rng(77 + q, 9);
        Eigen::Vector3d e = Eigen::Vector3d::Zero();
        int ray = 0;
        for (const solver::WeightedDirection& d :
             solver::HemisphereDirections(gq, ref_rays, 0.2, rng)) {
          e += d.weight * ref.ReflectedRadiance(gq.position + gq.n_geo * ls.ray_epsilon(), d.wi, 1,
                                                uint64_t(q) * 65536 + ray++);
        }
        const solver::GatherPoint& gp = st.gather.points[st.first_patch_point + q];
        const Eigen::Vector3d e_dir = gp.e_direct.cast<double>();
        pe[k] = {e_dir.sum(), (st.patch_e[q].cast<double>() - e_dir).sum(), e.sum(),
                 double(hits[q]), s.materials.PatchAlbedo(s.patches, q).sum()};
      },
      2, 1);
  std::map<std::string, std::array<double, 6>> by_region;
  for (size_t k = 0; k < unseen.size(); ++k) {
    const int q = unseen[k];
    const int r = s.patches.patch_region[q];
    auto& a = by_region[scene.materials[r].name];
    const double w = pe[k][3];  // weighted by the rays that meet the patch
    Eigen::Vector3d rt(truth[scene.materials[r].name]["rho_d"][0].get<double>(),
                       truth[scene.materials[r].name]["rho_d"][1].get<double>(),
                       truth[scene.materials[r].name]["rho_d"][2].get<double>());
    a[0] += w * pe[k][0], a[1] += w * pe[k][1], a[2] += w * pe[k][2], a[3] += w;
    a[4] += w * pe[k][4], a[5] += w * rt.sum();
  }
  std::printf(
      "unseen patches met by the rays (weighted by rays): E_dir/E_ref, E_ind/E_ind_ref, "
      "E/E_ref, albedo/true\n");
  for (const auto& [name, a] : by_region) {
    std::printf("  %-14s %4.0f rays  E_dir share %.3f  E_ind %.4f  E %.4f  albedo %.4f\n",
                name.c_str(), a[3], a[0] / (a[0] + a[2]), a[1] / a[2],
                (a[0] + a[1]) / (a[0] + a[2]), a[4] / a[5]);
  }
  return 0;
}
