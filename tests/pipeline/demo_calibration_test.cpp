// igi-run --demo's absolute calibration (tools/pipeline/demo.h MeasureRadianceScale): the median
// ratio of the HDR maps to igi-synth's noise-free radiance, whatever a few outliers do; the
// comparison with the truth (CompareWithTruth) and of the registered cameras with the true ones
// (ComparePoses).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <numbers>

#include "tests/temp_dir.h"
#include "tools/common/atomic_file.h"
#include "tools/common/error.h"
#include "tools/common/image.h"
#include "tools/common/json.h"
#include "tools/pipeline/demo.h"

namespace igi::pipeline {
namespace {
namespace fs = std::filesystem;

Image Constant(int w, int h, float v) {
  Image im;
  im.width = w;
  im.height = h;
  im.channels = 3;
  im.pixels.assign(size_t(w) * h * 3, v);
  return im;
}

TEST(DemoCalibrationTest, MedianRatioOfHdrToTrueRadiance) {
  const fs::path dir = test::UniqueTempDir("demo_calibration");
  const fs::path synth = dir / "synth", hdr = dir / "hdr";
  fs::create_directories(synth / "truth" / "radiance");
  fs::create_directories(hdr);
  Json sets = Json::array();
  for (int i = 0; i < 2; ++i) {
    const std::string name = "cam" + std::to_string(i) + "_L0";
    Image truth = Constant(20, 10, 0.5f + i);
    for (size_t k = 0; k < truth.pixels.size(); ++k) truth.pixels[k] += 0.001f * float(k % 50);
    Image measured = truth;
    for (float& v : measured.pixels) v *= 0.25f;
    measured.pixels[0] = 1e6f;   // a hot pixel
    measured.pixels[7] = -1.0f;  // a masked one
    WriteImage(synth / "truth" / "radiance" / (name + ".exr"), truth);
    WriteImage(hdr / (name + ".exr"), measured);
    sets.push_back({{"dir", "brackets/" + name}, {"radiance", "truth/radiance/" + name + ".exr"}});
  }
  WriteJsonFile(synth / "truth.json", Json{{"brackets", {{"sets", sets}}}});
  EXPECT_NEAR(MeasureRadianceScale(hdr, synth), 0.25, 1e-6);
  fs::remove_all(hdr);
  fs::create_directories(hdr);
  EXPECT_THROW(MeasureRadianceScale(hdr, synth), Error);  // no HDR map to compare
  fs::remove_all(dir);
}

// The comparison leaves out regions whose material was given (the reference) from both the
// table and the median k, and --demo-calibration takes only its three values.
TEST(DemoCalibrationTest, ComparisonLeavesOutTheGivenReference) {
  const fs::path dir = test::UniqueTempDir("demo_compare");
  fs::create_directories(dir);
  WriteJsonFile(dir / "truth.json", Json{{"materials",
                                          {{"a", {{"rho_d", {0.5, 0.5, 0.5}}}},
                                           {"b", {{"rho_d", {0.2, 0.2, 0.2}}, {"rho_s", 0.1}}},
                                           {"ref", {{"rho_d", {0.7, 0.7, 0.7}}}}}}});
  WriteJsonFile(dir / "scene.json", Json{{"materials",
                                          {{"a", {{"rho_d", {1.0, 1.0, 1.0}}}},
                                           {"b", {{"rho_d", {0.4, 0.4, 0.4}}, {"rho_s", 0.2}}},
                                           {"ref", {{"rho_d", {0.7, 0.7, 0.7}}}}}}});
  const Json all = CompareWithTruth(dir / "scene.json", dir / "truth.json");
  EXPECT_EQ(all["regions"].size(), 3u);
  const Json without = CompareWithTruth(dir / "scene.json", dir / "truth.json", {"ref"});
  ASSERT_EQ(without["regions"].size(), 2u);
  // a and b are both 2x their truth: k = 2 once the reference (1x) is out of the median.
  EXPECT_NEAR(without["photometric_scale_k"].get<double>(), 2.0, 1e-9);
  for (const Json& r : without["regions"]) {
    EXPECT_NE(r["region"], "ref");
    EXPECT_NEAR(r["rho_d"]["relative_error"].get<double>(), 0.0, 1e-9);
  }
  fs::remove_all(dir);
  DemoOptions o;
  o.out = dir;
  EXPECT_NO_THROW(o.Validate());
  DemoChoiceFlags choices;
  choices.calibration = "guess";
  try {
    o.SetChoices(choices);
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.problems(), std::vector<std::string>{
                                "--demo-calibration: guess: must be reference, measured or none"});
  }
  choices.calibration = "measured";
  o.SetChoices(choices);
  EXPECT_EQ(o.calibration, DemoCalibration::kMeasured);
  for (DemoCalibration c :
       {DemoCalibration::kReference, DemoCalibration::kMeasured, DemoCalibration::kNone}) {
    EXPECT_EQ(DemoCalibrationFromName(DemoCalibrationName(c)), c);
  }
  EXPECT_FALSE(DemoCalibrationFromName("Reference"));
}

// A scene with the given cameras (name -> {qvec, tvec}) and nothing to load.
Json SceneWithCameras(const Json& poses) {
  Json cameras = Json::object();
  for (const auto& [name, pose] : poses.items()) {
    cameras[name] = {{"model", "PINHOLE"},         {"width", 40},          {"height", 30},
                     {"params", {30, 30, 20, 15}}, {"qvec", pose["qvec"]}, {"tvec", pose["tvec"]}};
  }
  return {{"format", "igi-scene"},
          {"version", 1},
          {"geometry", Json::array({Json{{"file", "room.obj"}}})},
          {"materials", {{"m", {{"brdf", "lambert"}, {"rho_d", 0.5}}}}},
          {"lights", {{"p", {{"type", "point"}, {"position", {0, 0, 1}}, {"intensity", 1}}}}},
          {"lightings", {{"L0", {"p"}}}},
          {"cameras", cameras}};
}

// Registered cameras are named after their photo (camN_L0), the true ones camN. Exact values:
// camera a rotated by 2 degrees about z (its centre kept), camera b (looking up) moved 3 cm.
TEST(DemoCalibrationTest, ComparesRegisteredPosesWithTruth) {
  const fs::path dir = test::UniqueTempDir("demo_poses");
  fs::create_directories(dir);
  WriteFileAtomic(dir / "room.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");  // not loaded
  const double half = 0.5 * 2.0 * std::numbers::pi / 180;                     // half of 2 degrees
  // b looks up: world +z is its optical axis (camera z); rotation of pi about x maps z -> -z,
  // so b's cam_from_world is the identity (camera z = world z).
  WriteJsonFile(dir / "truth.json",
                SceneWithCameras({{"a", {{"qvec", {0, 1, 0, 0}}, {"tvec", {0, 0, 0}}}},
                                  {"b", {{"qvec", {1, 0, 0, 0}}, {"tvec", {0, 0, 0}}}}}));
  WriteJsonFile(
      dir / "registered.json",
      SceneWithCameras(
          {{"a_L0",
            {{"qvec", {0, std::cos(half), std::sin(half), 0}},  // (0,1,0,0) then 2 deg about z
             {"tvec", {0, 0, 0}}}},
           {"b_L0", {{"qvec", {1, 0, 0, 0}}, {"tvec", {0.03, 0, 0}}}}}));
  const Json poses = ComparePoses(dir / "registered.json", dir / "truth.json");
  EXPECT_EQ(poses["registered"], 2);
  ASSERT_EQ(poses["cameras"].size(), 2u);
  for (const Json& c : poses["cameras"]) {
    if (c["photo"] == "a_L0") {
      EXPECT_NEAR(c["rotation_error_deg"].get<double>(), 2.0, 1e-9);
      EXPECT_NEAR(c["position_error_m"].get<double>(), 0.0, 1e-12);
      EXPECT_FALSE(c["looks_up"].get<bool>());
    } else {
      EXPECT_NEAR(c["rotation_error_deg"].get<double>(), 0.0, 1e-9);
      EXPECT_NEAR(c["position_error_m"].get<double>(), 0.03, 1e-12);
      EXPECT_TRUE(c["looks_up"].get<bool>());
    }
  }
  EXPECT_NEAR(poses["max_rotation_error_deg"].get<double>(), 2.0, 1e-9);
  EXPECT_NEAR(poses["max_position_error_m"].get<double>(), 0.03, 1e-12);
  fs::remove_all(dir);
}

// The seen part of a texture: a 2 x 2 m floor (z = 0, UVs over [0,1]^2) whose texture is 0.2 on
// its left half (u < 0.5) and 0.8 on its right, under a pinhole camera 1 m above x = 0.45 looking
// down with a field of view of 1 m at the floor: it sees x < 0.95 (u < 0.475), the left half
// only (the bilinear lookup mixes in the right half's value only within half a texel of u = 0.5,
// which it does not reach). The seen mean is 0.2; the whole texture's is 0.5.
TEST(DemoCalibrationTest, SeenTrueAlbedoAveragesTheSeenSurfaceOnly) {
  const fs::path dir = test::UniqueTempDir("demo_seen");
  fs::create_directories(dir / "textures");
  WriteFileAtomic(dir / "floor.obj",
                  "v 0 0 0\nv 2 0 0\nv 2 2 0\nv 0 2 0\n"
                  "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
                  "usemtl floor\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n");
  Image texture = Constant(64, 64, 0.2f);
  for (int y = 0; y < 64; ++y) {
    for (int x = 32; x < 64; ++x) {
      for (int c = 0; c < 3; ++c) texture.pixels[(size_t(y) * 64 + x) * 3 + c] = 0.8f;
    }
  }
  WriteImage(dir / "textures" / "floor.exr", texture);
  // Camera looking down (-z): cam_from_world rotates world z to camera -z (pi about x), centre
  // (0.45, 1, 1): t = -R c = -(0.45, -1, -1). Focal 20 px over 20 px: 1 m wide at 1 m.
  Json scene = SceneWithCameras({{"down", {{"qvec", {0, 1, 0, 0}}, {"tvec", {-0.45, 1, 1}}}}});
  scene["cameras"]["down"]["width"] = 20;
  scene["cameras"]["down"]["height"] = 20;
  scene["cameras"]["down"]["params"] = {20, 20, 10, 10};
  scene["geometry"] = Json::array({Json{{"file", "floor.obj"}}});
  scene["materials"] = {
      {"floor", {{"brdf", "lambert"}, {"rho_d", 0.5}, {"rho_d_map", "textures/floor.exr"}}}};
  WriteJsonFile(dir / "scene.json", scene);
  const auto seen = SeenTrueAlbedo(dir / "scene.json", 20000, 3);
  ASSERT_EQ(seen.count("floor"), 1u);
  EXPECT_NEAR(seen.at("floor").x(), 0.2, 1e-6);
  // Moved to x = 1 the camera sees u in [0.25, 0.75]: half of each value, mean 0.5 within the
  // sampling noise (20000 points, about half of them seen).
  scene["cameras"]["down"]["tvec"] = {-1.0, 1, 1};
  WriteJsonFile(dir / "scene.json", scene);
  EXPECT_NEAR(SeenTrueAlbedo(dir / "scene.json", 20000, 3).at("floor").x(), 0.5, 0.02);
  fs::remove_all(dir);
}

// The truth over the solved map's seen texels: a true texture 0.2 on its left half (u < 0.5) and
// 0.8 on its right; the solved map (8 x 4 texels) marks its two left columns seen (u < 0.25): the
// truth there is 0.2, and a solved ρd of 0.2 is exact; without the mask the comparison falls back
// to the whole texture's mean (no true scene beside truth.json), 0.5.
TEST(DemoCalibrationTest, TruthOverTheSolvedMapsSeenTexels) {
  const fs::path dir = test::UniqueTempDir("demo_texels");
  fs::create_directories(dir / "textures");
  fs::create_directories(dir / "solve" / "albedo");
  Image texture = Constant(64, 64, 0.2f);
  for (int y = 0; y < 64; ++y) {
    for (int x = 32; x < 64; ++x) {
      for (int c = 0; c < 3; ++c) texture.pixels[(size_t(y) * 64 + x) * 3 + c] = 0.8f;
    }
  }
  WriteImage(dir / "textures" / "floor.exr", texture);
  WriteJsonFile(dir / "truth.json",
                Json{{"materials",
                      {{"floor", {{"rho_d", {0.5, 0.5, 0.5}}, {"rho_d_map", "textures/floor.exr"}}},
                       {"wall", {{"rho_d", {0.3, 0.3, 0.3}}}}}}});
  WriteJsonFile(dir / "solve" / "scene.json",
                Json{{"materials",
                      {{"floor", {{"rho_d", {0.2, 0.2, 0.2}}, {"rho_d_map", "albedo/floor.exr"}}},
                       {"wall", {{"rho_d", {0.3, 0.3, 0.3}}}}}}});
  WriteImage(dir / "solve" / "albedo" / "floor.exr", Constant(8, 4, 0.2f));
  Image seen(8, 4, 1);
  for (int y = 0; y < 4; ++y) seen.at(0, y, 0) = seen.at(1, y, 0) = 1.0f;
  WriteImageOptions mo;
  mo.type = PixelType::kUInt8;
  WriteImage(dir / "solve" / "albedo" / "floor_seen.png", seen, mo);

  const auto texels = TrueAlbedoOverSolvedTexels(dir / "solve" / "scene.json", dir / "truth.json");
  ASSERT_EQ(texels.size(), 1u);  // the wall has no texture
  EXPECT_NEAR(texels.at("floor").x(), 0.2, 1e-6);
  const Json d = CompareWithTruth(dir / "solve" / "scene.json", dir / "truth.json");
  for (const Json& r : d["regions"]) {
    EXPECT_NEAR(r["rho_d"]["relative_error"].get<double>(), 0.0, 1e-6) << r.dump();
    if (r["region"] == "floor") {
      EXPECT_NE(r["rho_d"]["truth_is"].get<std::string>().find("texels"), std::string::npos);
      EXPECT_NEAR(r["rho_d"]["truth_whole_texture"].get<double>(), 0.5, 1e-9);
    }
  }
  fs::remove(dir / "solve" / "albedo" / "floor_seen.png");
  const Json whole = CompareWithTruth(dir / "solve" / "scene.json", dir / "truth.json");
  for (const Json& r : whole["regions"]) {
    if (r["region"] == "floor") {
      EXPECT_NEAR(r["rho_d"]["truth"].get<double>(), 0.5, 1e-9);
    }
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace igi::pipeline
