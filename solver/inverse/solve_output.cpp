#include "solver/inverse/solve_output.h"

#include <fmt/format.h>

#include <cmath>
#include <filesystem>

#include "recon/scene_document.h"
#include "solver/inverse/uv_charts.h"
#include "tools/common/atomic_file.h"
#include "tools/common/error.h"
#include "tools/common/image.h"

namespace igi::solver {
namespace fs = std::filesystem;
namespace {

// The seen-texel mask beside an albedo map: albedo/floor.exr -> albedo/floor_seen.png.
std::string SeenFile(const std::string& map_file) {
  const fs::path p(map_file);
  return (p.parent_path() / (p.stem().string() + "_seen.png")).generic_string();
}

Json Num(double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); }
Json Vec(const Eigen::Vector3d& v) { return Json::array({Num(v[0]), Num(v[1]), Num(v[2])}); }

Json FitJson(const RegionFitResult& f, const render::BrdfParams& params) {
  const recon::BrdfModel model = params.model;
  Json j;
  if (!f.fitted) {
    j["fitted"] = false;
    if (!f.message.empty()) j["message"] = f.message;
    return j;
  }
  j["rho_d"] = Vec(f.rho_d);
  j["sigma_rho_d"] = Vec(f.sigma_rho_d);
  if (recon::HasSigma(params.diffuse)) j["sigma"] = Num(f.sigma);
  if (recon::HasSpecularLobe(model)) {
    j["rho_s"] = Vec(f.rho_s);
    j["sigma_rho_s"] = Num(f.sigma_rho_s);
    if (recon::IsAnisotropic(model)) {
      j["alpha_x"] = Num(f.alpha_x);
      j["alpha_y"] = Num(f.alpha_y);
      j["sigma_alpha_x"] = Num(f.sigma_alpha_x);
      j["sigma_alpha_y"] = Num(f.sigma_alpha_y);
    } else {
      j["alpha"] = Num(f.alpha);
      j["sigma_alpha"] = Num(f.sigma_alpha);
    }
  }
  j["albedo_model"] = std::string(AlbedoModelName(f.albedo_model));
  j["albedo_varies"] = f.albedo_varies;
  j["relative_rms"] = Num(f.relative_rms);
  j["samples"] = f.samples;
  if (!f.message.empty()) j["message"] = f.message;
  return j;
}

}  // namespace

Json SolvedSceneDocument(const recon::Scene& scene, const SolveSummary& summary,
                         const fs::path& out) {
  recon::SceneDocument doc(scene.document);
  doc.RebasePaths(scene.dir, out);
  if (summary.charted_mesh) doc.SetGeometryFiles({"geometry/solved.obj"});
  if (summary.photo_scale) {
    for (size_t i = 0; i < doc.NumPhotos(); ++i) {
      doc.SetPhotoExposure(i, doc.PhotoExposure(i).value_or(1.0) * summary.photo_scale->scale);
    }
  }
  for (size_t r = 0; r < scene.materials.size(); ++r) {
    const std::string& name = scene.materials[r].name;
    const RegionSolution& rs = summary.regions[r];
    const render::BrdfParams& p = rs.final_params;
    if (!recon::IsReflective(scene.materials[r].brdf)) continue;
    doc.SetMaterialValue(name, "rho_d", Vec(p.rho_d));
    if (recon::HasSigma(p.diffuse)) doc.SetMaterialValue(name, "sigma", p.sigma);
    if (!rs.albedo_map_file.empty()) doc.SetMaterialValue(name, "rho_d_map", rs.albedo_map_file);
    if (recon::HasSpecularLobe(p.model)) {
      const bool grey = p.rho_s[0] == p.rho_s[1] && p.rho_s[1] == p.rho_s[2];
      doc.SetMaterialValue(name, "rho_s", grey ? Json(p.rho_s[0]) : Vec(p.rho_s));
      if (recon::IsAnisotropic(p.model)) {
        doc.SetMaterialValue(name, "alpha_x", p.alpha_x);
        doc.SetMaterialValue(name, "alpha_y", p.alpha_y);
      } else {
        doc.SetMaterialValue(name, "alpha", p.alpha);
      }
    }
  }
  return std::move(doc).json();
}

