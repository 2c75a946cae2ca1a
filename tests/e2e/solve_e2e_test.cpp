// igi-solve end to end on small box rooms built in a temporary folder: bad input exits 2 with
// one line naming the file and key and writes nothing; a region no photo sees gives exit 3 with
// the outputs written; and a room photographed by igi-render itself is solved back to its
// albedos, and the solved scene renders again.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "tests/e2e/box_room.h"
#include "tests/e2e/run.h"
#include "tests/temp_dir.h"
#include "tools/common/atomic_file.h"
#include "tools/common/image.h"
#include "tools/common/json.h"

namespace igi {
namespace {

namespace fs = std::filesystem;
using test::Quote;
using test::RunTool;

// Fast settings for every solve (the task of this binary is the tool's behaviour, not accuracy
// at full settings).
const std::string kFast =
    " --threads 2 --quiet --pixel-stride 2 --indirect-rays 32 --refine-iterations 1";

using test::box_room::kHeight;
using test::box_room::kWidth;
using test::box_room::PhotoEntry;
using test::box_room::RoomObj;
using test::box_room::SceneDoc;
using test::box_room::TrueMaterials;

Image Constant(int w, int h, int channels, float value) {
  Image im;
  im.width = w;
  im.height = h;
  im.channels = channels;
  im.pixels.assign(size_t(w) * h * channels, value);
  return im;
}

class SolveE2E : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::UniqueTempDir("igi_solve_e2e");
    fs::create_directories(dir_ / "scene" / "geometry");
    fs::create_directories(dir_ / "scene" / "photos");
    fs::create_directories(dir_ / "out");
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path SceneDir() const { return dir_ / "scene"; }
  fs::path Out() const { return dir_ / "out"; }

  void WriteGeometry(bool hidden) const {
    std::ofstream(SceneDir() / "geometry" / "room.obj") << RoomObj(hidden);
  }

  // Photos of both cameras under L0, rendered by igi-render from the true materials.
  void RenderPhotos(bool hidden) const {
    WriteGeometry(hidden);
    WriteJsonFile(SceneDir() / "render.json", SceneDoc(TrueMaterials(hidden), Json::array()));
    for (const char* cam : {"cam0", "cam1"}) {
      const fs::path exr = SceneDir() / "photos" / (std::string(cam) + "_L0.exr");
      const auto r =
          RunTool("igi-render", Quote((SceneDir() / "render.json").string()) + " --camera " + cam +
                                    " --lighting L0 --spp 256 --threads 2 --quiet --out " +
                                    Quote(exr.string()));
      ASSERT_EQ(r.exit_code, 0) << r.err;
    }
  }

  fs::path WriteScene(const Json& doc) const {
    const fs::path p = SceneDir() / "scene.json";
    WriteJsonFile(p, doc);
    return p;
  }

  test::RunResult Solve(const fs::path& scene, const fs::path& out,
                        const std::string& extra = "") const {
    return RunTool("igi-solve",
                   Quote(scene.string()) + " --out " + Quote(out.string()) + kFast + extra);
  }

  // Solve with igi-solve's log on stderr (kFast without --quiet).
  test::RunResult SolveLogged(const fs::path& scene, const std::string& extra) const {
    std::string logged = kFast;
    logged.erase(logged.find(" --quiet"), 8);
    return RunTool("igi-solve",
                   Quote(scene.string()) + " --out " + Quote(Out().string()) + logged + extra);
  }

  // igi-render of the solved scene (Out()/scene.json) from `camera` under L0, at 2 spp.
  test::RunResult RenderSolved(const std::string& camera) const {
    return RunTool("igi-render", Quote((Out() / "scene.json").string()) + " --camera " + camera +
                                     " --lighting L0 --spp 2 --quiet --out " +
                                     Quote((dir_ / "check.exr").string()));
  }

  // Both cameras' photos of the Lambertian room, every albedo stripped from its scene.json.
  fs::path LambertRoomAlbedosUnknown() const {
    RenderPhotos(false);
    Json m = TrueMaterials(false);
    for (auto& [name, material] : m.items()) material.erase("rho_d");
    return WriteScene(SceneDoc(m, Json::array({PhotoEntry("photos/cam0_L0.exr", "cam0", "L0"),
                                               PhotoEntry("photos/cam1_L0.exr", "cam1", "L0")})));
  }

