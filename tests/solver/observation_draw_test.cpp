// Drawing the observations to a budget as they are collected (solver/inverse/observation_draw.h)
// and the memory plan behind it (solver/inverse/solve_memory.h): the probabilities keep each
// region's highlight candidates and fit samples and share the rest of the budget; a thinned
// collection keeps a subset of the very pixels a full one keeps, every highlight candidate among
// them; drawn blocks are the means of their pixels on one surface; a budget that cannot hold one
// photo is refused before any work.
//
// Scene: tests/e2e/box_room.h's 2 m room with a Ward floor of unknown lobe, cam0 looking down at
// the lamp's highlight on the floor, cam1 up; photos path-traced at 16 paths, every pixel
// (stride 1: 6144 pixels).
#include "solver/inverse/observation_draw.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <tuple>

#include "recon/scene.h"
#include "solver/inverse/solve.h"
#include "solver/inverse/solve_internal.h"
#include "tests/e2e/box_room.h"
#include "tests/solver/box_room_photos.h"
#include "tests/temp_dir.h"
#include "tools/common/error.h"
#include "tools/common/json.h"

namespace igi::solver {
namespace {
namespace fs = std::filesystem;
namespace room = test::box_room;

TEST(PlanObservationDraw, EveryPixelWhenTheyFitTheBudget) {
  const std::vector<RegionPixelCensus> census = {{1000, 5000}, {0, 3000}};
  ObservationDrawOptions o;
  o.budget = 9000;
  const ObservationDraw d = PlanObservationDraw(census, {1, 0}, o);
  EXPECT_DOUBLE_EQ(d.available, 9000);
  EXPECT_DOUBLE_EQ(d.expected, 9000);
  for (double p : {d.p_near[0], d.p_rest[0], d.p_near[1], d.p_rest[1]}) EXPECT_EQ(p, 1.0);
}

TEST(PlanObservationDraw, KeepsEachRegionsNeedsAndSharesTheRest) {
  // Region 0 has a fitted lobe: 50 000 highlight candidates, 200 000 others; region 1 has none
  // (its 1000 pixels near a highlight count with its others); region 2 is small.
  const std::vector<RegionPixelCensus> census = {{50000, 200000}, {1000, 500000}, {0, 3000}};
  ObservationDrawOptions o;
  o.budget = 100000;
  o.max_highlight_samples = 30000;
  o.max_fit_samples = 6000;
  const ObservationDraw d = PlanObservationDraw(census, {1, 0, 0}, o);
  EXPECT_DOUBLE_EQ(d.available, 754000);
  // The budget is met (the bisection's precision), never exceeded.
  EXPECT_LE(d.expected, 100000);
  EXPECT_GT(d.expected, 100000 - 1);
  EXPECT_NEAR(d.p_near[0] * 50000, 30000, 1);  // the highlight candidates the fit needs
  EXPECT_EQ(d.p_rest[2], 1.0);                 // a region smaller than its fit samples: all
  // The rest shares one probability: region 0's and region 1's other pixels alike.
  EXPECT_NEAR(d.p_rest[0], d.p_rest[1], 1e-9);
  EXPECT_NEAR(d.p_rest[0] * (200000 + 501000) + 30000 + 3000, 100000, 1);
  EXPECT_EQ(d.Probability(1, true), d.p_rest[1]);  // no lobe class: near counts as rest
}

// The needs take at most half of the budget (kNeedsShare), and the other half is still drawn
// evenly over every pixel: the even draw is what covers every surface with observations. Within
// that half the fit samples come first and the highlight candidates give way.
TEST(PlanObservationDraw, HighlightCandidatesGiveWayBeyondHalfTheBudget) {
  // Region 0: a fitted lobe; region 1: a large wall; region 2: seen by few pixels.
  const std::vector<RegionPixelCensus> census = {{50000, 200000}, {0, 500000}, {0, 8000}};
  ObservationDrawOptions o;
  o.budget = 80000;  // the needs: 30 000 + 3 × 6000 = 48 000, over the half of 40 000
  o.max_highlight_samples = 30000;
  o.max_fit_samples = 6000;
  const ObservationDraw d = PlanObservationDraw(census, {1, 0, 0}, o);
  EXPECT_LE(d.expected, 80000);
  EXPECT_GT(d.expected, 80000 - 1);
  EXPECT_NEAR(d.p_rest[2] * 8000, 6000, 1e-3);                          // its fit samples, whole
  EXPECT_NEAR(d.p_near[0] * 50000, kNeedsShare * 80000 - 18000, 1e-3);  // what is left of half
  // Every other pixel at one probability q: the kept classes and q·(200 000 + 500 000) fill it.
  EXPECT_NEAR(d.p_rest[0], d.p_rest[1], 1e-9);
  EXPECT_NEAR(22000 + 6000 + d.p_rest[0] * 700000, 80000, 1);
}

// Where the fit samples alone would leave the highlight candidates under half of the needs'
// share, both classes are scaled down to a half each.
TEST(PlanObservationDraw, NeedsBeyondHalfTheBudgetAreScaledTogether) {
  const std::vector<RegionPixelCensus> census = {{50000, 200000}, {0, 500000}};
  ObservationDrawOptions o;
  o.budget = 18000;  // the needs: 30 000 + 6000 + 6000 = 42 000
  o.max_highlight_samples = 30000;
  o.max_fit_samples = 6000;
  const ObservationDraw d = PlanObservationDraw(census, {1, 0}, o);
  EXPECT_LE(d.expected, 18000);
  EXPECT_GT(d.expected, 18000 - 1);
  const double half = 0.5 * kNeedsShare * 18000;  // 4500 for each class
  EXPECT_NEAR(d.p_near[0] * 50000, half, 1e-3);
  // Every other pixel at one probability q, above the scaled fit samples (2250 a region).
  EXPECT_NEAR(d.p_rest[0], d.p_rest[1], 1e-9);
  EXPECT_GT(d.p_rest[0] * 200000, half / 2);
  EXPECT_NEAR(half + d.p_rest[0] * 700000, 18000, 1);
}

TEST(PlanObservationDraw, BlockSidesFollowTheProbabilities) {
  const std::vector<RegionPixelCensus> census = {{50000, 200000}, {1000, 500000}, {0, 3000}};
  ObservationDrawOptions o;
  o.budget = 100000;
  o.max_highlight_samples = 30000;
  o.max_fit_samples = 6000;
  ObservationDraw d = PlanObservationDraw(census, {1, 0, 0}, o);
  // p_rest ≈ 0.096: blocks of ⌊1/√p⌋ = 3 cells, kept with p·9; p_near 0.6 and 1: single pixels.
  ASSERT_NEAR(d.p_rest[0], 0.0956, 0.001);
  EXPECT_EQ(d.Block(0, false), 3);
  EXPECT_EQ(d.Block(1, false), 3);
  EXPECT_EQ(d.Block(0, true), 1);
  EXPECT_EQ(d.Block(2, false), 1);
  EXPECT_NEAR(d.Threshold(0, false), 9 * d.p_rest[0], 1e-12);
  EXPECT_EQ(d.Threshold(0, true), d.p_near[0]);
  o.max_block = 2;
  d = PlanObservationDraw(census, {1, 0, 0}, o);
  EXPECT_EQ(d.Block(0, false), 2);
  o.budget = 2000;  // p ≈ 0.003: ⌊18.3⌋ capped at max_block
  o.max_block = 8;
  d = PlanObservationDraw(census, {1, 0, 0}, o);
  EXPECT_EQ(d.Block(1, false), 8);
  EXPECT_LE(d.Threshold(1, false), 1.0);
}

TEST(ObservationDraw, BlocksKeepTheDensityOfSinglePixels) {
  // One region, p = 1/20: blocks of 4 × 4 stride cells (stride 2), kept with p·16 = 0.8, the
  // centre cell of each block its anchor.
  ObservationDraw d;
  d.lobe_class = {0};
  d.p_near = d.p_rest = {0.05};
  d.block_near = d.block_rest = {4};
  const int stride = 2, cells = 400;
  int kept = 0;
  for (int cy = 0; cy < cells; ++cy) {
    for (int cx = 0; cx < cells; ++cx) {
      int x0 = -1, y0 = -1, size = 0;
      if (!d.Draws(3, cx * stride + 1, cy * stride + 1, stride, 0, false, &x0, &y0, &size)) {
        continue;
      }
      ++kept;
      EXPECT_EQ(cx % 4, 2);
      EXPECT_EQ(cy % 4, 2);
      EXPECT_EQ(size, 8);
      EXPECT_EQ(x0, (cx - 2) * stride);
      EXPECT_EQ(y0, (cy - 2) * stride);
    }
  }
  const double expected = 0.05 * cells * cells;  // 8000, binomial σ ≈ 40 over 10 000 blocks
  EXPECT_NEAR(kept, expected, 4 * std::sqrt(expected * 0.2));
  // Single pixels: the pixel itself.
  d.block_rest = {1};
  int x0 = -1, y0 = -1, size = 0;
  for (int x = 1; x < 200; x += 2) {
    if (d.Draws(3, x, 5, stride, 0, false, &x0, &y0, &size)) break;
  }
  EXPECT_EQ(size, 1);
  EXPECT_EQ(y0, 5);
}

class ObservationDrawRoom : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new fs::path(test::UniqueTempDir("observation_draw"));
    room::WriteRoomFolder(*dir_);
    Json photos = Json::array();
    for (const char* cam : {"cam0", "cam1"}) {
      photos.push_back(room::PhotoEntry(std::string("photos/") + cam + ".exr", cam, "L0"));
    }
    Json unknown = room::TrueMaterials(false);
    for (auto& [name, m] : unknown.items()) m.erase("rho_d");
    unknown["floor"] = {{"brdf", "ward"}};  // ρd, ρs and α unknown: a fitted lobe
    WriteJsonFile(*dir_ / "truth.json", room::SceneDoc(room::TrueMaterials(false), Json::array()));
    WriteJsonFile(*dir_ / "scene.json", room::SceneDoc(unknown, photos));
    room::RenderTruthPhotos(*dir_, {"cam0", "cam1"}, 16, 5);
  }
  static void TearDownTestSuite() {
    fs::remove_all(*dir_);
    delete dir_;
  }
  static SolveOptions Options() {
    SolveOptions o;
    o.pixel_stride = 1;
    o.num_threads = 2;
    o.show_progress = false;
    return o;
  }
  static fs::path* dir_;
};
fs::path* ObservationDrawRoom::dir_ = nullptr;

