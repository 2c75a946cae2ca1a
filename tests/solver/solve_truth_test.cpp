// igi-solve against known truth (the accuracy targets' evidence):
//  - the independent RADIANCE room (../shared/data/reference/radiance_room, every value known):
//    material values stripped, solved, compared with truth.json;
//  - an igi-synth room (Ward regions with highlights, a textured glossy floor), noise-free and
//    with realistic sensor noise, plus relighting under the lighting no photo used.
// Tolerances are stated at each check with the measured values they guard.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "recon/scene.h"
#include "solver/inverse/albedo_map.h"
#include "solver/inverse/solve.h"
#include "solver/render/ray_scene.h"
#include "solver/render/render.h"
#include "solver/synth/synthesize.h"
#include "tests/temp_dir.h"
#include "tools/common/image.h"
#include "tools/common/json.h"

namespace igi::solver {
namespace {
namespace fs = std::filesystem;

const fs::path kRoom = fs::path(IGI_SHARED_DATA_DIR) / "reference" / "radiance_room";

// A copy of `scene_json` with every material reduced to its "brdf" (all values unknown) and
// paths made absolute, written into `dir`.
fs::path StrippedScene(const fs::path& scene_json, const fs::path& dir) {
  Json doc = ReadJsonFile(scene_json);
  const fs::path base = scene_json.parent_path();
  for (Json& g : doc["geometry"]) g["file"] = (base / g["file"].get<std::string>()).string();
  for (auto& [name, m] : doc["materials"].items()) m = Json{{"brdf", m["brdf"]}};
  for (Json& p : doc["photos"]) p["file"] = (base / p["file"].get<std::string>()).string();
  fs::create_directories(dir);
  WriteJsonFile(dir / "scene.json", doc);
  return dir / "scene.json";
}

double RelErr(double a, double b) { return std::abs(a - b) / std::abs(b); }

// The mean of `truth` (a texture on the region's UVs) over its texels whose centres look up seen
// texels of the solver's map (`seen`, 1 = estimated from observations).
Eigen::Vector3d SeenMean(const Image& truth, const Image& seen) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int n = 0;
  for (int y = 0; y < truth.height; ++y) {
    for (int x = 0; x < truth.width; ++x) {
      const Eigen::Vector2d uv((x + 0.5) / truth.width, 1.0 - (y + 0.5) / truth.height);
      if (render::SampleTexture(seen, uv)[0] < 1.0) continue;
      for (int c = 0; c < 3; ++c) sum[c] += truth.at(x, y, c);
      ++n;
    }
  }
  return sum / std::max(1, n);
}

TEST(SolveTruth, RadianceRoomMatchesTheIndependentRenderersValues) {
  const fs::path tmp = test::UniqueTempDir("solve_radiance");
  const recon::Scene scene = recon::LoadScene(StrippedScene(kRoom / "scene.json", tmp));
  SolveOptions o;
  o.albedo_maps = AlbedoMaps::kNone;
  o.refine_iterations = 1;
  const SolveSummary s = Solve(scene, o, tmp / "out");
  const Json truth = ReadJsonFile(kRoom / "truth.json")["materials"];
  for (const RegionSolution& r : s.regions) {
    const Json& t = truth[r.name];
    ASSERT_EQ(r.status, RegionStatus::kSolved) << r.name;
    for (int c = 0; c < 3; ++c) {
      const double want = t["rho_d"][c].get<double>();
      // Target: within 2 %. Measured (paper stage): at most 0.45 %.
      EXPECT_LT(RelErr(r.stage1.rho_d[c], want), 0.02) << r.name << " paper rho_d[" << c << "]";
      // The path-traced refinement: measured within 1 % (its noisier gathering moves them).
      EXPECT_LT(RelErr(r.stage2.rho_d[c], want), 0.03) << r.name << " refined rho_d[" << c << "]";
    }
    if (t.contains("rho_s")) {
      // Target: within 10 %. Measured: rho_s 0.0 %, alpha +0.2 % (paper); -0.4 %, -0.4 %.
      for (const RegionFitResult* f : {&r.stage1, &r.stage2}) {
        EXPECT_LT(RelErr(f->rho_s.mean(), t["rho_s"].get<double>()), 0.10) << r.name;
        EXPECT_LT(RelErr(f->alpha, t["alpha"].get<double>()), 0.10) << r.name;
        EXPECT_TRUE(std::isfinite(f->sigma_alpha)) << r.name;
      }
    }
  }
  EXPECT_TRUE(s.converged) << s.message;
  // Rendered at the observed pixels, the model reproduces the photos to within RADIANCE's own
  // noise (2.4-5 % per pixel): measured 4.9 % (paper) and 5.6 % (refined).
  EXPECT_LT(s.stage1_render_residual, 0.09);
  EXPECT_LT(s.stage2_render_residual, 0.09);
  ASSERT_EQ(s.coverage.size(), 1u);
  EXPECT_TRUE(s.coverage[0].observed);
}

// The residual the report states ("rendered at the observed pixels") is of the model as written.
// The written scene.json is rendered here twice per photo (independent seeds, 128 paths each) and
// Σ(r1 − p)(r2 − p) over the observed pixels estimates its residual without the renders' own
// noise, as the report's two halves do; the two must agree.
// - "no_maps": with --albedo-maps none a region the fit treats per patch (its albedo varies from
//   patch to patch) is written with one albedo, and the report renders that albedo, not its
//   per-patch map (rendered with the map on a two-lighting capture: reported 0.153, 0.48 as
//   written). Measured: reported 0.1604, the written model 0.1608; with the fit's per-patch
//   albedo map instead, 0.108 reported.
// - "texel_maps": every region textured finer than the patches, --albedo-maps auto: three
//   regions whose fit keeps one albedo get a map from the texel test (BuildAlbedoMaps), which the
//   report renders, not that one albedo. Measured: reported 0.1766, the written model 0.1708
//   (1.034); with the one albedo instead, 0.1844 reported (1.080).
struct WrittenCase {
  std::string name;
  AlbedoMaps albedo_maps;
  bool textured_walls;
};

void PrintTo(const WrittenCase& c, std::ostream* os) { *os << c.name; }

class SolveWritten : public ::testing::TestWithParam<WrittenCase> {};

TEST_P(SolveWritten, ReportedRenderResidualIsOfTheWrittenModel) {
  const fs::path tmp = test::UniqueTempDir("solve_written");
  synth::SynthOptions so;
  so.out = tmp / "capture";
  so.cameras = 4;
  so.spp = 64;
  so.textured_walls = GetParam().textured_walls;
  synth::Synthesize(so);
  const recon::Scene scene = recon::LoadScene(so.out / "scene.json");
  SolveOptions o;
  o.albedo_maps = GetParam().albedo_maps;
  o.refine_iterations = 0;
  const SolveSummary s = Solve(scene, o, tmp / "out");
  WriteSolveOutputs(s, o, tmp / "out");
  const recon::Scene written = recon::LoadScene(tmp / "out" / "scene.json");
  int mapped = 0;
  for (size_t r = 0; r < written.materials.size(); ++r) {
    const recon::Material& m = written.materials[r];
    if (o.albedo_maps == AlbedoMaps::kNone) EXPECT_FALSE(m.rho_d_map) << m.name;
    if (m.rho_d_map && s.regions[r].stage1.albedo_model == AlbedoModel::kConstant) ++mapped;
  }
  // The case's point: regions fitted with one albedo and written with a map.
  if (o.albedo_maps != AlbedoMaps::kNone) EXPECT_GE(mapped, 2);
  double num = 0, den = 0;
  for (size_t k = 0; k < written.photos.size(); ++k) {
    const recon::Photo& ph = written.photos[k];
    const render::Renderer renderer(written, ph.lighting);
    render::RenderOptions ro;
    ro.spp = 128;
    ro.show_progress = false;
    ro.seed = 2 * k + 1;
    const Image r1 = renderer.Render(written.cameras[ph.camera], ro);
    ro.seed = 2 * k + 2;
    const Image r2 = renderer.Render(written.cameras[ph.camera], ro);
    const PhotoResidual& pr = s.residuals[k];
    const int stride = o.pixel_stride;
    for (int y = 0; y < pr.photo.height; ++y) {
      for (int x = 0; x < pr.photo.width; ++x) {
        if (pr.photo.at(x, y, 0) == 0 && pr.photo.at(x, y, 1) == 0) continue;  // not observed
        for (int c = 0; c < 3; ++c) {
          const double p = pr.photo.at(x, y, c);
          // The observation's pixel (solver/inverse/observations.cpp: the middle of each stride
          // cell).
          const int px = x * stride + stride / 2;
          const int py = std::min(y * stride + stride / 2, r1.height - 1);
          num += (r1.at(px, py, c) - p) * (r2.at(px, py, c) - p);
          den += p * p;
        }
      }
    }
  }
  const double measured = std::sqrt(std::max(0.0, num) / den);
  std::printf("reported %.4f (standard error %.4f), the written model rendered %.4f\n",
              s.stage1_render_residual,
              s.stage1_render_residual_sq_se / (2 * s.stage1_render_residual), measured);
  EXPECT_GT(s.stage1_render_residual, 0.93 * measured);
  EXPECT_LT(s.stage1_render_residual, 1.06 * measured);
}

INSTANTIATE_TEST_SUITE_P(Cases, SolveWritten,
                         ::testing::Values(WrittenCase{"no_maps", AlbedoMaps::kNone, false},
                                           WrittenCase{"texel_maps", AlbedoMaps::kAuto, true}),
                         [](const auto& info) { return info.param.name; });

struct SynthCase {
  std::string name;
  bool noise;
  int spp;  // the photos' paths per pixel
};

void PrintTo(const SynthCase& c, std::ostream* os) { *os << c.name; }

class SolveSynth : public ::testing::TestWithParam<SynthCase> {};

TEST_P(SolveSynth, RecoversTheRoomsMaterialsAndRelightsIt) {
  const fs::path tmp = test::UniqueTempDir("solve_synth");
  synth::SynthOptions so;
  so.out = tmp / "capture";
  so.spp = GetParam().spp;
  if (GetParam().noise) so.noise = synth::NoiseModel::kRealistic;
  synth::Synthesize(so);
  const recon::Scene scene = recon::LoadScene(so.out / "scene.json");
  SolveOptions o;  // igi-solve's defaults: two refinement rounds
  const SolveSummary s = Solve(scene, o, tmp / "out");
  WriteSolveOutputs(s, o, tmp / "out");
  const Json truth = ReadJsonFile(so.out / "truth.json")["materials"];
  for (const RegionSolution& r : s.regions) {
    const Json& t = truth[r.name];
    const RegionFitResult& f = r.stage1;
    if (r.name == "floor") {
      // The textured glossy floor. Its region mean is compared with the true texture's mean over
      // the texels some photo sees (a quarter of the floor is hidden, and the tiles there
      // differ: the whole texture's mean is 2 % off the seen part's).
      ASSERT_TRUE(r.albedo_map_seen.has_value());
      const Eigen::Vector3d seen_mean =
          SeenMean(ReadImage(so.out / t["rho_d_map"].get<std::string>(), 3), *r.albedo_map_seen);
      std::printf(
          "floor: rho_d %+.2f %+.2f %+.2f %% (of the seen texels' true mean), rho_s "
          "%+.2f %%, alpha %+.2f %%\n",
          100 * (f.rho_d[0] / seen_mean[0] - 1), 100 * (f.rho_d[1] / seen_mean[1] - 1),
          100 * (f.rho_d[2] / seen_mean[2] - 1),
          100 * (f.rho_s.mean() / t["rho_s"].get<double>() - 1),
          100 * (f.alpha / t["alpha"].get<double>() - 1));
      // Measured (paper stage, 256-spp photos): rho_d +0.73..+1.19 % (clean),
      // +0.42..+0.82 % (noisy), the fit's area mean over the patches (it weights each patch's
      // texture by where its samples crowd); guarded at 2 %: the region's final rho_d is the
      // map's (below), which meets the 1 % target. The lobe is fitted with each highlight
      // sample's albedo as the other photos see its texel off their highlights
      // (solver/inverse/held_out_albedo.h), rho_s through that albedo's own lobe: rho_s -4.14 %
      // (clean), -2.32 % (noisy), alpha -3.45 %, -2.08 % at the paper's stage (64-spp photos: -2.19
      // %, -1.69 %, -1.54 %, -1.37 %); rho_s and alpha also join stage 2's joint update. The 5 %
      // target guards them. Without that, rho_s came out -10.3 % / -8.1 % (the photos' Monte Carlo
      // noise in the held-out albedos: the lobe is 14 % of the highlight samples' radiance, so 0.07
      // % of albedo error is 1 % of rho_s; bench/solver/floor_probe, bench/RESULTS.md).
      for (int c = 0; c < 3; ++c) EXPECT_LT(RelErr(f.rho_d[c], seen_mean[c]), 0.02);
      EXPECT_LT(RelErr(f.rho_s.mean(), t["rho_s"].get<double>()), 0.05);
      EXPECT_LT(RelErr(f.alpha, t["alpha"].get<double>()), 0.05);
      EXPECT_EQ(f.albedo_model, AlbedoModel::kPerPatch);  // the texture is detected
      // The region's final rho_d (scene.json's) is its albedo map's mean over the texels the
      // photos show, compared with the true texture's mean over the same texels. The 1 % target:
      // measured +0.01..+0.16 % (clean), +0.22..+0.34 % (noisy) from 256-spp photos
      // (-0.17..-0.23 % and -0.5..-0.8 % from 64-spp photos).
      ASSERT_TRUE(r.rho_d_from_map);
      const Eigen::Vector3d over_map = TextureMeanOverSeenTexels(
          ReadImage(so.out / t["rho_d_map"].get<std::string>(), 3), *r.albedo_map_seen);
      std::printf(
          "floor: final rho_d %+.2f %+.2f %+.2f %% (of the truth over the map's seen "
          "texels)\n",
          100 * (r.final_params.rho_d[0] / over_map[0] - 1),
          100 * (r.final_params.rho_d[1] / over_map[1] - 1),
          100 * (r.final_params.rho_d[2] / over_map[2] - 1));
      for (int c = 0; c < 3; ++c) {
        EXPECT_LT(RelErr(r.final_params.rho_d[c], over_map[c]), 0.01) << "final rho_d[" << c << "]";
        EXPECT_NEAR(r.final_params.rho_d[c], r.albedo_map_seen_mean[c], 1e-12);
      }
      {  // what is written: scene.json's rho_d, report.json's rho_d and its source
        const Json solved = ReadJsonFile(tmp / "out" / "scene.json")["materials"]["floor"];
        for (int c = 0; c < 3; ++c) {
          EXPECT_NEAR(solved["rho_d"][c].get<double>(), r.final_params.rho_d[c], 1e-9);
        }
        bool reported = false;
        const Json report = ReadJsonFile(tmp / "out" / "report.json");
        for (const Json& rj : report["regions"]) {
          if (rj["name"] != "floor") continue;
          reported = true;
          EXPECT_EQ(rj["rho_d_source"], "albedo_map_seen_mean");
          EXPECT_NEAR(rj["rho_d"][0].get<double>(), r.final_params.rho_d[0], 1e-9);
        }
        EXPECT_TRUE(reported);
      }
      continue;
    }
    std::printf("%s: rho_d %+.2f %+.2f %+.2f %%", r.name.c_str(),
                100 * (f.rho_d[0] / t["rho_d"][0].get<double>() - 1),
                100 * (f.rho_d[1] / t["rho_d"][1].get<double>() - 1),
                100 * (f.rho_d[2] / t["rho_d"][2].get<double>() - 1));
    if (t.contains("rho_s")) {
      std::printf(", rho_s %+.2f %%, alpha %+.2f %%",
                  100 * (f.rho_s.mean() / t["rho_s"].get<double>() - 1),
                  100 * (f.alpha / t["alpha"].get<double>() - 1));
    }
    std::printf("; final rho_d %+.2f %+.2f %+.2f %%\n",
                100 * (r.final_params.rho_d[0] / t["rho_d"][0].get<double>() - 1),
                100 * (r.final_params.rho_d[1] / t["rho_d"][1].get<double>() - 1),
                100 * (r.final_params.rho_d[2] / t["rho_d"][2].get<double>() - 1));
    for (int c = 0; c < 3; ++c) {
      // The paper's stage (stage 1), 256-spp photos: wall_x0 -1.20 / -1.02 %, the
      // glossy sphere -2.26..-2.83 % (clean / noisy; its patches' gathered indirect light is
      // 1.9 % high at these cameras' 3-4 cm per pixel and exact at twice the resolution,
      // bench/RESULTS.md), the others within 0.9 %. 3.5 % guards them; the refinement below
      // is what igi-solve writes.
      EXPECT_LT(RelErr(f.rho_d[c], t["rho_d"][c].get<double>()), 0.035)
          << r.name << " rho_d[" << c << "]";
      // The written (refined) value, the 1 % target. Measured (256-spp photos, the last round's
      // rays scaled up for regions with few observations): every region but the sphere within
      // 0.88 % (the glossy box's red, noisy; the walls and the ceiling within 0.51 %); the
      // sphere -1.14 / -1.26 / -1.31 % (clean), -1.01 / -0.86 / -1.20 % (noisy): these
      // photos themselves are 0.83 / 0.44 / 0.34 % (standard error 0.34 %) darker on the sphere
      // than a box-filtered 1024-path render of the true scene (bench/solver/ceiling_probe);
      // from 1024-spp photos (0.1 % off) the sphere comes to -0.5..-0.9 % and from another
      // scene seed's 256-spp photos to within 0.1 % (bench/RESULTS.md). The sphere
      // is guarded at 2 % from 256-spp photos. (From 64-spp photos: -2.30..+1.75 %.)
      // The "converged" cases' 1024-spp photos are within 0.1 % of the true scene's radiance
      // (the noise-free capture; "converged_noisy" adds the realistic sensor noise): there
      // the sphere too has the 1 % accuracy target. Measured, the worst written rho_d:
      // converged the sphere -0.80 %, the ceiling +0.60 %, the rest within 0.46 %;
      // converged_noisy the sphere -0.79 %, the glossy box +0.62 %, the rest within 0.40 %.
      // (The "noisy" figures at 256 spp are of 256-spp photos with the sensor noise, a case not
      // run here: converged_noisy covers the noise.)
      const double bar = r.name == "glossy_sphere" && GetParam().spp < 1024 ? 0.02 : 0.01;
      EXPECT_LT(RelErr(r.final_params.rho_d[c], t["rho_d"][c].get<double>()), bar)
          << r.name << " final rho_d[" << c << "]";
    }
    if (t.contains("rho_s")) {
      // Target: within 5 %; measured (256-spp photos; rho_s / alpha, clean and
      // noisy): glossy_box -0.1 / +0.3 % and -1.4 / +0.5 %, wall_y4 -0.0 / +1.5 % and
      // -1.2 / +2.6 %, glossy_sphere +1.4 / +0.6 % and +3.4 / +1.5 %. 5 % (the accuracy target)
      // guards them.
      EXPECT_LT(RelErr(f.rho_s.mean(), t["rho_s"].get<double>()), 0.05) << r.name;
      EXPECT_LT(RelErr(f.alpha, t["alpha"].get<double>()), 0.05) << r.name;
    }
  }
  // The floor's albedo map against the true texture (both on the floor's UVs): the estimate is
  // looked up bilinearly at the truth's texel centres. Texels no photo sees (under the boxes)
  // are filled from their neighbours and count too.
  {
    const RegionSolution& floor_solution = s.regions[scene.FindMaterial("floor")];
    ASSERT_FALSE(floor_solution.albedo_map_file.empty());
    const Image mine = ReadImage(tmp / "out" / floor_solution.albedo_map_file, 3);
    // Beside the map: which texels the photos estimate (255) and which were filled (0).
    const Image seen_png = ReadImage(tmp / "out" / "albedo" / "floor_seen.png", 1);
    ASSERT_EQ(seen_png.width, mine.width);
    ASSERT_EQ(seen_png.height, mine.height);
    double seen_share = 0;
    for (float v : seen_png.pixels) seen_share += v > 0.5f;
    seen_share /= double(seen_png.pixels.size());
    EXPECT_GT(seen_share, 0.5);  // about two thirds of the floor's texels (boxes, sphere hide some)
    EXPECT_LT(seen_share, 0.9);
    const Image want = ReadImage(so.out / truth["floor"]["rho_d_map"].get<std::string>(), 3);
    Image resampled(want.width, want.height, 3);
    double peak = 0;
    for (int y = 0; y < want.height; ++y) {
      for (int x = 0; x < want.width; ++x) {
        const Eigen::Vector3d v = render::SampleTexture(
            mine, Eigen::Vector2d((x + 0.5) / want.width, 1.0 - (y + 0.5) / want.height));
        for (int c = 0; c < 3; ++c) {
          resampled.at(x, y, c) = float(v[c]);
          peak = std::max(peak, double(want.at(x, y, c)));
        }
      }
    }
    const double psnr = AlbedoPsnr(resampled, want, peak);
    std::printf("floor albedo map: %dx%d, PSNR %.1f dB against the true texture\n", mine.width,
                mine.height, psnr);
    // The target is 35 dB (noise-free): see solve_albedo_truth_test for a texture the photos
    // resolve. Measured here 18.7 dB (18.0 dB from 64-spp photos): the tiles' edges are finer
    // than these cameras' 4.6 cm texel, most texels hold one or two observations, and a quarter
    // of the floor is seen by no photo (filled from neighbours). Guarded at 16 dB.
    EXPECT_GT(psnr, 16.0);
  }
  // Relighting: the solved scene under L1 (no photo used it) against the true scene's clean
  // render of the same view, compared with the true scene rendered again with another seed
  // (the Monte Carlo noise floor of the two 64-spp renders against the 256-spp validation).
  const recon::Scene solved = recon::LoadScene(tmp / "out" / "scene.json");
  const recon::Scene true_scene = recon::LoadScene(so.out / "truth" / "scene.json");
  const int l1 = solved.FindLighting("L1");
  ASSERT_GE(l1, 0);
  render::Renderer model(solved, l1), reference(true_scene, true_scene.FindLighting("L1"));
  render::RenderOptions ro;
  ro.spp = 64;
  ro.show_progress = false;
  const Image validation = ReadImage(so.out / "validation" / "cam0_L1.exr", 3);
  ro.seed = 101;
  const Image mine = model.Render(solved.cameras[solved.FindCamera("cam0")], ro);
  const Image again = reference.Render(true_scene.cameras[true_scene.FindCamera("cam0")], ro);
  // Compared over 8×8-pixel block means: single pixels of 64-spp renders of this room carry
  // ~45 % relative noise (fireflies off the small lamp), blocks an eighth of it.
  auto blocks = [](const Image& a) {
    std::vector<double> out;
    for (int by = 0; by + 8 <= a.height; by += 8) {
      for (int bx = 0; bx + 8 <= a.width; bx += 8) {
        for (int c = 0; c < 3; ++c) {
          double sum = 0;
          for (int y = by; y < by + 8; ++y) {
            for (int x = bx; x < bx + 8; ++x) sum += a.at(x, y, c);
          }
          out.push_back(sum / 64);
        }
      }
    }
    return out;
  };
  const std::vector<double> want = blocks(validation);
  auto rel_rms = [&](const Image& a) {
    const std::vector<double> got = blocks(a);
    double num = 0, den = 0;
    for (size_t i = 0; i < got.size(); ++i) {
      num += std::pow(got[i] - want[i], 2);
      den += std::pow(want[i], 2);
    }
    return std::sqrt(num / den);
  };
  const double floor = rel_rms(again), err = rel_rms(mine);
  std::printf("relighting cam0/L1: model %.4f, noise floor %.4f\n", err, floor);
  // Target: within 2 % relative RMS plus the noise floor (added in quadrature here), the
  // accuracy target. Measured (256-spp photos, igi-solve's defaults): 1.39 % beyond (clean: model
  // 0.0267, floor 0.0228), 1.35 % (noisy: 0.0265, 0.0228). From 64-spp photos
  // it was 2.63 %: 78 % of the squared error sat on the floor's blocks, the texel noise of a map
  // from photos that noisy (bench/solver/relight_probe, bench/RESULTS.md).
  EXPECT_LT(err, std::sqrt(floor * floor + 0.02 * 0.02));
}

INSTANTIATE_TEST_SUITE_P(Rooms, SolveSynth,
                         ::testing::Values(SynthCase{"clean", false, 256},
                                           SynthCase{"converged", false, 1024},
                                           SynthCase{"converged_noisy", true, 1024}),
                         [](const auto& test_info) { return test_info.param.name; });

}  // namespace
}  // namespace igi::solver