  fs::path dir_;
};

// Bad input: exit 2, exactly one stderr line containing `key` and `file`, --out left empty.
void ExpectBadInput(const test::RunResult& r, const fs::path& out, const std::string& key,
                    const std::string& file) {
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find(key), std::string::npos) << "expected " << key << " in: " << r.err;
  EXPECT_NE(r.err.find(file), std::string::npos) << "expected " << file << " in: " << r.err;
  if (fs::exists(out)) {
    EXPECT_TRUE(fs::is_empty(out)) << "something was written into --out";
  }
}

// The simplest valid capture: cam0 under L0, a constant photo (bad-input checks come before
// any fitting, so the photo's values do not matter).
Json ConstantPhotoScene(const fs::path& scene_dir, const Json& photo) {
  WriteImage(scene_dir / "photos" / "cam0_L0.exr", Constant(kWidth, kHeight, 3, 0.1f));
  Json m = TrueMaterials(false);
  m["floor"].erase("rho_d");
  return SceneDoc(m, Json::array({photo}));
}

TEST_F(SolveE2E, PhotoUnderLightingWithoutLightIsBadInput) {
  WriteGeometry(false);
  const fs::path scene =
      WriteScene(ConstantPhotoScene(SceneDir(), PhotoEntry("photos/cam0_L0.exr", "cam0", "dark")));
  const auto r = Solve(scene, Out());
  ExpectBadInput(r, Out(), "photos[0].lighting", "scene.json");
  EXPECT_NE(r.err.find("dark"), std::string::npos) << r.err;
}

TEST_F(SolveE2E, PhotoWithNoValidPixelIsBadInput) {
  WriteGeometry(false);
  Image mask = Constant(kWidth, kHeight, 1, 0.0f);
  WriteImageOptions wo;
  wo.type = PixelType::kUInt8;
  WriteImage(SceneDir() / "photos" / "mask.png", mask, wo);
  const fs::path scene = WriteScene(ConstantPhotoScene(
      SceneDir(), PhotoEntry("photos/cam0_L0.exr", "cam0", "L0", "photos/mask.png")));
  const auto r = Solve(scene, Out());
  ExpectBadInput(r, Out(), "photos[0]", "cam0_L0.exr");
  EXPECT_NE(r.err.find("no valid pixel"), std::string::npos) << r.err;
}

TEST_F(SolveE2E, OutEqualToSceneFolderIsBadInput) {
  WriteGeometry(false);
  const fs::path scene =
      WriteScene(ConstantPhotoScene(SceneDir(), PhotoEntry("photos/cam0_L0.exr", "cam0", "L0")));
  const auto before = std::distance(fs::recursive_directory_iterator(SceneDir()),
                                    fs::recursive_directory_iterator());
  const auto r = Solve(scene, SceneDir());
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find("--out"), std::string::npos) << r.err;
  // Nothing added to (or removed from) the scene's folder.
  EXPECT_EQ(std::distance(fs::recursive_directory_iterator(SceneDir()),
                          fs::recursive_directory_iterator()),
            before);
  EXPECT_FALSE(fs::exists(SceneDir() / "report.json"));
}

TEST_F(SolveE2E, PhotoSizeDifferentFromCameraIsBadInput) {
  WriteGeometry(false);
  Json doc = ConstantPhotoScene(SceneDir(), PhotoEntry("photos/small.exr", "cam0", "L0"));
  WriteImage(SceneDir() / "photos" / "small.exr", Constant(kWidth / 2, kHeight / 2, 3, 0.1f));
  const auto r = Solve(WriteScene(doc), Out());
  ExpectBadInput(r, Out(), "photos[0].file", "small.exr");
}

TEST_F(SolveE2E, MaskOfAnotherSizeIsBadInput) {
  WriteGeometry(false);
  Json doc = ConstantPhotoScene(SceneDir(),
                                PhotoEntry("photos/cam0_L0.exr", "cam0", "L0", "photos/mask.png"));
  WriteImage(SceneDir() / "photos" / "mask.png", Constant(kWidth / 2, kHeight, 1, 1.0f));
  const auto r = Solve(WriteScene(doc), Out());
  ExpectBadInput(r, Out(), "photos[0].mask", "scene.json");
}

