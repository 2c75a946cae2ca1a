// igi-solve's albedo map against known truth, fairly (the target: "albedo maps within 35 dB PSNR of
// the truth (noise-free)"): igi-synth's default floor has grain finer than a pixel's footprint
// and one-texel grout lines, which no photo resolves. Here the floor is --floor-texture smooth
// (the same tiles and grout low-pass filtered, σ = 6.25 cm), lit by a point lamp (direct light
// without Monte Carlo noise), rendered at 256 spp and solved from every pixel; the map is
// compared with the true texture only over the texels some photo sees (the solver's
// albedo_map_seen), and over those away from unseen texels and the room's walls.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>

#include "recon/scene.h"
#include "solver/inverse/albedo_map.h"
#include "solver/inverse/solve.h"
#include "solver/synth/synthesize.h"
#include "tests/temp_dir.h"
#include "tools/common/image.h"
#include "tools/common/json.h"

namespace igi::solver {
namespace {
namespace fs = std::filesystem;

// `mask` with every texel within `radius` texels (square) of a 0 texel or of the border set to 0.
Image Eroded(const Image& mask, int radius) {
  Image out(mask.width, mask.height, 1);
  for (int y = 0; y < mask.height; ++y) {
    for (int x = 0; x < mask.width; ++x) {
      bool ok = true;
      for (int dy = -radius; dy <= radius && ok; ++dy) {
        for (int dx = -radius; dx <= radius && ok; ++dx) {
          const int xi = x + dx, yi = y + dy;
          ok = xi >= 0 && yi >= 0 && xi < mask.width && yi < mask.height && mask.at(xi, yi) > 0.5f;
        }
      }
      out.at(x, y) = ok ? 1.f : 0.f;
    }
  }
  return out;
}

double RelErr(double a, double b) { return std::abs(a - b) / std::abs(b); }

// The floor's map from photos of `spp` paths per pixel, its PSNR over the seen texels and over
// those two texels inside them held above the bars.
void CheckMapOfAResolvedTexture(int spp, double seen_bar_db, double interior_bar_db) {
  const fs::path tmp = test::UniqueTempDir("solve_albedo_truth");
  synth::SynthOptions so;
  so.out = tmp / "capture";
  so.spp = spp;
  so.lamp = synth::LampShape::kPoint;
  so.floor_texture = synth::FloorTexture::kSmooth;
  so.validation_lightings = {};
  synth::Synthesize(so);
  const recon::Scene scene = recon::LoadScene(so.out / "scene.json");
  SolveOptions o;
  o.pixel_stride = 1;       // every pixel: the map averages the photos' Monte Carlo noise
  o.texel_size_m = 0.0462;  // twice the median pixel footprint (87 × 87 texels on the floor)
  o.refine_iterations = 0;
  o.show_progress = false;
  const SolveSummary s = Solve(scene, o, tmp / "out");
  const Json truth = ReadJsonFile(so.out / "truth.json")["materials"];
  const RegionSolution& floor = s.regions[scene.FindMaterial("floor")];
  ASSERT_TRUE(floor.albedo_map.has_value());
  ASSERT_TRUE(floor.albedo_map_seen.has_value());
  const Image want = ReadImage(so.out / truth["floor"]["rho_d_map"].get<std::string>(), 3);
  double peak = 0;
  for (float v : want.pixels) peak = std::max(peak, double(v));
  const AlbedoComparison all = CompareAlbedoMaps(*floor.albedo_map, nullptr, want, peak);
  const AlbedoComparison seen =
      CompareAlbedoMaps(*floor.albedo_map, &*floor.albedo_map_seen, want, peak);
  const Image interior_mask = Eroded(*floor.albedo_map_seen, 2);
  const AlbedoComparison interior =
      CompareAlbedoMaps(*floor.albedo_map, &interior_mask, want, peak);
  std::printf(
      "floor albedo map: PSNR %.2f dB (all texels), %.2f dB over the %.0f %% seen, %.2f dB "
      "over the %.0f %% two texels inside\n",
      all.psnr_db, seen.psnr_db, 100 * seen.compared, interior.psnr_db, 100 * interior.compared);
  // About three quarters of the floor is seen (the boxes and the sphere hide the rest).
  EXPECT_GT(seen.compared, 0.65);
  // The target is 35 dB (noise-free). At 256 spp: measured 33.1 dB over the seen texels and 34.9 dB
  // two texels (9 cm) inside them (32.9 / 34.4 dB before the specular bounces; 33.8 and 35.3 dB
  // with 512-spp photos then, bench/RESULTS.md): the rest is the photos' Monte Carlo noise (about
  // 7 % per pixel at 256 spp), the gathered indirect irradiance's noise, and its bias near the
  // walls and the boxes' and sphere's contacts. The adaptive smoothing of the indirect
  // irradiance (SolveOptions::smoothing_accuracy: a radius from the harmonic mean distance of
  // each observation's indirect hits) gives 33.50 and 36.33 dB (with a fixed radius 33.13 and
  // 35.01); the same capture at 2048 spp (nearly noise-free: the slow NoiseFree case below)
  // 35.49 and 39.81 dB (fixed radius 35.01, 37.43; bench/RESULTS.md). Guarded 1 dB
  // below the measured values: the interior bound fails with the fixed radius.
  EXPECT_GT(seen.psnr_db, seen_bar_db);
  EXPECT_GT(interior.psnr_db, interior_bar_db);
  std::printf("floor: rho_s %+.2f %%, alpha %+.2f %%\n",
              100 * (floor.stage1.rho_s.mean() / truth["floor"]["rho_s"].get<double>() - 1),
              100 * (floor.stage1.alpha / truth["floor"]["alpha"].get<double>() - 1));
  // The floor's lobe, fitted with each sample's albedo from the other photos (held-out, texel
  // scale): measured rho_s -2.0 %, alpha -1.5 % (-1.5 %, -0.6 % before the specular bounces;
  // -1.0 %, -0.3 % before rho_s was fitted through the held-out samples' own lobe and the
  // off-highlight test took the region's mean albedo); guarded at the 5 % target.
  EXPECT_LT(RelErr(floor.stage1.rho_s.mean(), truth["floor"]["rho_s"].get<double>()), 0.05);
  EXPECT_LT(RelErr(floor.stage1.alpha, truth["floor"]["alpha"].get<double>()), 0.05);
  // Target: region-mean albedos within 1 %. The floor's (scene.json's rho_d) is its map's mean
  // over the texels the photos show, against the true texture's over the same texels: measured
  // -0.10..-0.26 % (the fit's patch-area mean, kept in report.json, +1.73 %: it weights each
  // patch's texture by where its samples crowd).
  {
    ASSERT_TRUE(floor.rho_d_from_map);
    const Eigen::Vector3d over_map = TextureMeanOverSeenTexels(want, *floor.albedo_map_seen);
    std::printf("floor: final rho_d %+.2f %+.2f %+.2f %%\n",
                100 * (floor.final_params.rho_d[0] / over_map[0] - 1),
                100 * (floor.final_params.rho_d[1] / over_map[1] - 1),
                100 * (floor.final_params.rho_d[2] / over_map[2] - 1));
    for (int c = 0; c < 3; ++c) {
      EXPECT_LT(RelErr(floor.final_params.rho_d[c], over_map[c]), 0.01)
          << "floor rho_d[" << c << "]";
    }
  }
  // The regions of one albedo (all but the textured floor), paper stage: measured -0.56..+0.83 %
  // (glossy_box's red, rho_d 0.1, +0.83 %; the ceiling +0.27..+0.60 %; +0.59..+0.87 % with the
  // adaptive smoothing of the indirect irradiance, where the wider mean over the open ceiling
  // moved it). Without the specular bounces (SolveOptions::specular_bounces,
  // solver/inverse/gather.h) the ceiling is +2.0..+2.3 % and this fails.
  for (const RegionSolution& r : s.regions) {
    if (r.name == "floor" || !truth.contains(r.name)) continue;
    const Json& t = truth[r.name];
    std::printf("%s: rho_d %+.2f %+.2f %+.2f %%\n", r.name.c_str(),
                100 * (r.stage1.rho_d[0] / t["rho_d"][0].get<double>() - 1),
                100 * (r.stage1.rho_d[1] / t["rho_d"][1].get<double>() - 1),
                100 * (r.stage1.rho_d[2] / t["rho_d"][2].get<double>() - 1));
    for (int c = 0; c < 3; ++c) {
      EXPECT_LT(RelErr(r.stage1.rho_d[c], t["rho_d"][c].get<double>()), 0.01)
          << r.name << " rho_d[" << c << "]";
    }
  }
}

TEST(SolveAlbedoTruth, MapOfATextureThePhotosResolve) {
  CheckMapOfAResolvedTexture(256, 32.5, 35.3);
}

// The 35 dB target is for noise-free photos: the same capture at 2048 paths per pixel (123 s alone
// on 2 threads; labelled slow, run with IGI_SLOW=1). Measured:
// 35.49 dB over the seen texels, 39.81 dB two texels inside; every region's rho_d within 0.57 %.
TEST(SolveAlbedoTruth, MapOfATextureThePhotosResolveNoiseFree) {
  CheckMapOfAResolvedTexture(2048, 35.0, 37.0);
}

// igi-synth's room under a point lamp (no validation lighting) as `so` sets it otherwise, solved
// by the paper's method alone (no refinement round).
struct SolvedRoom {
  fs::path capture;
  recon::Scene scene;
  SolveOptions options;
  SolveSummary summary;
};
SolvedRoom SolveRoom(const fs::path& tmp, synth::SynthOptions so) {
  SolvedRoom room;
  so.out = room.capture = tmp / "capture";
  so.lamp = synth::LampShape::kPoint;
  so.validation_lightings = {};
  synth::Synthesize(so);
  room.scene = recon::LoadScene(so.out / "scene.json");
  room.options.refine_iterations = 0;
  room.options.show_progress = false;
  room.summary = Solve(room.scene, room.options, tmp / "out");
  return room;
}

// A texture finer than the solver's patches averages out within each patch, so the fit's
// per-patch test keeps a constant albedo, and the region's constant ρd weights the texture by
// where the samples crowd and by the irradiance: the demo's glossy box (igi-synth
// --textured-walls, a noise texture of 42 % standard deviation) came out +3.1 % off its area
// mean that way. With --albedo-maps auto such a region gets a map when two maps from disjoint
// halves of the photos agree, significantly, on a texel-to-texel variation above 10 %
// (solver/inverse/albedo_map.h SharedTexelDetail), and its ρd is the map's mean over the texels the
// photos show.
// Observations drawn to a budget (SolveOptions::max_observations,
// solver/inverse/observation_draw.h) are spaced more coarsely than the photos' pixels; the maps
// then come from their own pass over the photos (SolveOptions::albedo_map_pass,
// SolverState::StreamAlbedoMaps) at the photos' footprint. The same capture as above (smooth floor
// texture, point lamp, 64-spp photos, every pixel):
//  - solved from all of its observations, the pass reproduces the map the observations give (same
//    atlas; the pass gathers each pixel's direct light itself and takes the rest from the nearest
//    observation): within 0.2 dB of the truth's PSNR, its seen mean within 0.5 %;
//  - solved from a fifth of them (blocks of 2 × 2 pixels), the map keeps the photos' texel (the
//    fits' spacing is about √5 times coarser) and its coverage, and comes within 1.5 dB of the
//    full solve's PSNR (measured −1.07 dB: the thinned solve's indirect irradiance is averaged
//    over fewer neighbours, and its noise enters every texel), its ρd no farther from the truth.
TEST(SolveAlbedoTruth, AThinnedSolvesMapIsAtThePhotosResolution) {
  const fs::path tmp = test::UniqueTempDir("solve_albedo_thinned");
  synth::SynthOptions so;
  so.out = tmp / "capture";
  so.spp = 64;
  so.lamp = synth::LampShape::kPoint;
  so.floor_texture = synth::FloorTexture::kSmooth;
  so.validation_lightings = {};
  synth::Synthesize(so);
  const recon::Scene scene = recon::LoadScene(so.out / "scene.json");
  const Json truth = ReadJsonFile(so.out / "truth.json")["materials"];
  const Image want = ReadImage(so.out / truth["floor"]["rho_d_map"].get<std::string>(), 3);
  double peak = 0;
  for (float v : want.pixels) peak = std::max(peak, double(v));
  const int f = scene.FindMaterial("floor");
  auto solve = [&](const std::string& name, int64_t max_observations, const std::string& pass) {
    SolveOptions o;
    o.pixel_stride = 1;
    o.refine_iterations = 0;
    o.show_progress = false;
    o.max_observations = max_observations;
    o.albedo_map_pass = AlbedoMapPassFromName(pass).value();
    SolveSummary s = Solve(scene, o, tmp / name);
    const RegionSolution& r = s.regions[f];
    EXPECT_TRUE(r.albedo_map && r.albedo_map_seen) << name;
    const AlbedoComparison c =
        r.albedo_map ? CompareAlbedoMaps(*r.albedo_map, &*r.albedo_map_seen, want, peak)
                     : AlbedoComparison{};
    std::printf("%s: %d observations, map %dx%d, %.2f dB over the %.0f %% seen, rho_s %.4f\n",
                name.c_str(), s.observations, r.albedo_map ? r.albedo_map->width : 0,
                r.albedo_map ? r.albedo_map->height : 0, c.psnr_db, 100 * c.compared,
                r.final_params.rho_s.mean());
    return std::make_pair(std::move(s), c);
  };
  const auto [full, full_c] = solve("full", 0, "never");
  const auto [pass, pass_c] = solve("full_pass", 0, "always");
  const auto [thin, thin_c] = solve("thin", full.observations / 5, "auto");
  ASSERT_TRUE(full.regions[f].albedo_map && pass.regions[f].albedo_map &&
              thin.regions[f].albedo_map);
  const RegionSolution &a = full.regions[f], &p = pass.regions[f], &b = thin.regions[f];
  // The pass against the observations' map, from the same solve.
  EXPECT_EQ(p.albedo_map->width, a.albedo_map->width);
  EXPECT_NEAR(pass_c.psnr_db, full_c.psnr_db, 0.2);
  for (int c = 0; c < 3; ++c) {
    EXPECT_LT(RelErr(p.albedo_map_seen_mean[c], a.albedo_map_seen_mean[c]), 0.005) << c;
  }
  // The thinned solve.
  ASSERT_FALSE(full.observations_thinned);
  ASSERT_TRUE(thin.observations_thinned);
  EXPECT_LT(thin.observations, full.observations / 4);
  EXPECT_GT(thin.texel_size_m, 1.8 * thin.map_texel_size_m);
  EXPECT_NEAR(thin.map_texel_size_m, full.map_texel_size_m, 0.05 * full.map_texel_size_m);
  EXPECT_NEAR(b.albedo_map->width, a.albedo_map->width, 0.05 * a.albedo_map->width);
  EXPECT_GT(thin_c.compared, 0.95 * full_c.compared);
  EXPECT_GT(thin_c.psnr_db, full_c.psnr_db - 1.5);
  // Its ρd (the map's mean) no farther from the truth than the full solve's, within 0.5 %
  // (measured: full +2.0, +2.0, +1.9 %; thinned +1.1, +1.1, +1.5 %).
  const Json& rho = truth["floor"]["rho_d"];
  for (int c = 0; c < 3; ++c) {
    const double t = rho[c].get<double>();
    std::printf("rho_d[%d]: truth %.4f, full %+.2f %%, thinned %+.2f %%\n", c, t,
                100 * (a.final_params.rho_d[c] / t - 1), 100 * (b.final_params.rho_d[c] / t - 1));
    EXPECT_LT(RelErr(b.final_params.rho_d[c], t), RelErr(a.final_params.rho_d[c], t) + 0.005) << c;
  }
  fs::remove_all(tmp);
}

TEST(SolveAlbedoTruth, AGlossyRegionsFineTextureGetsAMap) {
  synth::SynthOptions so;
  so.textured_walls = true;
  // The ceiling photographed (an unseen ceiling's placeholder albedo biases every region's
  // bounced light by several per cent, which would hide what this test looks at).
  so.cameras = 10;
  so.ceiling_cameras = 2;
  const SolvedRoom room = SolveRoom(test::UniqueTempDir("solve_fine_texture"), so);
  const recon::Scene& scene = room.scene;
  const SolveSummary& s = room.summary;
  const Json truth = ReadJsonFile(room.capture / "truth.json")["materials"];
  const Json report = SolveReportJson(s, room.options);
  for (const char* name : {"glossy_box", "glossy_sphere"}) {
    const RegionSolution& r = s.regions[scene.FindMaterial(name)];
    const Image texture = ReadImage(room.capture / truth[name]["rho_d_map"].get<std::string>(), 3);
    ASSERT_TRUE(r.albedo_map.has_value()) << name << ": texel variation " << r.texel_variation;
    ASSERT_TRUE(r.albedo_map_seen.has_value());
    EXPECT_TRUE(r.rho_d_from_map) << name;
    // A region whose per-patch test does not see its texture (patches too coarse for it) gets
    // its map from the texel test.
    if (!r.stage1.albedo_varies) {
      EXPECT_GT(r.texel_variation, 0.1) << name;
      EXPECT_GT(r.texel_variation_z, 3) << name;
    }
    const Eigen::Vector3d want = TextureMeanOverSeenTexels(texture, *r.albedo_map_seen);
    std::printf(
        "%s: texel variation %.1f %% (z %.1f); rho_d from the map %+.2f %%, the constant fit's "
        "%+.2f %% (against the true texture's mean over the map's seen texels)\n",
        name, 100 * r.texel_variation, r.texel_variation_z,
        100 * (r.final_params.rho_d.mean() / want.mean() - 1),
        100 * (r.stage1.rho_d.mean() / want.mean() - 1));
    // Measured: the box -0.42 % (its constant fit +0.36 %), the sphere -0.59 % (its stage-1 fit
    // +3.07 %; both per patch); this small capture's walls and ceiling are off by up to 5 %
    // themselves (160 x 120 photos), which the regions' bounced light inherits. The demo's
    // (480 x 360): box -0.2 %, sphere -0.5 % (constant fits +3.1 %, +1.1 %).
    EXPECT_LT(RelErr(r.final_params.rho_d.mean(), want.mean()), 0.02) << name;
    if (std::string(name) != "glossy_sphere") continue;
    EXPECT_LT(RelErr(r.final_params.rho_d.mean(), want.mean()),
              RelErr(r.stage1.rho_d.mean(), want.mean()));
    bool reported = false;
    for (const Json& rj : report["regions"]) {
      if (rj["name"] != name) continue;
      const bool texel_test =
          r.stage1.albedo_varies ||
          (rj.contains("texel_variation") && rj["texel_variation"]["mapped"].get<bool>());
      reported =
          rj.contains("albedo_map") && texel_test && rj["rho_d_source"] == "albedo_map_seen_mean";
    }
    EXPECT_TRUE(reported) << name << ": report.json's texel_variation and albedo_map";
  }
}

// The same room with one albedo per region: the glossy regions' texel-to-texel variation stays
// below the bar (their albedo constant, the photos' noise and the smooth errors of the gathered
// irradiance left out by the split halves and the local means), and they get no map.
TEST(SolveAlbedoTruth, ConstantGlossyRegionsGetNoMap) {
  const SolvedRoom room =
      SolveRoom(test::UniqueTempDir("solve_no_fine_texture"), synth::SynthOptions{});
  for (const char* name : {"glossy_box", "glossy_sphere"}) {
    const RegionSolution& r = room.summary.regions[room.scene.FindMaterial(name)];
    std::printf("%s: texel variation %.1f %% (z %.1f)\n", name, 100 * r.texel_variation,
                r.texel_variation_z);
    ASSERT_TRUE(std::isfinite(r.texel_variation)) << name;
    EXPECT_LT(r.texel_variation, 0.1) << name;
    EXPECT_FALSE(r.albedo_map.has_value()) << name;
  }
}

// A lobe of the wrong shape is no texture. igi-diagnose's grazing specular_lobe_shape capture
// (every glossy region truly Ward-GMD, declared Ward; the lamp 0.6 m high, a camera on the
// floor's highlight at 60-80 degrees; the ceiling, which no photo sees, given): the Ward fit
// leaves the sphere's diffuse residual patterned where its lobe is wrong, grey (ρs has no colour)
// on a sphere whose green and blue albedos are 0.15 and 0.1. Measured as the mean of each
// channel's relative variance it read 10.8 % and gave the sphere a map, which then absorbed the
// lobe's shape before igi-diagnose could name it; an albedo texture multiplies every channel
// alike, so the measure is the channels' summed detail variance over their summed mean²: 5.1 %.
TEST(SolveAlbedoTruth, AWrongLobeShapeIsNoTexture) {
  const fs::path tmp = test::UniqueTempDir("solve_lobe_no_texture");
  synth::SynthOptions so;
  so.out = tmp / "capture";
  so.cameras = 4;
  so.seed = 11;
  so.lamp = synth::LampShape::kPoint;
  so.lamp_position = Eigen::Vector3d(2, 2, 0.6);
  so.grazing_cameras = 1;
  so.validation_lightings = {};
  so.effects.push_back(synth::ParseEffectSpec("specular_lobe_shape"));
  synth::Synthesize(so);
  recon::Scene scene = recon::LoadScene(so.out / "scene.json");
  const Json truth = ReadJsonFile(so.out / "truth.json")["materials"];
  recon::Material& ceiling = scene.materials[scene.FindMaterial("ceiling")];
  ASSERT_FALSE(ceiling.rho_d.has_value());
  const std::vector<double> rho = truth["ceiling"]["rho_d"].get<std::vector<double>>();
  ceiling.rho_d = Eigen::Vector3d(rho[0], rho[1], rho[2]);
  SolveOptions options;
  options.show_progress = false;
  const SolveSummary s = Solve(scene, options, tmp / "out");
  const RegionSolution& r = s.regions[scene.FindMaterial("glossy_sphere")];
  std::printf("glossy_sphere: texel variation %.1f %%\n", 100 * r.texel_variation);
  ASSERT_TRUE(std::isfinite(r.texel_variation));
  EXPECT_LT(r.texel_variation, 0.1);
  EXPECT_FALSE(r.albedo_map.has_value());
}

// With the lamp 0.6 m above the floor no camera sees the ceiling (the cameras look down at the
// lit floor), yet half the light on the walls is the ceiling's: its ρd is fitted to the light it
// bounces onto the regions the photos show (solver/inverse/paper_stage.h FitUnobservedAlbedos).
// Before, it kept a placeholder (the seen regions' mean albedo, 0.495 against the true 0.8), and
// the walls' albedos absorbed the missing light.
TEST(SolveAlbedoTruth, AnUnseenCeilingsAlbedoFromTheLightItBounces) {
  synth::SynthOptions so;
  so.lamp_position = Eigen::Vector3d(2, 2, 0.6);
  const SolvedRoom room = SolveRoom(test::UniqueTempDir("solve_unseen_ceiling"), so);
  const Json truth = ReadJsonFile(room.capture / "truth.json")["materials"];
  const RegionSolution& ceiling = room.summary.regions[room.scene.FindMaterial("ceiling")];
  ASSERT_EQ(ceiling.status, RegionStatus::kUnobserved);
  ASSERT_TRUE(ceiling.RhoDFromBouncedLight());
  const Eigen::Vector3d want(truth["ceiling"]["rho_d"][0].get<double>(),
                             truth["ceiling"]["rho_d"][1].get<double>(),
                             truth["ceiling"]["rho_d"][2].get<double>());
  std::printf("ceiling (unseen): rho_d %.3f %.3f %.3f (truth %.3f), relative sigma %.3f\n",
              ceiling.final_params.rho_d[0], ceiling.final_params.rho_d[1],
              ceiling.final_params.rho_d[2], want[0], ceiling.bounce_fit_sigma.maxCoeff());
  for (int c = 0; c < 3; ++c) {
    EXPECT_LT(RelErr(ceiling.final_params.rho_d[c], want[c]), 0.1) << "ceiling rho_d[" << c << "]";
  }
  for (const char* name : {"wall_x0", "wall_x4", "wall_y0", "wall_y4", "matte_box"}) {
    const RegionSolution& r = room.summary.regions[room.scene.FindMaterial(name)];
    if (r.status != RegionStatus::kSolved) continue;
    const Json& t = truth[name]["rho_d"];
    std::printf("%s: rho_d %+.2f %+.2f %+.2f %%\n", name,
                100 * (r.final_params.rho_d[0] / t[0].get<double>() - 1),
                100 * (r.final_params.rho_d[1] / t[1].get<double>() - 1),
                100 * (r.final_params.rho_d[2] / t[2].get<double>() - 1));
    // Measured: ceiling 0.786 / 0.776 / 0.769, the walls and the matte box
    // -0.1..+2.1 %. With the placeholder (sphere lamp, same cameras) the walls were +4..+11 %.
    for (int c = 0; c < 3; ++c) {
      EXPECT_LT(RelErr(r.final_params.rho_d[c], t[c].get<double>()), 0.03) << name << c;
    }
  }
}

}  // namespace
}  // namespace igi::solver