using Pixel = std::tuple<int, int, int>;  // photo, x, y

TEST_F(ObservationDrawRoom, AThinnedCollectionKeepsHighlightsAndASubsetOfTheSamePixels) {
  const recon::Scene scene = recon::LoadScene(*dir_ / "scene.json");
  SolveOptions o = Options();
  o.max_fit_samples = 200;      // the regions' needs (their highlight candidates and 200 others)
                                // well inside the budget below
  o.max_observation_block = 1;  // single pixels (blocks: below)
  SolverState full(scene, o);
  full.Prepare();
  o.max_observations = 2000;
  SolverState thin(scene, o);
  thin.Prepare();
  ASSERT_GT(full.obs.size(), 4000u);
  EXPECT_FALSE(full.summary.observations_thinned);
  EXPECT_TRUE(thin.summary.observations_thinned);

  const int floor = scene.FindMaterial("floor");
  auto near = [&](const SolverState& s, const Observation& ob) {
    const render::RayScene& g = *s.lighting_scenes[scene.photos[ob.photo].lighting];
    return NearHighlight(g, ob.position.cast<double>(), ob.view.cast<double>(),
                         ob.normal.cast<double>());
  };
  std::map<Pixel, const Observation*> full_pixels;
  int full_near = 0;
  for (const Observation& ob : full.obs) {
    full_pixels[{ob.photo, ob.x, ob.y}] = &ob;
    full_near += ob.region == floor && near(full, ob);
  }
  int thin_near = 0, undrawn = 0;
  for (const Observation& ob : thin.obs) {
    const auto it = full_pixels.find({ob.photo, ob.x, ob.y});
    ASSERT_NE(it, full_pixels.end()) << "a thinned observation the full collection lacks";
    EXPECT_EQ(it->second->position, ob.position);
    EXPECT_EQ(it->second->radiance, ob.radiance);
    thin_near += ob.region == floor && near(thin, ob);
  }
  for (const PhotoObservationStats& st : thin.summary.photos) undrawn += st.undrawn;
  // Within the budget (the census's estimate has the hash's spread: ±3σ of a binomial draw).
  EXPECT_LE(double(thin.obs.size()), 2000 + 3 * std::sqrt(2000.0));
  EXPECT_LT(thin.obs.size(), full.obs.size() / 2);
  EXPECT_GT(undrawn, 2000);
  // Available: every pixel that saw a reflective surface, drawn or not (the undrawn ones skip the
  // edge test, so the two collections' edge counts differ by the undrawn edge pixels).
  auto edges = [](const SolverState& s) {
    return s.summary.photos[0].edge + s.summary.photos[1].edge;
  };
  EXPECT_EQ(thin.summary.observations_available + edges(thin),
            double(full.obs.size()) + edges(full));
  // Every highlight candidate of the floor is kept (fewer than max_highlight_samples).
  ASSERT_GT(full_near, 50);
  EXPECT_EQ(thin_near, full_near);
  // The fit's subset is drawn inside the collection's: still at most max_fit_samples-ish per
  // region, and only of collected observations.
  int walls_fit = 0;
  const int walls = scene.FindMaterial("walls");
  for (size_t i = 0; i < thin.obs.size(); ++i)
    walls_fit += thin.obs[i].region == walls && thin.obs.in_fit[i];
  EXPECT_GT(walls_fit, 0);
}