// A memory budget too small for even one photo and the scene: refused before any work, naming
// the photo and the flag (solver/inverse/solve_memory.h).
TEST_F(SolveE2E, MemoryBudgetBelowOnePhotoIsBadInput) {
  WriteGeometry(false);
  Json doc = ConstantPhotoScene(SceneDir(), PhotoEntry("photos/cam0_L0.exr", "cam0", "L0"));
  const auto r = Solve(WriteScene(doc), Out(), " --memory-budget 0.01");
  ExpectBadInput(r, Out(), "photos[0].file", "cam0_L0.exr");
  EXPECT_NE(r.err.find("--memory-budget"), std::string::npos) << r.err;
}

// A region that no photo sees (a quad behind the wall, its albedo unknown): exit 3, the region
// named on stderr, every output written, the solved scene complete enough to render.
TEST_F(SolveE2E, UnobservedRegionIsPartialAndOutputsStillRender) {
  RenderPhotos(true);
  Json m = TrueMaterials(true);
  m["floor"].erase("rho_d");
  m["hidden"].erase("rho_d");
  const fs::path scene =
      WriteScene(SceneDoc(m, Json::array({PhotoEntry("photos/cam0_L0.exr", "cam0", "L0")})));
  const auto r = Solve(scene, Out());
  ASSERT_EQ(r.exit_code, 3) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find("materials.hidden"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("materials.floor"), std::string::npos) << r.err;
  ASSERT_TRUE(fs::exists(Out() / "scene.json"));
  ASSERT_TRUE(fs::exists(Out() / "report.json"));
  const Json report = ReadJsonFile(Out() / "report.json");
  bool found_hidden = false;
  for (const Json& region : report.at("regions")) {
    if (region.at("name") == "hidden") {
      found_hidden = true;
      EXPECT_EQ(region.at("status"), "unobserved");
    } else if (region.at("name") == "floor") {
      EXPECT_EQ(region.at("status"), "solved");
    }
  }
  EXPECT_TRUE(found_hidden);
  const auto render = RenderSolved("cam0");
  EXPECT_EQ(render.exit_code, 0) << render.err;
}

// A solve that does not converge (here: one iteration of the paper's alternation, which needs two
// to measure a change) is reported, not a crash: exit 0, one warning line, report.json
// converged false with the reason, report.html's warning, and a scene.json that renders.
TEST_F(SolveE2E, NonConvergenceIsReportedNotACrash) {
  const fs::path scene = LambertRoomAlbedosUnknown();
  const auto r = SolveLogged(scene, " --max-iterations 1");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("not converged after 1 iterations"), std::string::npos) << r.err;
  const Json report = ReadJsonFile(Out() / "report.json");
  EXPECT_FALSE(report.at("converged").get<bool>());
  EXPECT_NE(report.at("message").get<std::string>().find("not converged after 1 iterations"),
            std::string::npos)
      << report.at("message");
  EXPECT_NE(ReadFileToString(Out() / "report.html").find("Stage 1 did not converge"),
            std::string::npos);
  const auto render = RenderSolved("cam0");
  EXPECT_EQ(render.exit_code, 0) << render.err;
}

