// Stage 2 (the path tracer against the photos), the residual renders, the albedo maps and the
// solve's entry point. See solver/inverse/solve.h.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>

#include "solver/inverse/albedo_map.h"
#include "solver/inverse/albedo_map_stage.h"
#include "solver/inverse/refine_stage.h"
#include "solver/inverse/solve_internal.h"
#include "solver/render/render.h"
#include "tools/common/error.h"
#include "tools/common/memory.h"
#include "tools/common/parallel.h"
#include "tools/common/progress.h"

namespace igi::solver {
namespace {

// The mesh with per-corner vertices carrying each atlas's UVs (other regions keep theirs).
recon::TriangleMesh ApplyAtlases(const recon::TriangleMesh& mesh,
                                 const std::vector<RegionAtlas>& atlases) {
  std::vector<const RegionAtlas*> of_region(mesh.region_names.size(), nullptr);
  for (const RegionAtlas& a : atlases) {
    if (a.generated && a.region >= 0 && a.region < int(of_region.size())) of_region[a.region] = &a;
  }
  recon::TriangleMesh out;
  out.region_names = mesh.region_names;
  out.triangle_region = mesh.triangle_region;
  for (size_t t = 0; t < mesh.num_triangles(); ++t) {
    const Eigen::Vector3i& tri = mesh.triangles[t];
    const RegionAtlas* a = of_region[mesh.triangle_region[t]];
    Eigen::Vector3i nt;
    for (int k = 0; k < 3; ++k) {
      nt[k] = static_cast<int>(out.positions.size());
      out.positions.push_back(mesh.positions[tri[k]]);
      out.normals.push_back(mesh.normals[tri[k]]);
      if (a != nullptr) {
        out.uvs.push_back(a->corner_uv[t][k]);
      } else {
        out.uvs.push_back(mesh.has_uvs() ? mesh.uvs[tri[k]] : Eigen::Vector2f::Zero());
      }
    }
    out.triangles.push_back(nt);
  }
  return out;
}

}  // namespace

recon::Scene SolverState::CompleteScene(std::vector<RegionAtlas>* atlases, std::vector<Image>* maps,
                                        const std::filesystem::path& temp_dir,
                                        bool as_written) const {
  recon::Scene model = scene;
  const MapStageData data = MapData();
  const MapLight map_light = MapLightOf(data);
  atlases->clear();
  maps->clear();
  bool generated = false;
  for (size_t r = 0; r < materials.size(); ++r) {
    const MaterialState& m = materials[r];
    if (!m.reflective) continue;
    recon::Material& out = model.materials[r];
    if (!out.rho_d_map) out.rho_d = m.params.rho_d;
    if (recon::HasSigma(m.params.diffuse)) out.sigma = m.params.sigma;
    if (recon::HasSpecularLobe(m.params.model)) {
      out.rho_s = m.params.rho_s;
      out.alpha = m.params.alpha;
      if (recon::IsAnisotropic(m.params.model)) {
        out.alpha_x = m.params.alpha_x;
        out.alpha_y = m.params.alpha_y;
      }
    }
    if (as_written) {  // reflectances above 1 held at 1, as BoundReflectances writes them
      if (out.rho_d) out.rho_d = out.rho_d->cwiseMin(1.0);
      if (out.rho_s) out.rho_s = out.rho_s->cwiseMin(1.0);
    }
    if (as_written ? !MapCandidate(data, r)
                   : !m.unknown_rho_d || m.last_fit.albedo_model != AlbedoModel::kPerPatch) {
      continue;
    }
    RegionAtlas atlas = MapAtlas(data, int(r));
    if (!as_written || WritesMap(data, r, atlas, map_light, nullptr)) {
      atlases->push_back(std::move(atlas));
      if (as_written) {
        maps->push_back(AlbedoMapOf(data, int(r), atlases->back(), map_light));
        const Eigen::Vector3d rho = m.params.rho_d;
        ScaleMapHeldAtOne((rho.array() > 1).select(rho.cwiseInverse(), 1.0), &maps->back());
      } else {
        maps->push_back(RefinementAlbedoMap(data, int(r), atlases->back(), map_light));
      }
      const std::filesystem::path file = temp_dir / (out.name + ".exr");
      WriteImage(file, maps->back());
      out.rho_d_map = file;
      generated |= atlases->back().generated;
    }
  }
  if (generated || (!atlases->empty() && !scene.mesh.has_uvs())) {
    model.mesh = ApplyAtlases(scene.mesh, *atlases);
  }
  return model;
}

void SolverState::RenderResiduals(recon::Scene model, int stage) {
  const auto start = std::chrono::steady_clock::now();
  // Two independent renders of kSpp/2 paths: Σ(r1 − p)(r2 − p) estimates Σ(r − p)² of the
  // noise-free render r without the render's own Monte Carlo variance (whose size at a few
  // paths per pixel would otherwise swamp the model's error).
  constexpr int kSpp = 16;
  summary.render_residual_spp = kSpp;
  std::vector<std::unique_ptr<render::Renderer>> renderers(scene.lightings.size());
  for (size_t l = 0; l < scene.lightings.size(); ++l) {
    if (light.lightings[l].active) renderers[l] = std::make_unique<render::Renderer>(model, int(l));
  }
  std::vector<Eigen::Vector3d> pred(obs.size()), pred1(obs.size()), pred2(obs.size());
  Progress progress(fmt::format("igi-solve: rendering the stage-{} model", stage),
                    int64_t(obs.size()), 2.0, options.show_progress && ProgressAllowed());
  ParallelFor(
      0, int64_t(obs.size()),
      [&](int64_t i) {
        progress.Add(1);
        const Observation& o = obs[i];
        const recon::Photo& p = scene.photos[o.photo];
        const recon::Camera& cam = scene.cameras[p.camera];
        // Each path through its own point of the pixel or block (the photo's pixel is the mean
        // over its footprint; igi-render's box filter), stratified 2×2 per half.
        const uint64_t seed = options.seed * 7919 + uint64_t(i) * 2;
        render::Pcg32 rng = render::PixelSampleRng(seed, uint64_t(i), 0xf00);
        Eigen::Vector3d half[2] = {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
        for (int k = 0; k < kSpp; ++k) {
          const int cell = (k / 2) % 4;
          const Eigen::Vector2d u = rng.Uniform2D();
          const Eigen::Vector2d px(o.x + 0.5 * o.size * ((cell % 2) + u.x()),
                                   o.y + 0.5 * o.size * ((cell / 2) + u.y()));
          half[k % 2] += renderers[p.lighting]->Radiance(
              cam.CenterInWorld(), cam.WorldRayFromImg(px), 1, seed * kSpp + uint64_t(k));
        }
        pred1[i] = half[0] / (kSpp / 2);
        pred2[i] = half[1] / (kSpp / 2);
        pred[i] = 0.5 * (pred1[i] + pred2[i]);
      },
      options.num_threads);
  summary.residuals.resize(scene.photos.size());
  std::vector<int> report_stride(scene.photos.size());
  std::vector<double> num(scene.photos.size(), 0), den(scene.photos.size(), 0);
  double all_num = 0, all_den = 0;
  for (size_t k = 0; k < scene.photos.size(); ++k) {
    const recon::Camera& cam = scene.cameras[scene.photos[k].camera];
    PhotoResidual& pr = summary.residuals[k];
    pr.file = scene.photos[k].file.filename().string();
    const int stride = report_stride[k] = ReportStride(cam.width, cam.height, options.pixel_stride);
    const int w = (cam.width + stride - 1) / stride, h = (cam.height + stride - 1) / stride;
    pr.photo = Image(w, h, 3);
    pr.render = Image(w, h, 3);
    pr.residual = Image(w, h, 3);
  }
  for (size_t i = 0; i < obs.size(); ++i) {
    const Observation& o = obs[i];
    PhotoResidual& pr = summary.residuals[o.photo];
    const int stride = report_stride[o.photo];
    const int x = std::min(o.x / stride, pr.photo.width - 1),
              y = std::min(o.y / stride, pr.photo.height - 1);
    for (int c = 0; c < 3; ++c) {
      pr.photo.at(x, y, c) = o.radiance[c];
      pr.render.at(x, y, c) = float(pred[i][c]);
      pr.residual.at(x, y, c) = float(pred[i][c] - o.radiance[c]);
    }
    const double d =
        (pred1[i] - o.radiance.cast<double>()).dot(pred2[i] - o.radiance.cast<double>());
    const double p2 = o.radiance.cast<double>().squaredNorm();
    num[o.photo] += d, den[o.photo] += p2, all_num += d, all_den += p2;
  }
  for (size_t k = 0; k < scene.photos.size(); ++k) {
    const double r = den[k] > 0 ? std::sqrt(std::max(0.0, num[k]) / den[k]) : 0.0;
    (stage == 1 ? summary.residuals[k].stage1 : summary.residuals[k].stage2) = r;
    if (stage == 1) summary.residuals[k].stage2 = r;
  }
  const double total = all_den > 0 ? std::sqrt(std::max(0.0, all_num) / all_den) : 0.0;
  // Standard error of the squared residual, from the spread of the per-pixel terms.
  double mean = all_num / std::max<size_t>(1, obs.size()), var = 0;
  for (size_t i = 0; i < obs.size(); ++i) {
    const double d =
        (pred1[i] - obs[i].radiance.cast<double>()).dot(pred2[i] - obs[i].radiance.cast<double>());
    var += (d - mean) * (d - mean);
  }
  const double se_sq = all_den > 0 ? std::sqrt(var) / all_den : 0.0;  // of residual²
  (stage == 1 ? summary.stage1_render_residual : summary.stage2_render_residual) = total;
  (stage == 1 ? summary.stage1_render_residual_sq_se : summary.stage2_render_residual_sq_se) =
      se_sq;
  if (stage == 1) {
    summary.stage2_render_residual = total;
    summary.stage2_render_residual_sq_se = se_sq;
  }
  summary.seconds_rays +=
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  spdlog::info("stage {} model rendered at the observed pixels: relative rms {:.4f}", stage, total);
}

void SolverState::RefineRound(int round, const std::filesystem::path& temp_dir) {
  std::vector<RegionAtlas> atlases;
  std::vector<Image> maps;
  std::filesystem::create_directories(temp_dir);
  const recon::Scene model = CompleteScene(&atlases, &maps, temp_dir);
  const StageData stage = Stage();
  const RenderCost cost =
      RenderIncident(stage, model, RayEpsilons(), materials, uint64_t(round), &light);
  summary.seconds_rays += cost.seconds;
  summary.rays += cost.rays;
  if (spdlog::should_log(spdlog::level::debug)) {
    size_t entries = 0, lists = 0;
    for (const auto& inc : light.incident) entries += inc.capacity(), lists += !inc.empty();
    spdlog::debug("round {}: {} incident lists, {:.2f} GiB; peak so far {:.2f} GiB", round, lists,
                  entries * sizeof(IncidentLocal) / kGiB, PeakResidentBytes() / kGiB);
  }
  SmoothStageIrradiance(stage, materials.size(), &light);
  FitRegions(stage, light, 2, round, &materials, &summary);
  UpdateSpecularTerms(stage, materials, &light);
  summary.stage2_iterations = round;
}

void SolverState::RunStage2() {
  const std::filesystem::path temp =
      std::filesystem::temp_directory_path() /
      fmt::format("igi-solve-{}-{}", ::getpid(), reinterpret_cast<uintptr_t>(this));
  std::filesystem::create_directories(temp);
  struct Cleanup {
    std::filesystem::path p;
    ~Cleanup() {
      std::error_code ec;
      std::filesystem::remove_all(p, ec);
    }
  } cleanup{temp};
  std::vector<RegionAtlas> atlases;
  std::vector<Image> maps;
  const std::vector<MaterialState> stage1 = materials.regions;
  RenderResiduals(CompleteScene(&atlases, &maps, temp / "s1", true), 1);
  for (int round = 1; round <= options.refine_iterations; ++round) {
    RefineRound(round, temp / std::to_string(round));
  }
  for (size_t r = 0; r < materials.size(); ++r) summary.regions[r].stage2 = materials[r].last_fit;
  if (options.refine_iterations > 0) {
    std::filesystem::create_directories(temp / "final");
    RenderResiduals(CompleteScene(&atlases, &maps, temp / "final", true), 2);
    // The refinement's parameters are kept only if the photos are not explained worse than by
    // the paper's (beyond twice the standard error of the comparison).
    const double r1 = summary.stage1_render_residual, r2 = summary.stage2_render_residual;
    const double se =
        std::hypot(summary.stage1_render_residual_sq_se, summary.stage2_render_residual_sq_se);
    summary.refinement_accepted = r2 * r2 <= r1 * r1 + 2 * se;
    if (!summary.refinement_accepted) {
      for (size_t r = 0; r < materials.size(); ++r) {
        materials[r].params = stage1[r].params;
        materials[r].patch_rho_d = stage1[r].patch_rho_d;
        materials[r].last_fit = stage1[r].last_fit;
        materials[r].map_scale = stage1[r].map_scale;
      }
      UpdateSpecularTerms(Stage(), materials, &light);
      spdlog::warn(
          "the refinement explains the photos worse ({:.4f} vs {:.4f}): the paper stage's "
          "parameters are kept",
          r2, r1);
    }
  }
}

MapStageData SolverState::MapData() const {
  return MapStageData{scene,
                      options,
                      obs,
                      materials,
                      patches,
                      light,
                      summary.texel_size_m,
                      summary.scene_scale_m,
                      summary.stage2_iterations,
                      summary.refinement_accepted};
}

void SolverState::BuildAlbedoMaps() {
  std::vector<RegionAtlas> generated;
  const MapStageData data = MapData();
  const MapLight map_light = MapLightOf(data);
  // Regions whose maps come from their own pass over the photos (observations drawn to a
  // budget), on atlases at the photos' footprint.
  std::vector<int> streamed;
  std::vector<RegionAtlas> fine;
  for (size_t r = 0; r < materials.size(); ++r) {
    const MaterialState& m = materials[r];
    if (!MapCandidate(data, r)) continue;
    const RegionAtlas atlas = MapAtlas(data, int(r));
    RegionSolution& rs = summary.regions[r];
    TexelDetail detail;
    const bool mapped = WritesMap(data, r, atlas, map_light, &detail);
    rs.texel_variation = detail.variation;
    rs.texel_variation_z = detail.z;
    if (!mapped) continue;
    if (!m.last_fit.albedo_varies && options.albedo_maps != AlbedoMaps::kAll) {
      spdlog::info(
          "region {}: its albedo varies by {:.0f} % from texel to texel (finer than the "
          "patches; z {:.1f}): given a map",
          rs.name, 100 * rs.texel_variation, rs.texel_variation_z);
    }
    rs.albedo_map_file = "albedo/" + scene.materials[r].name + ".exr";
    if (options.albedo_map_pass == AlbedoMapPass::kAlways ||
        (options.albedo_map_pass == AlbedoMapPass::kAuto && obs.draw.census)) {
      AtlasOptions ao;
      ao.texel_size_m = summary.map_texel_size_m;
      streamed.push_back(int(r));
      fine.push_back(BuildRegionAtlas(scene.mesh, int(r), ao));
      continue;
    }
    Image seen;
    rs.albedo_map = AlbedoMapOf(data, int(r), atlas, map_light, &rs.albedo_map_coverage, &seen);
    rs.albedo_map_seen_mean = SeenTexelMean(*rs.albedo_map, seen);
    rs.albedo_map_seen = std::move(seen);
    rs.albedo_map_generated_uvs = atlas.generated;
    if (atlas.generated) generated.push_back(atlas);
  }
  if (!streamed.empty()) {
    std::vector<Image> seen;
    std::vector<double> coverage;
    std::vector<Image> maps = StreamAlbedoMaps(streamed, fine, map_light, &seen, &coverage);
    for (size_t k = 0; k < streamed.size(); ++k) {
      RegionSolution& rs = summary.regions[streamed[k]];
      rs.albedo_map_seen_mean = SeenTexelMean(maps[k], seen[k]);
      rs.albedo_map = std::move(maps[k]);
      rs.albedo_map_seen = std::move(seen[k]);
      rs.albedo_map_coverage = coverage[k];
      rs.albedo_map_generated_uvs = fine[k].generated;
      if (fine[k].generated) generated.push_back(fine[k]);
    }
  }
  if (!generated.empty()) summary.charted_mesh = ApplyAtlases(scene.mesh, generated);
}

SolveSummary Solve(const recon::Scene& scene, const SolveOptions& options,
                   const std::filesystem::path& out_dir) {
  options.Validate();
  const auto start = std::chrono::steady_clock::now();
  SolverState s(scene, options);
  if (scene.photos.empty()) {
    throw InputError(DescribeProblem(scene.file.string(), "photos", "[]",
                                     "the solver needs at least one photo"));
  }
  // The process's peak resident memory after each stage (report.json memory.peak_after).
  auto stage_done = [&](const char* stage) {
    s.summary.peak_after.emplace_back(stage, double(PeakResidentBytes()));
    spdlog::debug("peak memory after {}: {:.2f} GiB", stage,
                  s.summary.peak_after.back().second / kGiB);
  };
  s.Prepare();
  stage_done("observations");
  if (options.photo_scale == PhotoScaleMode::kSolve) {
    PhotoScaleReferenceRegions(s);  // before the rays
  }
  s.GatherAll();
  stage_done("gather");
  if (options.photo_scale == PhotoScaleMode::kSolve) {
    s.summary.photo_scale = RunStage1WithPhotoScale(&s);
  } else {
    s.RunStage1();
  }
  stage_done("paper");
  s.RunStage2();
  stage_done("refined");
  s.BuildAlbedoMaps();
  s.FinishRegions();
  stage_done("albedo_maps");
  s.summary.seconds_total =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  s.summary.peak_memory_bytes = double(PeakResidentBytes());
  s.summary.scene_document = SolvedSceneDocument(scene, s.summary, out_dir);
  return std::move(s.summary);
}

}  // namespace igi::solver