TEST_F(ObservationDrawRoom, DrawnBlocksAreTheMeansOfTheirPixelsOnOneSurface) {
  const recon::Scene scene = recon::LoadScene(*dir_ / "scene.json");
  SolveOptions o = Options();
  o.max_fit_samples = 200;
  o.max_observations = 1000;
  SolverState thin(scene, o);
  thin.Prepare();
  ASSERT_TRUE(thin.summary.observations_thinned);
  EXPECT_LE(double(thin.obs.size()), 1000 + 3 * std::sqrt(1000.0));
  const Image photos[2] = {ReadImage(scene.photos[0].file, 3), ReadImage(scene.photos[1].file, 3)};
  int blocks = 0, counted = 0;
  for (const Observation& ob : thin.obs) {
    if (ob.size == 1) continue;
    ++blocks;
    const Image& im = photos[ob.photo];
    ASSERT_LE(ob.x + ob.size, im.width);
    ASSERT_LE(ob.y + ob.size, im.height);
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (int y = ob.y; y < ob.y + ob.size; ++y) {
      for (int x = ob.x; x < ob.x + ob.size; ++x) {
        for (int c = 0; c < 3; ++c) sum[c] += im.at(x, y, c);
      }
    }
    const Eigen::Vector3d mean = sum / double(ob.size * ob.size);
    EXPECT_LT((mean - ob.radiance.cast<double>()).norm(), 1e-5 * (1 + mean.norm()));
    // Its point is where the block's centre ray meets the surface.
    const recon::Camera& cam = scene.cameras[scene.photos[ob.photo].camera];
    const std::optional<Eigen::Vector2d> centre = cam.ImgFromWorld(ob.position.cast<double>());
    ASSERT_TRUE(centre);
    EXPECT_NEAR(centre->x(), ob.x + 0.5 * ob.size, 1e-3);
    EXPECT_NEAR(centre->y(), ob.y + 0.5 * ob.size, 1e-3);
  }
  for (const PhotoObservationStats& st : thin.summary.photos) counted += st.blocks;
  EXPECT_GT(blocks, 100);
  EXPECT_EQ(blocks, counted);
}

