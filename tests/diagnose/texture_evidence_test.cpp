// texture_evidence: a texture (a ratio to the constant-albedo model that changes from cell to cell,
// the same in every photo) is found; photo noise, smooth lighting errors and a sharp shadow edge
// are not textures. Synthetic records on a 1.2 m × 1.2 m floor with known ratios.
#include "solver/diagnose/texture_evidence.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <random>

namespace igi::diagnose {
namespace {

// Records every 1.5 cm over the floor z = 0, seen by 4 photos with 12 % photo noise (a 16-spp
// render's), the photos recording `ratio`(x, y) times the model.
std::vector<PixelRecord> FloorRecords(const std::function<double(double, double)>& ratio,
                                      uint32_t seed, double size = 1.2) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.12);
  std::vector<PixelRecord> out;
  for (int photo = 0; photo < 4; ++photo) {
    for (double y = 0.0; y < size; y += 0.015) {
      for (double x = 0.0; x < size; x += 0.015) {
        PixelRecord r;
        r.photo = photo;
        r.region = 0;
        r.position = Eigen::Vector3f(float(x), float(y), 0.0f);
        r.sim = Eigen::Vector3f::Constant(0.5f);
        r.recorded = r.sim * float(ratio(x, y) * (1 + noise(rng)));
        out.push_back(r);
      }
    }
  }
  return out;
}

recon::Scene FloorScene() {
  recon::Scene s;
  recon::Material m;
  m.name = "floor";
  s.materials.push_back(m);
  return s;
}

TextureEvidence Evidence(const std::function<double(double, double)>& ratio, double size = 1.2) {
  TextureEvidenceOptions o;
  o.cell_m = 0.05;
  const std::vector<TextureEvidence> e =
      FindTexturedRegions(FloorScene(), FloorRecords(ratio, 7, size), {true}, o);
  EXPECT_EQ(e.size(), 1u);
  if (!e.empty()) {
    std::printf("cells %d agreement %.3f z %.1f amplitude %.4f\n", e[0].cells, e[0].agreement,
                e[0].z, e[0].amplitude);
  }
  return e.empty() ? TextureEvidence{} : e[0];
}

// A blotchy albedo at the scale of a few cells (±10 %): what igi-synth's textured walls show.
double FaintBlotches(double x, double y, double amplitude) {
  const int ix = int(std::floor(x / 0.07)), iy = int(std::floor(y / 0.07));
  const uint32_t h = uint32_t(ix * 73856093) ^ uint32_t(iy * 19349663);
  return 1.0 + amplitude * ((h % 1000) / 500.0 - 1.0);
}
double Blotches(double x, double y) { return FaintBlotches(x, y, 0.1); }

TEST(TextureEvidence, FindsABlotchyTexture) {
  const TextureEvidence e = Evidence(Blotches);
  EXPECT_TRUE(e.textured) << "agreement " << e.agreement << " z " << e.z << " amplitude "
                          << e.amplitude;
  EXPECT_GT(e.amplitude, 0.015);
}

// A faint texture on few cells, as the suite's control floor showed (±7 % blotches under 12 %
// noise on a 0.75 m square: 225 cells): the signs agree in 65 % of the cells, a sign test's z of
// 4.6 (the control's: 3.9–4.1, 218 cells, 63–64 %) stays under 5; the rank correlation of the
// values (z 7.1) finds it.
TEST(TextureEvidence, FindsAFaintTextureOnFewCells) {
  const TextureEvidence e =
      Evidence([](double x, double y) { return FaintBlotches(x, y, 0.07); }, 0.75);
  EXPECT_LT(e.cells, 250);
  EXPECT_LT(e.sign_z, 5.0) << "a sign test would find it: not the faint case";
  EXPECT_TRUE(e.textured) << "rank correlation " << e.rank_correlation << " z " << e.z
                          << " agreement " << e.agreement << " amplitude " << e.amplitude;
}

TEST(TextureEvidence, PhotoNoiseAloneIsNoTexture) {
  const TextureEvidence e = Evidence([](double, double) { return 1.0; });
  EXPECT_FALSE(e.textured) << "agreement " << e.agreement << " z " << e.z << " amplitude "
                           << e.amplitude;
  EXPECT_LT(std::abs(e.agreement - 0.5), 0.08);
}

