// igi-diagnose's memory plan (solver/diagnose/diagnose_memory.h): what it holds follows the
// analysed pixels, its solves get the rest of the budget, and a capture whose analysed pixels
// leave its solves too little is refused before anything is read.
#include "solver/diagnose/diagnose_memory.h"

#include <gtest/gtest.h>

#include <string>

#include "tools/common/error.h"
#include "tools/common/memory.h"

namespace igi::diagnose {
namespace {

// 10 photos of 12 MP (4000×3000) from one camera; nothing is read.
recon::Scene TwelveMegapixelCapture() {
  recon::Scene scene;
  scene.file = "capture/scene.json";
  recon::Camera cam;
  cam.name = "dslr";
  cam.width = 4000, cam.height = 3000;
  scene.cameras = {cam};
  for (int i = 0; i < 10; ++i) {
    recon::Photo p;
    p.camera = 0;
    p.file = "photos/" + std::to_string(i) + ".exr";
    scene.photos.push_back(p);
  }
  return scene;
}

TEST(DiagnoseMemory, HoldsWhatTheAnalysedPixelsNeedAndGivesTheSolvesTheRest) {
  DiagnoseOptions o;
  o.solve.memory_budget = 16;
  o.analysis_megapixels = 0.5;  // 5 × 5 blocks: 800 × 600
  const DiagnoseMemoryPlan plan = PlanDiagnoseMemory(TwelveMegapixelCapture(), o);
  EXPECT_DOUBLE_EQ(plan.pixels, 10 * 800.0 * 600.0);
  EXPECT_DOUBLE_EQ(plan.budget_bytes, 16 * kGiB);
  EXPECT_DOUBLE_EQ(plan.solve_budget_bytes, plan.budget_bytes - plan.held_bytes);
  // Per analysed pixel: the photos, max_tries + 2 re-renders with their variances, the records.
  const double per_pixel = plan.held_bytes / plan.pixels;
  EXPECT_GT(per_pixel, 16 + (o.max_tries + 2) * 36.0);
  EXPECT_LT(per_pixel, 1000);

  // Twice the analysed pixels (a camera of 1 MP analysis size), twice the held bytes.
  o.analysis_megapixels = 2;  // 3 × 3 blocks: 1333 × 1000
  const DiagnoseMemoryPlan larger = PlanDiagnoseMemory(TwelveMegapixelCapture(), o);
  EXPECT_DOUBLE_EQ(larger.pixels, 10 * 1333.0 * 1000.0);
  EXPECT_NEAR(larger.held_bytes / plan.held_bytes, larger.pixels / plan.pixels, 1e-9);
}

TEST(DiagnoseMemory, ACaptureAnalysedAtFullSizeOverTheBudgetIsRefusedWithOneLine) {
  DiagnoseOptions o;
  o.solve.memory_budget = 16;
  o.analysis_megapixels = 0;  // 120 M pixels analysed
  try {
    PlanDiagnoseMemory(TwelveMegapixelCapture(), o);
    FAIL() << "no refusal";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("capture/scene.json"), std::string::npos) << what;
    EXPECT_NE(what.find("--memory-budget"), std::string::npos) << what;
    EXPECT_NE(what.find("--analysis-megapixels"), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace igi::diagnose
