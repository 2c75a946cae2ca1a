#include "solver/inverse/solve.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <unordered_map>

#include "solver/inverse/albedo_map.h"
#include "solver/inverse/gather.h"
#include "solver/inverse/patches.h"
#include "solver/inverse/photo_model.h"
#include "solver/inverse/scene_scale.h"
#include "solver/inverse/solve_internal.h"
#include "solver/render/brdf.h"
#include "solver/render/ray_scene.h"
#include "solver/render/render.h"
#include "solver/render/sampling.h"
#include "tools/common/enum_names.h"
#include "tools/common/error.h"
#include "tools/common/memory.h"
#include "tools/common/parallel.h"
#include "tools/common/progress.h"

namespace igi::solver {
namespace {

using Clock = std::chrono::steady_clock;
double Since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

}  // namespace

constexpr EnumNames<RegionStatus, 4> kRegionStatusNames{
    {{RegionStatus::kKnown, "known"},
     {RegionStatus::kSolved, "solved"},
     {RegionStatus::kUnobserved, "unobserved"},
     {RegionStatus::kNoHighlight, "no_highlight"}}};

std::string_view RegionStatusName(RegionStatus status) { return kRegionStatusNames.Name(status); }
std::optional<RegionStatus> RegionStatusFromName(std::string_view name) {
  return kRegionStatusNames.FromName(name);
}

// ---------------------------------------------------------------------------------------------
// Set-up: materials, photos, observations, patches, gathering.

// Everything before the rays: patches, materials, photos, observations, fit samples, texel size
// and highlight coverage.
void SolverState::Prepare() {
  BuildLightingScenes();
  const render::RayScene* geometry = nullptr;
  for (const auto& s : lighting_scenes) geometry = geometry ? geometry : s.get();
  const SceneScale scale = MeasureSceneScale(scene, geometry);
  summary.scene_diagonal_m = scale.diagonal_m;
  summary.free_path_m = scale.free_path_m;
  summary.scene_scale_m = scale.scale_m;
  summary.patch_size_m = options.patch_size_m > 0 ? options.patch_size_m : scale.scale_m / 96.0;
  patches = BuildPatches(scene.mesh, summary.patch_size_m);
  summary.patches = patches.size();
  materials = MaterialEstimate::FromScene(scene, patches);
  summary.regions.resize(scene.materials.size());
  PlanObservations();
  CollectAllObservations();
  SummariseRegions();
  SelectFitSamples();
  ChooseTexelSize();
  AnalyseCoverage();
}

// Photo i as the solver reads it: linear radiance (photos whose values are not plain radiance
// are linearised, their clipped pixels masked out first, as the clip level is a recorded value),
// and an 8-bit mask (0 = ignore; empty: every pixel) with the held-out pixels masked out.
SolverState::LoadedPhoto SolverState::LoadPhoto(int i) const {
  const recon::Photo& p = scene.photos[i];
  const recon::Camera& cam = scene.cameras[p.camera];
  LoadedPhoto out;
  out.radiance = ReadImage(p.file, 3);
  if (out.radiance.width != cam.width || out.radiance.height != cam.height) {
    throw InputError(DescribeProblem(scene.file.string(), "photos[" + std::to_string(i) + "].file",
                                     p.file.string() + " is " + std::to_string(out.radiance.width) +
                                         "x" + std::to_string(out.radiance.height),
                                     "must match camera " + cam.name + " (" +
                                         std::to_string(cam.width) + "x" +
                                         std::to_string(cam.height) + ")"));
  }
  const size_t w = size_t(cam.width), h = size_t(cam.height);
  if (p.mask) {
    const Image m = ReadImage(*p.mask, 1);
    out.mask.resize(w * h);
    for (size_t k = 0; k < out.mask.size(); ++k) out.mask[k] = m.pixels[k] > 0 ? 1 : 0;
  }
  const PixelHoldout holdout{options.holdout_fraction, options.holdout_block_px,
                             options.holdout_seed};
  const bool model = HasPhotoModel(p, cam);
  if (!model && !(holdout.fraction > 0)) return out;
  Image& photo = out.radiance;
  const double clip = options.saturation > 0 ? options.saturation : AutoSaturation(photo);
  if (out.mask.empty()) out.mask.assign(w * h, 1);
  for (int y = 0; y < photo.height; ++y) {
    for (int x = 0; x < photo.width; ++x) {
      bool held = holdout.HeldOut(i, x, y);
      for (int c = 0; c < photo.channels && model; ++c) held |= photo.at(x, y, c) >= clip;
      if (held) out.mask[size_t(y) * w + x] = 0;
    }
  }
  if (model) photo = LinearRadianceOfPhoto(p, cam, photo);
  return out;
}

namespace {

// The fewest observations a solve is run on (or every available one, where fewer).
constexpr double kMinObservations = 5000;

std::string GiB(double bytes) { return fmt::format("{:.2f} GiB", bytes / kGiB); }

}  // namespace

void SolverState::PlanObservations() {
  memory = EstimateSolveMemory(scene, options, patches.size());
  summary.memory_budget_bytes = memory.budget_bytes;
  const size_t n = materials.size();
  std::vector<char> lobe_class(n, 0);
  for (size_t r = 0; r < n; ++r) {
    lobe_class[r] = materials[r].NeedsFit() && recon::HasSpecularLobe(materials[r].params.model);
  }
  const double fixed = memory.fixed_bytes + memory.photo_bytes;
  if (fixed > memory.budget_bytes) {
    size_t largest = 0;
    for (size_t i = 0; i < scene.photos.size(); ++i) {
      const recon::Camera& a = scene.cameras[scene.photos[i].camera];
      const recon::Camera& b = scene.cameras[scene.photos[largest].camera];
      if (double(a.width) * a.height > double(b.width) * b.height) largest = i;
    }
    const recon::Camera& cam = scene.cameras[scene.photos[largest].camera];
    throw InputError(DescribeProblem(
        scene.file.string(), "photos[" + std::to_string(largest) + "].file",
        fmt::format("{} ({}x{})", scene.photos[largest].file.string(), cam.width, cam.height),
        "reading it with the scene takes " + GiB(fixed) + " before any observation, over the " +
            GiB(memory.budget_bytes) + " memory budget (--memory-budget)"));
  }
  // The observations k that fit, each costing `per` bytes on average, of which at most
  // min(k, fitted_lobe) are fitted on regions with a lobe (fitted_lobe_bytes more each).
  auto fitting = [&](double per, double fitted_lobe) {
    const double room = memory.budget_bytes - fixed;
    double k = (room - memory.fitted_lobe_bytes * fitted_lobe) / per;
    if (k < fitted_lobe) k = room / (per + memory.fitted_lobe_bytes);
    return std::max(0.0, k);
  };
  auto capped = [&](double k) {
    return options.max_observations > 0 ? std::min(k, double(options.max_observations)) : k;
  };
  spdlog::debug(
      "memory plan: budget {}, fixed {}, largest photo {}, per observation {:.0f} B ({:.0f} B "
      "with a lobe, {:.0f} B more fitted there)",
      GiB(memory.budget_bytes), GiB(memory.fixed_bytes), GiB(memory.photo_bytes),
      memory.observation_bytes, memory.lobe_observation_bytes, memory.fitted_lobe_bytes);
  const double pixels = PixelsAtStride(scene, options.pixel_stride);
  double lobe_fit = 0;  // the lobe regions' fit samples at most
  bool any_lobe = false;
  for (size_t r = 0; r < n; ++r) {
    if (!lobe_class[r]) continue;
    any_lobe = true;
    lobe_fit += double(options.max_highlight_samples) + options.max_fit_samples;
  }
  lobe_fit = std::min(lobe_fit, pixels);
  summary.observation_budget = capped(
      fitting(any_lobe ? memory.lobe_observation_bytes : memory.observation_bytes, lobe_fit));
  if (pixels <= summary.observation_budget) {
    summary.memory_estimate_bytes = memory.BytesFor(pixels, any_lobe ? pixels : 0, lobe_fit);
    return;
  }
  ObservationDrawOptions d;
  d.pixel_stride = options.pixel_stride;
  d.max_highlight_samples = options.max_highlight_samples;
  d.max_fit_samples = options.max_fit_samples;
  d.max_block = options.max_observation_block;
  d.num_threads = options.num_threads;
  std::vector<const render::RayScene*> geometry(lighting_scenes.size(), nullptr);
  for (size_t l = 0; l < lighting_scenes.size(); ++l) geometry[l] = lighting_scenes[l].get();
  const std::vector<RegionPixelCensus> census = CensusPixels(scene, geometry, lobe_class, d);
  // The census's share of pixels on regions with a lobe, and their fit samples.
  double total = 0, lobe = 0;
  lobe_fit = 0;
  for (size_t r = 0; r < n; ++r) {
    total += census[r].near + census[r].rest;
    if (!lobe_class[r]) continue;
    lobe += census[r].near + census[r].rest;
    lobe_fit += std::min(census[r].near, double(options.max_highlight_samples)) +
                std::min(census[r].rest, double(options.max_fit_samples));
  }
  const double share = total > 0 ? lobe / total : 0.0;
  const double in_memory = fitting(
      memory.observation_bytes + share * (memory.lobe_observation_bytes - memory.observation_bytes),
      lobe_fit);
  d.budget = summary.observation_budget = capped(in_memory);
  const double fewest = std::min(total, kMinObservations);
  if (in_memory < fewest) {
    const double needed = memory.BytesFor(fewest, share * fewest, std::min(lobe_fit, fewest));
    throw InputError(DescribeProblem(
        scene.file.string(), "--memory-budget", GiB(memory.budget_bytes),
        "the solve needs at least " + GiB(needed) + " (" + std::to_string(int(fewest)) +
            " observations with the scene, the patches and the largest photo); raise the budget "
            "or lower --indirect-rays, --refine-final-rays or --max-highlight-samples"));
  }
  ObservationDraw& draw = obs.draw;
  draw = PlanObservationDraw(census, lobe_class, d);
  draw.census = draw.expected < draw.available;
  summary.observations_thinned = draw.census;
  for (size_t r = 0; r < n && draw.census; ++r) {
    spdlog::debug(
        "draw: {}: {:.0f} highlight candidates (p {:.4g}), {:.0f} other pixels (p {:.4g})",
        scene.materials[r].name, lobe_class[r] ? census[r].near : 0.0, draw.p_near[r],
        census[r].rest + (lobe_class[r] ? 0.0 : census[r].near), draw.p_rest[r]);
  }
  summary.memory_estimate_bytes =
      memory.BytesFor(draw.expected, share * draw.expected, std::min(lobe_fit, draw.expected));
  if (draw.census) {
    spdlog::warn(
        "the photos offer about {:.0f} observations at pixel stride {}; drawing about {:.0f} to "
        "fit {} of memory ({} budget{}): every region keeps its fit samples and highlight "
        "candidates within half of the budget, the rest is drawn evenly",
        draw.available, options.pixel_stride, draw.expected, GiB(summary.memory_estimate_bytes),
        GiB(memory.budget_bytes),
        options.max_observations > 0 ? fmt::format(", at most {}", options.max_observations)
                                     : std::string());
  }
}

void SolverState::BuildLightingScenes() {
  ProblemList problems;
  lighting_scenes.resize(scene.lightings.size());
  for (size_t i = 0; i < scene.photos.size(); ++i) {
    const int l = scene.photos[i].lighting;
    if (lighting_scenes[l]) continue;
    if (scene.lightings[l].lights.empty()) {
      bool emitter = false;
      for (const recon::Material& m : scene.materials)
        emitter |= m.brdf == recon::BrdfModel::kEmitter;
      if (!emitter) {
        problems.Add(scene.file.string(), "photos[" + std::to_string(i) + "].lighting",
                     scene.lightings[l].name,
                     "the lighting has no light and no material emits: the photo cannot be "
                     "explained");
        continue;
      }
    }
    lighting_scenes[l] = std::make_unique<render::RayScene>(scene, l);
  }
  problems.ThrowIfAny();
}

// The photos are streamed: each is read, linearised, turned into observations and released
// before the next, so that only one photo is in memory at a time (its observations are drawn to
// the budget as they are collected: solver/inverse/observation_draw.h).
void SolverState::CollectAllObservations() {
  ProblemList problems;
  ObservationOptions oo;
  oo.pixel_stride = options.pixel_stride;
  oo.saturation = options.saturation;
  oo.num_threads = options.num_threads;
  oo.draw = obs.draw.census ? &obs.draw : nullptr;
  summary.photos.resize(scene.photos.size());
  Progress progress("igi-solve: observations", int64_t(scene.photos.size()), 2.0,
                    options.show_progress && ProgressAllowed());
  for (size_t i = 0; i < scene.photos.size(); ++i) {
    std::vector<Observation> o;
    try {
      const LoadedPhoto photo = LoadPhoto(int(i));
      o = CollectObservations(
          scene, int(i), photo.radiance, photo.mask.empty() ? nullptr : &photo.mask,
          *lighting_scenes[scene.photos[i].lighting], patches, oo, &summary.photos[i]);
    } catch (const Error& e) {
      problems.Append(e);
      progress.Add(1);
      continue;
    }
    progress.Add(1);
    if (!options.pixel_footprint) {
      for (Observation& ob : o) ob.lobe_blur2 = 0;
    }
    const PhotoObservationStats& st = summary.photos[i];
    if (o.empty()) {
      problems.Add(scene.file.string(), "photos[" + std::to_string(i) + "]",
                   scene.photos[i].file.string(),
                   "no valid pixel (" + std::to_string(st.pixels) +
                       " looked at: " + std::to_string(st.masked) + " masked, " +
                       std::to_string(st.clipped) + " clipped, " + std::to_string(st.invalid) +
                       " non-finite or negative, " + std::to_string(st.background) +
                       " see no reflective surface, " + std::to_string(st.edge) + " on edges)");
    }
    obs.items.insert(obs.items.end(), o.begin(), o.end());
  }
  progress.Finish();
  problems.ThrowIfAny();
  obs.items.shrink_to_fit();
  summary.observations = static_cast<int>(obs.size());
  for (const PhotoObservationStats& st : summary.photos) {
    summary.observations_available += st.valid + st.undrawn;
  }
  for (const Observation& o : obs) ++materials[o.region].observations;
}

void SolverState::SelectFitSamples() {
  std::vector<char> fitted(materials.size(), 0), near(obs.size(), 0);
  for (size_t r = 0; r < materials.size(); ++r) fitted[r] = materials[r].NeedsFit();
  // Near a possible highlight: tanθh < 0.6 toward some light of the observation's lighting.
  for (size_t i = 0; i < obs.size(); ++i) {
    const Observation& o = obs[i];
    const MaterialState& m = materials[o.region];
    near[i] =
        m.NeedsFit() && recon::HasSpecularLobe(m.params.model) &&
        NearHighlight(*lighting_scenes[scene.photos[o.photo].lighting], o.position.cast<double>(),
                      o.view.cast<double>(), o.normal.cast<double>());
  }
  igi::solver::SelectFitSamples(fitted, near, size_t(options.max_highlight_samples),
                                size_t(options.max_fit_samples), &obs);
}

// The footprint of observation o's pixel or block (solver/inverse/gather.h): ray directions at unit
// depth, so that they are affine in the pixel coordinates (exactly for PINHOLE; OPENCV's distortion
// is linearised over the pixel).
GatherQuery::Footprint SolverState::PixelFootprint(const Observation& o) const {
  const recon::Camera& cam = scene.cameras[scene.photos[o.photo].camera];
  const Eigen::Quaterniond world_from_cam = cam.cam_from_world.rotation.conjugate();
  auto ray = [&](double u, double v) -> Eigen::Vector3d {
    const Eigen::Vector3d d =
        cam.CamRayFromImg(Eigen::Vector2d(o.x + u * o.size, o.y + v * o.size));
    return world_from_cam * (d / d.z());
  };
  GatherQuery::Footprint f;
  f.eye = cam.CenterInWorld();
  f.ray00 = ray(0, 0);
  f.ray_du = ray(1, 0) - f.ray00;
  f.ray_dv = ray(0, 1) - f.ray00;
  return f;
}

void SolverState::GatherAll() {
  const auto start = Clock::now();
  light.lightings.resize(scene.lightings.size());
  light.point.assign(obs.size(), -1);
  GatherOptions go;
  go.light_samples = options.light_samples;
  go.indirect_rays = options.indirect_rays;
  go.specular_bounces = options.specular_bounces;
  go.footprint_samples = options.footprint_samples;
  go.seed = options.seed;
  go.num_threads = options.num_threads;
  for (size_t l = 0; l < scene.lightings.size(); ++l) {
    if (options.show_progress)
      go.progress_label = "igi-solve: gathering " + scene.lightings[l].name;
    if (!lighting_scenes[l]) continue;
    LightingState& st = light.lightings[l];
    st.active = true;
    std::vector<GatherQuery> queries;
    for (size_t i = 0; i < obs.size(); ++i) {
      if (scene.photos[obs[i].photo].lighting != int(l)) continue;
      const Observation& o = obs[i];
      GatherQuery q;
      q.position = o.position.cast<double>();
      const Eigen::Vector3d fn = scene.mesh.FaceNormal(o.triangle).cast<double>();
      q.n_geo = fn.dot(o.view.cast<double>()) >= 0 ? fn : -fn;
      q.n_s = o.normal.cast<double>();
      q.view = o.view.cast<double>();
      q.lobe = recon::HasSpecularLobe(materials[o.region].params.model);
      if (options.pixel_footprint) q.footprint = PixelFootprint(o);
      light.point[i] = static_cast<int>(queries.size());
      st.obs.push_back(int(i));
      queries.push_back(q);
    }
    st.first_patch_point = static_cast<int>(queries.size());
    for (int p = 0; p < patches.size(); ++p) {
      GatherQuery q;
      q.position = patches.center[p].cast<double>();
      q.n_geo = scene.mesh.FaceNormal(patches.patch_triangle[p]).cast<double>();
      q.n_s = patches.normal[p].cast<double>();
      queries.push_back(q);
    }
    st.gather = Gather(*lighting_scenes[l], patches, queries, go);
    summary.rays += st.gather.rays;
    st.patch_d.assign(patches.size(), Eigen::Vector3f::Zero());
    st.patch_e.assign(patches.size(), Eigen::Vector3f::Zero());
    for (int p = 0; p < patches.size(); ++p) {
      st.patch_e[p] = st.gather.points[st.first_patch_point + p].e_direct;
    }
    BuildPatchLobes(patches, materials, &st);
  }
  summary.seconds_rays += Since(start);
}

// ---------------------------------------------------------------------------------------------
// Bookkeeping around the stages.

void SolverState::SummariseRegions() {
  for (size_t r = 0; r < materials.size(); ++r) {
    const MaterialState& m = materials[r];
    RegionSolution& rs = summary.regions[r];
    rs.name = scene.materials[r].name;
    rs.observations = m.observations;
    if (m.unknown_rho_d) rs.unknowns.push_back("rho_d");
    if (m.unknown_rho_s) rs.unknowns.push_back("rho_s");
    if (m.unknown_sigma) rs.unknowns.push_back("sigma");
    if (m.unknown_alpha) {
      if (recon::IsAnisotropic(m.params.model)) {
        rs.unknowns.push_back("alpha_x");
        rs.unknowns.push_back("alpha_y");
      } else {
        rs.unknowns.push_back("alpha");
      }
    }
    rs.status = !m.NeedsFit()         ? RegionStatus::kKnown
                : m.observations == 0 ? RegionStatus::kUnobserved
                                      : RegionStatus::kSolved;
    if (rs.status == RegionStatus::kUnobserved) {
      spdlog::warn("region {} has unknown values but no photo sees it: its values are placeholders",
                   rs.name);
    }
  }
}

// The albedo texel: the option, else the median footprint of the observations' pixel grid
// (distance / focal length, times the pixel stride), so a texel holds about one observation per
// photo.
void SolverState::ChooseTexelSize() {
  if (options.texel_size_m > 0) {
    summary.texel_size_m = summary.map_texel_size_m = options.texel_size_m;
    return;
  }
  std::vector<double> footprints, photo_footprints;
  for (size_t i = 0; i < obs.size(); i += 7) {
    const Observation& o = obs[i];
    const recon::Camera& cam = scene.cameras[scene.photos[o.photo].camera];
    const double d = (cam.CenterInWorld() - o.position.cast<double>()).norm();
    // The observations' spacing on the photo: the stride, widened where they were drawn.
    photo_footprints.push_back(d / cam.params[0] * options.pixel_stride);
    footprints.push_back(photo_footprints.back() / std::sqrt(obs.DrawnShare(o.region, false)));
  }
  if (footprints.empty()) {
    summary.texel_size_m = summary.map_texel_size_m = 0.01;
    return;
  }
  auto median = [](std::vector<double>& v) {
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return std::max(1e-4, v[v.size() / 2]);
  };
  summary.texel_size_m = median(footprints);
  summary.map_texel_size_m = median(photo_footprints);
}

void SolverState::AnalyseCoverage() {
  HighlightCoverageOptions ho;
  summary.coverage = AnalyseHighlightCoverage(scene, obs.items, lighting_scenes, ho);
  for (const RegionHighlightCoverage& c : summary.coverage) {
    if (c.region < 0 || c.region >= int(materials.size()) || c.observed) continue;
    MaterialState& m = materials[c.region];
    if (!(m.unknown_rho_s || m.unknown_alpha) || m.observations == 0) continue;
    m.no_highlight = true;
    m.params.rho_s.setZero();
    summary.regions[c.region].status = RegionStatus::kNoHighlight;
    spdlog::warn(
        "region {}: no photo shows its highlight; rho_s and alpha cannot be recovered "
        "(rho_s held at 0)",
        c.name);
  }
}

void SolverState::FinishRegions() {
  for (size_t r = 0; r < materials.size(); ++r) {
    RegionSolution& rs = summary.regions[r];
    if (rs.status == RegionStatus::kUnobserved && materials[r].bounce_fit_sigma.allFinite()) {
      // Its ρd fitted to the light it bounces onto the seen regions (FitUnobservedAlbedos); its
      // lobe cannot be known: no gloss.
      rs.bounce_fit_sigma = materials[r].bounce_fit_sigma;
      if (materials[r].unknown_rho_s) materials[r].params.rho_s.setZero();
    } else if (rs.status == RegionStatus::kUnobserved) {
      // Placeholders so that the scene renders: the observed regions' mean albedo, no gloss.
      Eigen::Vector3d mean = Eigen::Vector3d::Zero();
      int n = 0;
      for (const MaterialState& m : materials) {
        if (m.reflective && m.observations > 0) mean += m.params.rho_d, ++n;
      }
      materials[r].params.rho_d =
          n > 0 ? Eigen::Vector3d(mean / n) : Eigen::Vector3d::Constant(0.5);
      if (materials[r].unknown_rho_s) materials[r].params.rho_s.setZero();
    }
    // A region with an albedo map: its ρd is the map's mean over the texels the photos show
    // (equal areas: a texel is texel_size_m square on the surface), the albedo the written scene
    // renders there. The fit's region mean (each patch with samples weighted by its area, in
    // report.json's paper/refined blocks) weights each patch's texture by where its samples
    // crowd and by its irradiance: +1.7 % on SolveAlbedoTruth's floor where the map's mean is
    // within 0.2 % of the true texture's over the same texels (bench/RESULTS.md).
    if (rs.albedo_map && rs.albedo_map_seen_mean.allFinite() &&
        rs.albedo_map_seen_mean.minCoeff() > 0) {
      rs.rho_d_from_map = true;
      materials[r].params.rho_d = rs.albedo_map_seen_mean;
    }
    BoundReflectances(r);
    rs.final_params = materials[r].params;
  }
}

int ReportStride(int width, int height, int pixel_stride) {
  const int side = std::max(width, height);
  return std::max(pixel_stride, (side + kReportMaxSide - 1) / kReportMaxSide);
}

int ScaleMapHeldAtOne(const Eigen::Vector3d& factor, Image* map) {
  int clipped = 0;
  for (int y = 0; y < map->height; ++y) {
    for (int x = 0; x < map->width; ++x) {
      for (int c = 0; c < std::min(map->channels, 3); ++c) {
        if (factor[c] == 1.0) continue;
        float& v = map->at(x, y, c);
        v = float(v * factor[c]);
        if (v > 1.0f) {
          v = 1.0f;
          ++clipped;
        }
      }
    }
  }
  return clipped;
}

// scene.json refuses a reflectance above 1, and no passive surface has one: a fitted ρd or ρs
// above 1 is held at 1 (the fit's value goes to the report), the albedo map is scaled by the same
// factor per channel and its texels clipped at 1. The photos' excess stays in the residual, where
// igi-diagnose can look for its cause.
void SolverState::BoundReflectances(size_t r) {
  RegionSolution& rs = summary.regions[r];
  render::BrdfParams& p = materials[r].params;
  Eigen::Vector3d map_factor = Eigen::Vector3d::Ones();
  for (int c = 0; c < 3; ++c) {
    if (p.rho_d[c] > 1) {
      rs.rho_d_fitted = p.rho_d;
      map_factor[c] = 1 / p.rho_d[c];
    }
    if (p.rho_s[c] > 1) rs.rho_s_fitted = p.rho_s;
  }
  p.rho_d = p.rho_d.cwiseMin(1.0);
  p.rho_s = p.rho_s.cwiseMin(1.0);
  if (rs.albedo_map) rs.albedo_texels_clipped += ScaleMapHeldAtOne(map_factor, &*rs.albedo_map);
  if (rs.albedo_map && rs.albedo_map_seen &&
      (map_factor != Eigen::Vector3d::Ones() || rs.albedo_texels_clipped > 0)) {
    rs.albedo_map_seen_mean = SeenTexelMean(*rs.albedo_map, *rs.albedo_map_seen);
  }
  if (rs.rho_d_fitted.allFinite() || rs.rho_s_fitted.allFinite()) {
    const Eigen::Vector3d d = rs.rho_d_fitted.allFinite() ? rs.rho_d_fitted : p.rho_d;
    const Eigen::Vector3d s = rs.rho_s_fitted.allFinite() ? rs.rho_s_fitted : p.rho_s;
    spdlog::warn(
        "region {}: the fit wants a reflectance above 1 (rho_d {:.3f} {:.3f} {:.3f}, rho_s "
        "{:.3f}): the photos are brighter than any passive surface under the scene's lights "
        "(check the lights' power and the photos' exposure_scale, or run igi-diagnose); held at 1",
        rs.name, d[0], d[1], d[2], s.maxCoeff());
  }
}

}  // namespace igi::solver