Json SolveReportJson(const SolveSummary& s, const SolveOptions& o) {
  Json j;
  j["format"] = "igi-solve-report";
  j["version"] = 1;
  j["converged"] = s.converged;
  j["message"] = s.message;
  j["stages"]["paper"] = {{"iterations", s.stage1_iterations},
                          {"model_residual", Num(s.stage1_model_residual)},
                          {"render_residual", Num(s.stage1_render_residual)}};
  j["stages"]["paper"]["render_residual_squared_stderr"] = Num(s.stage1_render_residual_sq_se);
  j["stages"]["refined"] = {{"iterations", s.stage2_iterations},
                            {"render_residual", Num(s.stage2_render_residual)},
                            {"render_residual_squared_stderr", Num(s.stage2_render_residual_sq_se)},
                            {"accepted", s.refinement_accepted}};
  j["render_residual_spp"] = s.render_residual_spp;
  if (s.photo_scale) {
    const PhotoScaleEstimate& k = *s.photo_scale;
    j["photo_scale"] = {{"scale", Num(k.scale)},
                        {"sigma", Num(k.sigma)},
                        {"rgb", Vec(k.rgb)},
                        {"reference_regions", k.reference_regions},
                        {"samples", k.samples},
                        {"rejected", k.rejected},
                        {"rounds", k.rounds},
                        {"direct_share", Num(k.direct_share)},
                        {"meaning",
                         "photo value = scale x radiance in the scene's units, from the regions of "
                         "known diffuse reflectance; every photo's exposure_scale in scene.json is "
                         "multiplied by it"}};
  }
  j["residual_metric"] =
      "relative RMS residual sqrt(sum (render - photo)^2 / sum photo^2) over the observed pixels, "
      "all channels; renders path traced through each pixel's centre";
  Json regions = Json::array();
  for (const RegionSolution& r : s.regions) {
    Json rj;
    rj["name"] = r.name;
    rj["status"] = std::string(RegionStatusName(r.status));
    rj["unknowns"] = r.unknowns;
    rj["observations"] = r.observations;
    rj["paper"] = FitJson(r.stage1, r.final_params);
    rj["refined"] = FitJson(r.stage2, r.final_params);
    // scene.json's rho_d and where it comes from: the albedo map's mean over its seen texels
    // where the region has a map, else the fit's region mean (after the bound at 1).
    rj["rho_d"] = Vec(r.final_params.rho_d);
    rj["rho_d_source"] = r.rho_d_from_map                        ? "albedo_map_seen_mean"
                         : r.RhoDFromBouncedLight()              ? "bounced_light"
                         : r.status == RegionStatus::kUnobserved ? "placeholder"
                                                                 : "fit";
    if (r.RhoDFromBouncedLight()) {
      rj["bounced_light_fit"] = {
          {"relative_sigma", Vec(r.bounce_fit_sigma)},
          {"meaning",
           "no photo sees this region: its rho_d is fitted to the light it bounces onto the "
           "regions the photos show (their one-albedo regions' residuals, each region's albedo "
           "profiled out); relative_sigma from the cost's curvature"}};
    }
    if (r.Bounded()) {
      rj["bounded"] = {
          {"rho_d_fitted", Vec(r.rho_d_fitted)},
          {"rho_s_fitted", Vec(r.rho_s_fitted)},
          {"albedo_texels_clipped", r.albedo_texels_clipped},
          {"meaning",
           "the fit wanted a reflectance above 1 (null: not bounded); scene.json holds it at 1 "
           "(the albedo map scaled by the same factor, texels clipped at 1): the photos are "
           "brighter than the scene's lights can make any passive surface"}};
    }
    if (std::isfinite(r.texel_variation)) {
      rj["texel_variation"] = {
          {"value", r.texel_variation},
          {"z", r.texel_variation_z},
          {"mapped", !r.albedo_map_file.empty()},
          {"meaning",
           "the fit kept a constant albedo; the albedo's relative standard deviation from texel to "
           "texel beyond the photos' noise (covariance of two maps from disjoint halves of the "
           "photos, each less its local 7x7-texel mean; z: the covariance over its standard "
           "error, 16x16-texel tiles as samples); above 0.1 at z above 3 the region gets a map"}};
    }
    if (!r.albedo_map_file.empty()) {
      rj["albedo_map"] = {{"file", r.albedo_map_file},
                          {"width", r.albedo_map ? r.albedo_map->width : 0},
                          {"height", r.albedo_map ? r.albedo_map->height : 0},
                          {"coverage", Num(r.albedo_map_coverage)},
                          {"seen_mean", Vec(r.albedo_map_seen_mean)},
                          {"generated_uvs", r.albedo_map_generated_uvs}};
      // Which texels the photos estimate (255) and which were filled from neighbours (0).
      if (r.albedo_map_seen) rj["albedo_map"]["seen_file"] = SeenFile(r.albedo_map_file);
    }
    regions.push_back(rj);
  }
  j["regions"] = regions;
  Json photos = Json::array();
  for (size_t k = 0; k < s.photos.size(); ++k) {
    const PhotoObservationStats& p = s.photos[k];
    Json pj = {{"pixels", p.pixels},   {"valid", p.valid},
               {"masked", p.masked},   {"clipped", p.clipped},
               {"invalid", p.invalid}, {"background", p.background},
               {"edge", p.edge},       {"undrawn", p.undrawn},
               {"blocks", p.blocks},   {"saturation", Num(p.saturation)}};
    if (k < s.residuals.size()) {
      pj["file"] = s.residuals[k].file;
      pj["residual_paper"] = Num(s.residuals[k].stage1);
      pj["residual_refined"] = Num(s.residuals[k].stage2);
    }
    photos.push_back(pj);
  }
  j["photos"] = photos;
  j["highlight_coverage"] = HighlightCoverageJson(s.coverage);
  Json history = Json::array();
  for (const SolveIteration& it : s.history) {
    history.push_back({{"stage", it.stage == 1 ? "paper" : "refined"},
                       {"iteration", it.iteration},
                       {"relative_rms", Num(it.relative_rms)},
                       {"max_change", Num(it.max_change)},
                       {"params", it.params}});
    if (it.albedo_update) {
      history.back()["albedo_update"] = std::string(RefineUpdateName(*it.albedo_update));
      history.back()["albedo_step"] = it.albedo_step;
    }
  }
  j["history"] = history;
  j["timing"] = {
      {"total_s", s.seconds_total},
      {"ray_casting_s", s.seconds_rays},
      {"fitting_s", s.seconds_fit},
      {"ray_casting_share", s.seconds_total > 0 ? s.seconds_rays / s.seconds_total : 0.0}};
  j["rays"] = s.rays;
  j["patches"] = s.patches;
  j["patch_size_m"] = s.patch_size_m;
  j["scene_scale"] = {{"diagonal_m", s.scene_diagonal_m},
                      {"free_path_m", std::isfinite(s.free_path_m) ? Json(s.free_path_m) : Json()},
                      {"scale_m", s.scene_scale_m}};
  j["texel_size_m"] = s.texel_size_m;
  j["map_texel_size_m"] = s.map_texel_size_m;
  j["observations"] = s.observations;
  // The observation budget and the draw (solver/inverse/observation_draw.h), and the memory: the
  // budget, the estimate it was planned with (solver/inverse/solve_memory.h) and the measured peak.
  j["observation_draw"] = {{"budget", Num(s.observation_budget)},
                           {"available", Num(s.observations_available)},
                           {"drawn", s.observations},
                           {"thinned", s.observations_thinned}};
  j["memory"] = {{"budget_bytes", Num(s.memory_budget_bytes)},
                 {"estimate_bytes", Num(s.memory_estimate_bytes)},
                 {"peak_bytes", Num(s.peak_memory_bytes)}};
  for (const auto& [stage, bytes] : s.peak_after) j["memory"]["peak_after"][stage] = Num(bytes);
  j["options"] = {{"pixel_stride", o.pixel_stride},
                  {"memory_budget", o.memory_budget},
                  {"max_observations", o.max_observations},
                  {"max_observation_block", o.max_observation_block},
                  {"smoothing_accuracy", o.smoothing_accuracy},
                  {"light_samples", o.light_samples},
                  {"indirect_rays", o.indirect_rays},
                  {"max_iterations", o.max_iterations},
                  {"tolerance", o.tolerance},
                  {"specular_colour", std::string(SpecularColourName(o.specular_colour))},
                  {"albedo_maps", std::string(AlbedoMapsName(o.albedo_maps))},
                  {"albedo_map_pass", std::string(AlbedoMapPassName(o.albedo_map_pass))},
                  {"refine_iterations", o.refine_iterations},
                  {"refine_rays", o.refine_rays},
                  {"refine_final_rays", o.refine_final_rays},
                  {"seed", o.seed},
                  {"refine_albedo_step", o.refine_albedo_step},
                  {"refine_update", std::string(RefineUpdateName(o.refine_update))},
                  {"specular_bounces", o.specular_bounces},
                  {"pixel_footprint", o.pixel_footprint},
                  {"photo_scale", std::string(PhotoScaleModeName(o.photo_scale))}};
  if (!o.albedo_map_regions.empty()) j["options"]["albedo_map_regions"] = o.albedo_map_regions;
  return j;
}

void WriteSolveReportHtml(const SolveSummary& summary, const Json& report, const fs::path& path);

void WriteSolveOutputs(const SolveSummary& s, const SolveOptions& o, const fs::path& out) {
  fs::create_directories(out);
  for (const RegionSolution& r : s.regions) {
    if (r.albedo_map_file.empty() || !r.albedo_map) continue;
    fs::create_directories((out / r.albedo_map_file).parent_path());
    WriteImageOptions wo;
    wo.type = PixelType::kFloat;
    WriteImage(out / r.albedo_map_file, *r.albedo_map, wo);
    if (r.albedo_map_seen) {
      WriteImageOptions mo;
      mo.type = PixelType::kUInt8;
      WriteImage(out / SeenFile(r.albedo_map_file), *r.albedo_map_seen, mo);
    }
  }
  if (s.charted_mesh) {
    fs::create_directories(out / "geometry");
    WriteObjWithAtlases(*s.charted_mesh, {}, out / "geometry" / "solved.obj");
  }
  const Json report = SolveReportJson(s, o);
  WriteJsonFile(out / "report.json", report);
  WriteSolveReportHtml(s, report, out / "report.html");
  WriteJsonFile(out / "scene.json", s.scene_document);
}

}  // namespace igi::solver
