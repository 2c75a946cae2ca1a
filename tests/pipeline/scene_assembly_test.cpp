// The solvable scene igi-run writes after registration (tools/pipeline/scene_assembly.h): relative
// paths rebased to the new folder, one photo per registered camera with its HDR map, mask and
// the layout's lighting; unregistered photos listed. The registration PNG keeps the image size.
#include "tools/pipeline/scene_assembly.h"

#include <gtest/gtest.h>

#include <fstream>

#include "tests/temp_dir.h"
#include "tools/common/image.h"

namespace igi::pipeline {
namespace {
namespace fs = std::filesystem;

TEST(SceneAssemblyTest, RebasesPathsAndPairsPhotosWithCameras) {
  const fs::path dir = test::UniqueTempDir("igi_assembly");
  fs::create_directories(dir / "in" / "geometry");
  fs::create_directories(dir / "run" / "02-hdr");
  fs::create_directories(dir / "run" / "03-register");
  std::ofstream(dir / "run" / "02-hdr" / "a_L0_mask.png") << "x";
  SolvableSceneInputs in;
  in.input_scene = Json::parse(R"({"format": "igi-scene", "version": 1,
    "geometry": [{"file": "geometry/room.obj"}],
    "materials": {"m": {"brdf": "lambert", "rho_d_map": "tex/m.exr"}},
    "lights": {"p": {"type": "spot", "profile": {"ies": "/abs/x.ies"}}},
    "lightings": {"L0": ["p"], "L1": ["p"]}})");
  in.input_dir = dir / "in";
  const Json cam = {{"model", "PINHOLE"}, {"width", 4}, {"height", 3},
                    {"params", {1, 1, 2, 1.5}}, {"qvec", {1, 0, 0, 0}}, {"tvec", {0, 0, 0}}};
  in.registered_scene = {{"cameras", {{"a_L0", cam}, {"b_L1", cam}}}};
  for (const auto& [name, lighting] : std::vector<std::pair<std::string, std::string>>{
           {"a_L0", "L0"}, {"b_L1", "L1"}, {"c_L0", "L0"}}) {
    PhotoSource p;
    p.name = name;
    p.lighting = lighting;
    in.photos.push_back(p);
  }
  in.hdr_dir = dir / "run" / "02-hdr";
  in.out_dir = dir / "run" / "03-register";
  std::vector<std::string> unregistered;
  const Json s = SolvableScene(in, &unregistered);
  EXPECT_EQ(s["geometry"][0]["file"], "../../in/geometry/room.obj");
  EXPECT_EQ(s["materials"]["m"]["rho_d_map"], "../../in/tex/m.exr");
  EXPECT_EQ(s["lights"]["p"]["profile"]["ies"], "/abs/x.ies");
  ASSERT_EQ(s["photos"].size(), 2u);
  EXPECT_EQ(s["photos"][0]["file"], "../02-hdr/a_L0.exr");
  EXPECT_EQ(s["photos"][0]["mask"], "../02-hdr/a_L0_mask.png");
  EXPECT_EQ(s["photos"][1]["lighting"], "L1");
  EXPECT_FALSE(s["photos"][1].contains("mask"));
  EXPECT_EQ(s["cameras"].size(), 2u);
  EXPECT_EQ(unregistered, std::vector<std::string>{"c_L0"});
  fs::remove_all(dir);
}

TEST(SceneAssemblyTest, TonemapKeepsSizeAndOrder) {
  const fs::path dir = test::UniqueTempDir("igi_assembly");
  Image img;
  img.width = 8;
  img.height = 6;
  img.channels = 3;
  img.pixels.assign(8 * 6 * 3, 0.0f);
  for (int y = 0; y < 6; ++y) {
    for (int x = 0; x < 8; ++x) {
      for (int c = 0; c < 3; ++c) img.pixels[(y * 8 + x) * 3 + c] = x < 4 ? 0.1f : 10.0f;
    }
  }
  WriteImage(dir / "r.exr", img);
  TonemapForRegistration(dir / "r.exr", dir / "r.png");
  const Image png = ReadImage(dir / "r.png", 3);
  EXPECT_EQ(png.width, 8);
  EXPECT_EQ(png.height, 6);
  EXPECT_LT(png.pixels[(2 * 8 + 1) * 3], png.pixels[(2 * 8 + 6) * 3]);  // dark left, bright right
  EXPECT_GT(png.pixels[(2 * 8 + 6) * 3], 0.9f);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace igi::pipeline
