// igi-render end to end: a render of every lighting of a complete scene, and bad input that
// must exit 2 with one line and leave no output file behind.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include "tests/e2e/run.h"
#include "tests/temp_dir.h"
#include "tools/common/image.h"

namespace igi {
namespace {

namespace fs = std::filesystem;
using test::Quote;
using test::RunTool;

const std::string kScenes = std::string(IGI_SOURCE_DIR) + "/tests/data/scenes/";

class RenderE2E : public ::testing::Test {
 protected:
  void SetUp() override {
    out_ = test::UniqueTempDir("igi_render_e2e");
  }
  void TearDown() override { fs::remove_all(out_); }
  std::string Args(const std::string& scene, const std::string& rest) const {
    return Quote(kScenes + scene) + " " + rest;
  }
  fs::path out_;
};

TEST_F(RenderE2E, RendersEveryLightingToLinearExr) {
  for (const char* lighting : {"L0", "L1", "L2"}) {
    const fs::path exr = out_ / (std::string(lighting) + ".exr");
    auto r = RunTool("igi-render", Args("render/complete.json", std::string("--camera cam1 --lighting ") +
                                                                 lighting + " --spp 8 --out " +
                                                                 Quote(exr.string())));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const Image im = ReadImage(exr);
    EXPECT_EQ(im.width, 8);
    EXPECT_EQ(im.height, 6);
    EXPECT_EQ(std::get<std::string>(im.metadata.at("igi:lighting")), lighting);
    double sum = 0;
    for (float v : im.pixels) sum += v;
    EXPECT_GT(sum, 0.0) << lighting;
  }
  // --width/--height rescale the intrinsics; --half writes half floats.
  auto r = RunTool("igi-render", Args("render/complete.json", "--camera cam0 --lighting L0 --spp 2 "
                                      "--width 16 --height 12 --half --out " +
                                          Quote((out_ / "big.exr").string())));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(ReadImageInfo(out_ / "big.exr").width, 16);
  EXPECT_EQ(ReadImageInfo(out_ / "big.exr").type, PixelType::kHalf);
}

struct BadCase {
  const char* name;
  const char* scene;
  const char* args;
  const char* expect;  // a phrase of the one error line
};

class RenderBadInputE2E : public RenderE2E, public ::testing::WithParamInterface<BadCase> {};

TEST_P(RenderBadInputE2E, ExitsTwoWithOneLineAndNoOutput) {
  const BadCase& c = GetParam();
  const fs::path exr = out_ / "out.exr";
  auto r = RunTool("igi-render", Args(c.scene, std::string(c.args) + " --out " + Quote(exr.string())));
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find(c.expect), std::string::npos) << r.err;
  EXPECT_TRUE(fs::is_empty(out_)) << "something was written";
}

INSTANTIATE_TEST_SUITE_P(
    Cases, RenderBadInputE2E,
    ::testing::Values(
        BadCase{"unknown_camera", "render/complete.json", "--camera cam9 --lighting L0", "--camera: cam9"},
        BadCase{"unknown_lighting", "render/complete.json", "--camera cam0 --lighting L7", "--lighting: L7"},
        BadCase{"lighting_without_light", "render/complete.json", "--camera cam0 --lighting dark",
                "lightings.dark"},
        BadCase{"texture_unreadable", "render/bad_texture.json", "--camera cam0 --lighting L0", "bad.exr"},
        BadCase{"incomplete_material", "mini/scene.json", "--camera cam0 --lighting L0",
                "materials.box: "},
        BadCase{"zero_spp", "render/complete.json", "--camera cam0 --lighting L0 --spp 0", "--spp"}),
    [](const auto& param_info) { return std::string(param_info.param.name); });

TEST_F(RenderE2E, NotAnExrIsBadUsage) {
  auto r = RunTool("igi-render", Args("render/complete.json", "--camera cam0 --lighting L0 --out " +
                                                                  Quote((out_ / "x.png").string())));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(fs::is_empty(out_));
}

}  // namespace
}  // namespace igi
