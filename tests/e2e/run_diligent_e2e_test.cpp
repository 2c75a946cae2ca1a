// igi-run on real photographs: the DiLiGenT ball (shared data real/diligent_ball: 48 radiance
// maps of a shiny sphere under known directional lights, cameras in the scene). With
// --hdr-photos the response, HDR and registration stages are skipped (status "skipped") and the
// solve, report stages run on the photos as they are. Checked: exit 0, the ball solved with a
// glossy lobe in the range the solver's own DiLiGenT test accepts (ρs > 0, 0.01 < α < 0.5),
// the report written with the skipped stages named. Minutes on 2 cores: LABELS slow.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <regex>

#include "tests/e2e/run.h"
#include "tests/temp_dir.h"
#include "tools/common/atomic_file.h"
#include "tools/common/json.h"

namespace igi {
namespace {

namespace fs = std::filesystem;
using test::Quote;
using test::RunTool;

const fs::path kBall = fs::path(IGI_SHARED_DATA_DIR) / "real" / "diligent_ball";

TEST(RunDiligentE2eTest, SolvesTheBallFromItsRadianceMaps) {
  const fs::path dir = test::UniqueTempDir("igi_run_diligent");
  const fs::path out = dir / "ball";
  const auto t0 = std::chrono::steady_clock::now();
  const auto r =
      RunTool("igi-run", "--hdr-photos --scene " + Quote((kBall / "scene.json").string()) +
                             " --out " + Quote(out.string()) +
                             " --skip-diagnose --threads 2 --report-photos 2 --report-lightings 3"
                             " --report-spp 4 --solve-arg=--pixel-stride=4"
                             " --solve-arg=--refine-iterations=0 --solve-arg=--indirect-rays=4");
  std::printf("DiLiGenT ball: %.0f s\n%s",
              std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(),
              r.out.c_str());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* s : {"01-response", "02-hdr", "03-register"}) {
    EXPECT_TRUE(std::regex_search(r.out, std::regex(std::string(s) + " +skipped"))) << s;
  }
  const Json report = ReadJsonFile(out / "04-solve" / "report.json");
  ASSERT_EQ(report["regions"].size(), 1u);
  const Json& ball = report["regions"][0];
  EXPECT_EQ(ball["status"], "solved");
  const Json& fit = ball["paper"];
  std::printf("ball: rho_d %s rho_s %s alpha %s (sigma %s)\n", fit["rho_d"].dump().c_str(),
              fit["rho_s"].dump().c_str(), fit["alpha"].dump().c_str(),
              fit["sigma_alpha"].dump().c_str());
  for (const Json& v : fit["rho_s"]) EXPECT_GT(v.get<double>(), 0.0);
  EXPECT_GT(fit["alpha"].get<double>(), 0.01);
  EXPECT_LT(fit["alpha"].get<double>(), 0.5);
  const std::string html = ReadFileToString(out / "report.html");
  EXPECT_NE(html.find("skipped"), std::string::npos);
  EXPECT_NE(html.find("data:image/png;base64,"), std::string::npos);

  // --radiance-scale 2 (the maps are twice the radiance): 04-solve onwards is redone on a copy
  // of the scene whose photos carry exposure_scale 2, and the ball (nothing else in the scene to
  // bounce light) solves to half the reflectances, the same lobe width.
  const auto r2 =
      RunTool("igi-run", "--hdr-photos --scene " + Quote((kBall / "scene.json").string()) +
                             " --out " + Quote(out.string()) +
                             " --skip-diagnose --threads 2 --report-photos 2 --report-lightings 3"
                             " --report-spp 4 --solve-arg=--pixel-stride=4"
                             " --solve-arg=--refine-iterations=0 --solve-arg=--indirect-rays=4"
                             " --radiance-scale 2");
  ASSERT_EQ(r2.exit_code, 0) << r2.err;
  const Json input = ReadJsonFile(out / "04-solve" / "input" / "scene.json");
  ASSERT_FALSE(input["photos"].empty());
  for (const Json& p : input["photos"]) EXPECT_EQ(p["exposure_scale"].get<double>(), 2.0);
  const Json report2 = ReadJsonFile(out / "04-solve" / "report.json");
  const Json& fit2 = report2["regions"][0]["paper"];
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(fit2["rho_d"][c].get<double>() / fit["rho_d"][c].get<double>(), 0.5, 0.01) << c;
    EXPECT_NEAR(fit2["rho_s"][c].get<double>() / fit["rho_s"][c].get<double>(), 0.5, 0.02) << c;
  }
  EXPECT_NEAR(fit2["alpha"].get<double>(), fit["alpha"].get<double>(), 0.02);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace igi