// --refine-albedo-step S: each refinement round applies S of its albedo change. Round 1 starts
// from the paper stage's albedos in both runs (same seed, same model, same rays), so with
// S = 0.5 the refined albedo lies exactly halfway between the paper's and the full step's.
TEST_F(SolveE2E, RefineAlbedoStepMovesPartOfTheWay) {
  const fs::path scene = LambertRoomAlbedosUnknown();
  const fs::path full = dir_ / "full", half = dir_ / "half";
  // kFast: one refinement round.
  ASSERT_EQ(Solve(scene, full, " --refine-albedo-step 1").exit_code, 0);
  // No glossy region here: --specular-bounces false changes nothing but the report's options.
  ASSERT_EQ(Solve(scene, half, " --refine-albedo-step 0.5 --specular-bounces false").exit_code, 0);
  EXPECT_EQ(ReadJsonFile(full / "report.json")["options"]["specular_bounces"], true);
  EXPECT_EQ(ReadJsonFile(half / "report.json")["options"]["specular_bounces"], false);
  EXPECT_EQ(ReadJsonFile(half / "report.json")["options"]["refine_albedo_step"], 0.5);
  const Json a = ReadJsonFile(full / "report.json")["regions"];
  const Json b = ReadJsonFile(half / "report.json")["regions"];
  ASSERT_EQ(a.size(), b.size());
  for (size_t r = 0; r < a.size(); ++r) {
    for (int c = 0; c < 3; ++c) {
      const double paper = a[r]["paper"]["rho_d"][c], paper_b = b[r]["paper"]["rho_d"][c];
      const double step = a[r]["refined"]["rho_d"][c].get<double>() - paper;
      EXPECT_DOUBLE_EQ(paper, paper_b) << a[r]["name"];
      EXPECT_NEAR(b[r]["refined"]["rho_d"][c].get<double>(), paper + 0.5 * step, 1e-9)
          << a[r]["name"] << " channel " << c;
    }
  }
  // Out of range: one line naming the flag, exit 2.
  const auto bad = Solve(scene, dir_ / "bad", " --refine-albedo-step 0");
  EXPECT_EQ(bad.exit_code, 2) << bad.err;
  EXPECT_NE(bad.err.find("--refine-albedo-step"), std::string::npos) << bad.err;
}

// The happy path: photos rendered by igi-render from known Lambertian albedos (two views, one
// lamp), every albedo stripped, solved back. Tolerance 2 %: the photos are the same renderer's
// output, so there is no model error; what remains is the photos' Monte Carlo noise (256 spp,
// averaged over the floor's 100 observations), the solver's gathering noise at 32 indirect rays
// and one (joint) refinement round. Measured: floor -0.50 / -0.64 /
// -0.92 %, ceiling within 0.2 %, walls within 0.1 %; with the photos rendered from seeds 2 and 3
// the floor stays within 1.05 %. With 64-spp photos the floor's noise alone had put it at -3.3 %
// (seed 0; -0.5 % and -1.6 % with seeds 2 and 3), which the 3 % bound then allowed. Indirect
// light matters here: with --indirect-rays 0 --refine-iterations 0 the same test gives
// +55 % .. +207 %, so the tolerance catches a solver that loses the inter-reflections.
TEST_F(SolveE2E, RecoversLambertAlbedosOfARenderedRoom) {
  const fs::path scene = LambertRoomAlbedosUnknown();
  const auto r = Solve(scene, Out());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Json solved = ReadJsonFile(Out() / "scene.json");
  const Json truth = TrueMaterials(false);
  for (const auto& [name, material] : truth.items()) {
    const Json& rho = solved.at("materials").at(name).at("rho_d");
    ASSERT_TRUE(rho.is_array()) << name << ": " << rho.dump();
    for (int c = 0; c < 3; ++c) {
      const double want = material.at("rho_d")[c].get<double>();
      const double got = rho[c].get<double>();
      std::printf("%s[%d]: %.4f (truth %.2f, %+.2f %%)\n", name.c_str(), c, got, want,
                  100 * (got / want - 1));
      EXPECT_NEAR(got / want, 1.0, 0.02)
          << name << " channel " << c << ": " << got << " vs " << want;
    }
  }
  const Json report = ReadJsonFile(Out() / "report.json");
  EXPECT_EQ(report.at("format"), "igi-solve-report");
  for (const Json& region : report.at("regions")) EXPECT_EQ(region.at("status"), "solved");
  EXPECT_NE(ReadFileToString(Out() / "report.html").find("<img"), std::string::npos);
  const auto render = RenderSolved("cam1");
  EXPECT_EQ(render.exit_code, 0) << render.err;
  EXPECT_EQ(ReadImageInfo(dir_ / "check.exr").width, kWidth);
}