TEST_F(ObservationDrawRoom, TheSmoothingRadiusWidensToHoldTheDrawnNeighbours) {
  const recon::Scene scene = recon::LoadScene(*dir_ / "scene.json");
  SolveOptions o = Options();
  o.max_fit_samples = 200;
  o.indirect_rays = 8;
  SolverState full(scene, o);
  full.Prepare();
  full.GatherAll();
  const double r0 = full.summary.scene_scale_m / 96;
  for (float r : DrawnSmoothingRadii(full.Stage(), full.materials.size(), r0))
    ASSERT_EQ(r, float(r0));
  o.max_observations = 1000;
  SolverState thin(scene, o);
  thin.Prepare();
  thin.GatherAll();
  const std::vector<float> radii = DrawnSmoothingRadii(thin.Stage(), thin.materials.size(), r0);
  // Within [r0, 4 r0]; below 4 r0 the radius holds 32 observations of the region (itself and its
  // 31 nearest, normals within ~25°), above r0 it holds no more than 31 just inside.
  auto within = [&](size_t i, double r) {
    int n = 0;
    for (const Observation& other : thin.obs) {
      n += other.region == thin.obs[i].region && other.normal.dot(thin.obs[i].normal) >= 0.9f &&
           (other.position - thin.obs[i].position).norm() <= r;
    }
    return n;
  };
  int widened = 0;
  for (size_t i = 0; i < thin.obs.size(); ++i) {
    ASSERT_GE(radii[i], float(r0) * 0.999f);
    ASSERT_LE(radii[i], float(4 * r0) * 1.001f);
    if (radii[i] < float(4 * r0) * 0.999f) {
      EXPECT_GE(within(i, radii[i] * 1.0001), 32) << i;
    }
    if (radii[i] > float(r0) * 1.001f) {
      ++widened;
      EXPECT_LT(within(i, radii[i] * 0.9999), 32) << i;
    }
  }
  EXPECT_GT(widened, 100);
}

TEST_F(ObservationDrawRoom, ABudgetThatCannotHoldAPhotoIsRefusedBeforeAnyWork) {
  const recon::Scene scene = recon::LoadScene(*dir_ / "scene.json");
  SolveOptions o = Options();
  o.memory_budget = 0.01;  // 10 MiB: less than the process itself
  SolverState s(scene, o);
  try {
    s.Prepare();
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("photos["), std::string::npos) << what;
    EXPECT_NE(what.find("--memory-budget"), std::string::npos) << what;
  }
  EXPECT_TRUE(s.obs.empty());
}

}  // namespace
}  // namespace igi::solver