TEST(TextureEvidence, SmoothLightingErrorsAreNoTexture) {
  // An emission profile's fall-off and a hot spot: large, but smooth over the cells.
  const TextureEvidence e = Evidence([](double x, double y) {
    return (1 + 0.5 * x) * (1 + 0.4 * std::exp(-((x - 0.6) * (x - 0.6) + y * y) / 0.08));
  });
  EXPECT_FALSE(e.textured) << "agreement " << e.agreement << " z " << e.z << " amplitude "
                           << e.amplitude;
}

TEST(TextureEvidence, ASharpShadowEdgeIsNoTexture) {
  // A penumbra the model misses: a 40 % step along one line of cells.
  const TextureEvidence e = Evidence([](double x, double) { return x < 0.61 ? 1.0 : 0.6; });
  EXPECT_FALSE(e.textured) << "agreement " << e.agreement << " z " << e.z << " amplitude "
                           << e.amplitude;
}

// Large flat tiles (0.75 m, ±20 %, 1.5 cm joints at 40 %) on a 3 m floor.
double Tiles(double x, double y) {
  const double fx = std::fmod(x, 0.75), fy = std::fmod(y, 0.75);
  if (fx < 0.015 || fy < 0.015) return 0.4;
  const int ix = int(x / 0.75), iy = int(y / 0.75);
  const uint32_t h = uint32_t(ix * 73856093) ^ uint32_t(iy * 19349663);
  return 1.0 + 0.2 * ((h % 1000) / 500.0 - 1.0);
}

// The floor seen sparsely, as 160 × 120 photos see a 4 m room's floor at igi-diagnose's stride:
// each of 4 photos has `per_photo` records at its own random points, 12 % noise.
std::vector<PixelRecord> SparseFloorRecords(const std::function<double(double, double)>& ratio,
                                            uint32_t seed, double size, int per_photo) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, size);
  std::normal_distribution<double> noise(0.0, 0.12);
  std::vector<PixelRecord> out;
  for (int photo = 0; photo < 4; ++photo) {
    for (int i = 0; i < per_photo; ++i) {
      PixelRecord r;
      r.photo = photo;
      r.region = 0;
      const double x = u(rng), y = u(rng);
      r.position = Eigen::Vector3f(float(x), float(y), 0.0f);
      r.sim = Eigen::Vector3f::Constant(0.5f);
      r.recorded = r.sim * float(ratio(x, y) * (1 + noise(rng)));
      out.push_back(r);
    }
  }
  return out;
}

TEST(TextureEvidence, FindsLargeTilesAtACoarserScale) {
  TextureEvidenceOptions o;
  o.cell_m = 0.05;
  const std::vector<PixelRecord> records = SparseFloorRecords(Tiles, 7, 3.0, 3000);
  o.scales = {1};
  const std::vector<TextureEvidence> one = FindTexturedRegions(FloorScene(), records, {true}, o);
  o.scales = {1, 2, 3};
  const std::vector<TextureEvidence> three = FindTexturedRegions(FloorScene(), records, {true}, o);
  ASSERT_EQ(one.size(), 1u);
  ASSERT_EQ(three.size(), 1u);
  for (const TextureEvidence& e : {one[0], three[0]}) {
    std::printf("cells %d of %.0f cm, agreement %.3f z %.1f amplitude %.4f\n", e.cells,
                100 * e.cell_m, e.agreement, e.z, e.amplitude);
  }
  EXPECT_FALSE(one[0].textured);
  EXPECT_TRUE(three[0].textured);
  EXPECT_GT(three[0].cell_m, 0.06);
}

TEST(TextureEvidence, OnlySolvedRegionsAreTested) {
  TextureEvidenceOptions o;
  o.cell_m = 0.05;
  EXPECT_TRUE(FindTexturedRegions(FloorScene(), FloorRecords(Blotches, 7), {false}, o).empty());
  // Held-out records are not used: with every record held out there is nothing to test.
  std::vector<PixelRecord> held = FloorRecords(Blotches, 7);
  for (PixelRecord& r : held) r.held_out = true;
  EXPECT_TRUE(FindTexturedRegions(FloorScene(), held, {true}, o).empty());
}

}  // namespace
}  // namespace igi::diagnose