// --photo-scale solve: the photos are declared as 0.25 x radiance (exposure_scale) but are
// radiance itself, as an HDR map from a recovered response is off by an unknown constant. The
// ceiling's albedo is given (the reference); the photos' factor comes back (the report's
// photo_scale, 1 / 0.25), the solved scene's exposure_scale is the true 1, and the floor's and
// walls' albedos are right. Tolerances: 3 % on the scale and exposure (measured 3.986 ± 0.014,
// -0.4 %; with 64-spp photos 3.954, -1.2 %), 4 % on the albedos (measured floor -0.66 % at worst,
// walls +0.2 %: the happy path's error above plus the scale's, which every albedo inherits).
// Without the option the same scene solves to a floor 1.3x too bright (checked below, so the test
// fails if the option stops doing anything).
TEST_F(SolveE2E, PhotoScaleIsSolvedFromARegionOfKnownReflectance) {
  RenderPhotos(false);
  Json m = TrueMaterials(false);
  m["floor"].erase("rho_d");
  m["walls"].erase("rho_d");
  Json photos = Json::array({PhotoEntry("photos/cam0_L0.exr", "cam0", "L0"),
                             PhotoEntry("photos/cam1_L0.exr", "cam1", "L0")});
  for (Json& p : photos) p["exposure_scale"] = 0.25;
  const fs::path scene = WriteScene(SceneDoc(m, photos));
  const auto r = Solve(scene, Out(), " --photo-scale solve");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Json report = ReadJsonFile(Out() / "report.json");
  const Json& k = report.at("photo_scale");
  std::printf("photo scale %.4f ± %.4f (truth 4), %d rounds, references %s\n",
              k.at("scale").get<double>(), k.at("sigma").get<double>(), k.at("rounds").get<int>(),
              k.at("reference_regions").dump().c_str());
  EXPECT_NEAR(k.at("scale").get<double>(), 4.0, 0.03 * 4.0);
  EXPECT_EQ(k.at("reference_regions"), Json::array({"ceiling"}));
  const Json solved = ReadJsonFile(Out() / "scene.json");
  for (const Json& p : solved.at("photos")) {
    EXPECT_NEAR(p.at("exposure_scale").get<double>(), 1.0, 0.03);
  }
  const Json truth = TrueMaterials(false);
  for (const char* name : {"floor", "walls"}) {
    for (int c = 0; c < 3; ++c) {
      const double want = truth.at(name).at("rho_d")[c].get<double>();
      const double got = solved.at("materials").at(name).at("rho_d")[c].get<double>();
      std::printf("%s[%d]: %.4f (truth %.2f, %+.2f %%)\n", name, c, got, want,
                  100 * (got / want - 1));
      EXPECT_NEAR(got / want, 1.0, 0.04) << name << " channel " << c;
    }
  }
  // The same scene with the scale taken as given.
  const fs::path given_out = dir_ / "given";
  ASSERT_EQ(Solve(scene, given_out).exit_code, 0);
  const Json given = ReadJsonFile(given_out / "scene.json");
  EXPECT_GT(given.at("materials").at("floor").at("rho_d")[0].get<double>(),
            1.2 * truth.at("floor").at("rho_d")[0].get<double>());
}

