// igi-solve within its memory budget: an igi-synth room of 5 photos of 400×300 solved from every
// pixel (--pixel-stride 1: 600 000 of them, about 10 GiB at the full draw) under a 1.5 GiB
// budget draws fewer observations, says so on one warning line, and its measured peak stays
// within the budget (report.json memory.peak_bytes, getrusage's peak of the igi-solve process).
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "tests/e2e/run.h"
#include "tests/temp_dir.h"
#include "tools/common/json.h"

namespace igi {
namespace {

namespace fs = std::filesystem;
using test::Quote;
using test::RunTool;

class SolveBudgetE2E : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new fs::path(test::UniqueTempDir("igi_solve_budget"));
    const auto r =
        RunTool("igi-synth", "--out " + Quote((*dir_ / "room").string()) +
                                 " --cameras 5 --ceiling-cameras 1 --width 400 --height 300"
                                 " --spp 4"
                                 " --seed 2 --threads 2 --quiet");
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  static void TearDownTestSuite() {
    fs::remove_all(*dir_);
    delete dir_;
  }
  static fs::path* dir_;
};
fs::path* SolveBudgetE2E::dir_ = nullptr;

TEST_F(SolveBudgetE2E, ThePeakStaysWithinTheBudgetByDrawingFewerObservations) {
  const fs::path out = *dir_ / "out";
  const auto r = RunTool("igi-solve", Quote((*dir_ / "room" / "scene.json").string()) + " --out " +
                                          Quote(out.string()) +
                                          " --pixel-stride 1 --memory-budget 1.5 --threads 2"
                                          " --refine-iterations 1");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // One warning line says how many of how many were drawn.
  EXPECT_NE(r.err.find("drawing about"), std::string::npos) << r.err;
  const Json report = ReadJsonFile(out / "report.json");
  const Json& draw = report["observation_draw"];
  const Json& memory = report["memory"];
  EXPECT_TRUE(draw["thinned"].get<bool>());
  EXPECT_GT(draw["available"].get<double>(), 450000);
  EXPECT_LT(draw["drawn"].get<double>(), draw["available"].get<double>() / 4);
  EXPECT_GT(draw["drawn"].get<double>(), 5000);
  const double budget = memory["budget_bytes"].get<double>();
  EXPECT_DOUBLE_EQ(budget, 1.5 * 1024 * 1024 * 1024);
  EXPECT_LE(memory["estimate_bytes"].get<double>(), budget);
  // The measured peak: within the budget (the estimate is an upper bound, not a guess).
  EXPECT_LE(memory["peak_bytes"].get<double>(), budget);
  EXPECT_GT(memory["peak_bytes"].get<double>(), 0.2 * budget);
  // Every photo reports the pixels it did not draw.
  for (const Json& p : report["photos"]) EXPECT_GT(p["undrawn"].get<int>(), 0);
}

}  // namespace
}  // namespace igi