// Photos brighter than the declared light can make any passive surface (the lamp declared at a
// thirtieth of the power that lit them): the fit wants albedos above 1. The written scene holds
// them at 1 (scene.json's rule, so that it loads and renders), the report keeps the fit's values,
// and one warning line names the region.
TEST_F(SolveE2E, AlbedosAboveOneAreHeldAtOneAndReported) {
  RenderPhotos(false);
  Json m = TrueMaterials(false);
  m["floor"].erase("rho_d");
  m["walls"].erase("rho_d");
  Json doc = SceneDoc(m, Json::array({PhotoEntry("photos/cam0_L0.exr", "cam0", "L0"),
                                      PhotoEntry("photos/cam1_L0.exr", "cam1", "L0")}));
  doc["lights"]["lamp"]["intensity"] = {0.1, 0.1, 0.1};
  const fs::path scene = WriteScene(doc);
  const auto r = SolveLogged(scene, " --albedo-maps all");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("region walls: the fit wants a reflectance above 1"), std::string::npos)
      << r.err;
  const Json solved = ReadJsonFile(Out() / "scene.json");
  const Json report = ReadJsonFile(Out() / "report.json");
  int bounded_channels = 0;
  for (const Json& region : report.at("regions")) {
    const std::string name = region.at("name");
    if (name == "ceiling") {
      EXPECT_FALSE(region.contains("bounded"));
      continue;
    }
    const Json& rho_d = solved.at("materials").at(name).at("rho_d");
    // The value before the bound: the fit's, or for a region with an albedo map the map's mean
    // over its seen texels (report.json rho_d_source; after a bound `bounded.rho_d_fitted`).
    const bool from_map = region.at("rho_d_source") == "albedo_map_seen_mean";
    const Json& fitted = !from_map                    ? region.at("refined").at("rho_d")
                         : region.contains("bounded") ? region.at("bounded").at("rho_d_fitted")
                                                      : region.at("albedo_map").at("seen_mean");
    std::printf("%s: %s %s, written %s\n", name.c_str(), from_map ? "map's seen mean" : "fitted",
                fitted.dump().c_str(), rho_d.dump().c_str());
    for (int c = 0; c < 3; ++c) {
      const double f = fitted[c].get<double>();
      if (f > 1) {
        ++bounded_channels;
        EXPECT_EQ(rho_d[c].get<double>(), 1.0) << name << " channel " << c;
        ASSERT_TRUE(region.contains("bounded")) << name;
        EXPECT_EQ(region.at("bounded").at("rho_d_fitted")[c].get<double>(), f) << name;
      } else {
        EXPECT_EQ(rho_d[c].get<double>(), f) << name << " channel " << c;
      }
    }
  }
  EXPECT_GE(bounded_channels, 3);
  // The walls' albedo map: a channel held at 1 is scaled by the same bound and clipped (no
  // texel above 1); a channel within 1 is as the photos give it, its mean over the seen texels
  // the written rho_d (its texels above 1 are noise, and clipping them would darken it).
  const Json& walls = solved.at("materials").at("walls");
  const Image map = ReadImage(Out() / walls.at("rho_d_map").get<std::string>());
  const Json* walls_report = nullptr;
  for (const Json& region : report.at("regions")) {
    if (region.at("name") == "walls") walls_report = &region;
  }
  ASSERT_NE(walls_report, nullptr);
  const Image seen =
      ReadImage(Out() / walls_report->at("albedo_map").at("seen_file").get<std::string>());
  ASSERT_EQ(seen.width, map.width);
  ASSERT_EQ(seen.height, map.height);
  int held = 0;
  for (int c = 0; c < 3; ++c) {
    float highest = 0;
    double sum = 0;
    int n = 0;
    for (int y = 0; y < map.height; ++y) {
      for (int x = 0; x < map.width; ++x) {
        highest = std::max(highest, map.at(x, y, c));
        if (seen.at(x, y, 0) > 0.5f) sum += map.at(x, y, c), ++n;
      }
    }
    ASSERT_GT(n, 0);
    const double written = walls.at("rho_d")[c].get<double>();
    if (written == 1.0) {
      ++held;
      EXPECT_LE(highest, 1.0f) << "channel " << c;
      EXPECT_GT(highest, 0.9f) << "channel " << c;
    } else {
      EXPECT_NEAR(sum / n, written, 1e-3 * written) << "channel " << c;
    }
  }
  EXPECT_GE(held, 1);
  // It loads as a complete scene and renders.
  const auto render = RenderSolved("cam0");
  EXPECT_EQ(render.exit_code, 0) << render.err;
}

// --photo-scale solve with no region of known reflectance: exit 2, one line naming the scene
// and the rule, nothing written.
TEST_F(SolveE2E, PhotoScaleWithoutAReferenceIsBadInput) {
  RenderPhotos(false);
  Json m = TrueMaterials(false);
  for (auto& [name, material] : m.items()) material.erase("rho_d");
  const fs::path scene =
      WriteScene(SceneDoc(m, Json::array({PhotoEntry("photos/cam0_L0.exr", "cam0", "L0")})));
  const auto r = Solve(scene, Out(), " --photo-scale solve");
  ExpectBadInput(r, Out(), "materials", "scene.json");
  EXPECT_NE(r.err.find("known diffuse reflectance"), std::string::npos) << r.err;
  const auto bad = Solve(scene, Out(), " --photo-scale maybe");
  ExpectBadInput(bad, Out(), "--photo-scale", "");
}

}  // namespace
}  // namespace igi
