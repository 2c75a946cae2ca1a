// The albedo-map stage alone (solver/inverse/albedo_map_stage.h), on data built by hand:
// observations of a 1 m square under a known irradiance, photographed by two photos, whose radiance
// is a true albedo × E/π with a few paths' noise. No photo is read and nothing is gathered or
// fitted.
#include "solver/inverse/albedo_map_stage.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>

#include "solver/inverse/solve_internal.h"
#include "tests/solver/stage_fixture.h"

namespace igi::solver {
namespace {

constexpr double kIrradiance = 3.0;

// A checker of 0.1 m cells, ±30 % about 0.5.
double Checker(double u, double v) { return 0.5 * ((int(u * 10) + int(v * 10)) % 2 ? 1.3 : 0.7); }

// The stage's inputs (tests/solver/stage_fixture.h): `albedo(u, v)` on the square, `per_texel`
// observations per 2 cm texel on average, each observation's radiance times (1 + noise) with 3 %
// of them fireflies of 8×.
struct StageFixture : test::SquareStage {
  StageFixture(const std::function<double(double, double)>& albedo, int per_texel, unsigned seed)
      : SquareStage("map_stage", 2500 * per_texel, kIrradiance, seed,
                    [&albedo, gauss = std::normal_distribution<double>(0.0, 0.1),
                     u01 = std::uniform_real_distribution<double>(0.0, 1.0)](
                        double u, double v, std::mt19937& rng) mutable {
                      const double noise = 1 + gauss(rng) + (u01(rng) < 0.03 ? 8.0 : 0.0);
                      return albedo(u, v) * kIrradiance / render::kPi * noise;
                    }) {}

  MapStageData Data() const {
    return MapStageData{scene, options, obs, materials, patches, light, 0.02, 1.0};
  }
};

TEST(AlbedoMapStage, TheMapOfTheObservationsIsTheirAlbedo) {
  // 32 observations per texel: the texel means' noise (mean 1.24, the fireflies' share) is a
  // scale the maps carry; the checker's contrast shows through it.
  const StageFixture f(Checker, 32, 1);
  const MapStageData d = f.Data();
  ASSERT_TRUE(MapCandidate(d, 0));
  const RegionAtlas atlas = MapAtlas(d, 0);
  const MapLight light = MapLightOf(d);
  double coverage = 0;
  Image seen;
  const Image map = AlbedoMapOf(d, 0, atlas, light, &coverage, &seen);
  ASSERT_EQ(map.width, 50);
  EXPECT_GT(coverage, 0.95);
  // Texel centres away from the cells' edges: the ratio to the truth is the noise's mean.
  double ratio_light = 0, ratio_dark = 0;
  int n_light = 0, n_dark = 0;
  for (int y = 0; y < map.height; ++y) {
    for (int x = 0; x < map.width; ++x) {
      const double u = (x + 0.5) / map.width, v = 1 - (y + 0.5) / map.height;
      if (std::abs(u * 10 - std::round(u * 10)) < 0.2 ||
          std::abs(v * 10 - std::round(v * 10)) < 0.2) {
        continue;
      }
      const double truth = Checker(u, v);
      (truth > 0.5 ? ratio_light : ratio_dark) += map.at(x, y, 0) / truth;
      ++(truth > 0.5 ? n_light : n_dark);
    }
  }
  ASSERT_GT(n_light, 100);
  ASSERT_GT(n_dark, 100);
  // The light and dark cells in the same ratio to their truth: the map has the texture.
  EXPECT_NEAR((ratio_light / n_light) / (ratio_dark / n_dark), 1.0, 0.05);
}

TEST(AlbedoMapStage, ATextureFinerThanThePatchesGetsAMapAndNoiseDoesNot) {
  TexelDetail detail;
  {
    const StageFixture f(Checker, 8, 2);
    const MapStageData d = f.Data();
    EXPECT_TRUE(WritesMap(d, 0, MapAtlas(d, 0), MapLightOf(d), &detail));
    // The checker's 30 % relative to the map's mean (raised 24 % by the fireflies), less what
    // the 7 × 7-texel local means take of its 5-texel cells: about 20 %.
    EXPECT_GT(detail.variation, 0.15);
    EXPECT_LT(detail.variation, 0.3);
    EXPECT_GT(detail.z, 3);
  }
  for (unsigned seed = 3; seed < 8; ++seed) {
    const StageFixture f([](double, double) { return 0.5; }, 8, seed);
    const MapStageData d = f.Data();
    EXPECT_FALSE(WritesMap(d, 0, MapAtlas(d, 0), MapLightOf(d), &detail))
        << seed << ": variation " << detail.variation << ", z " << detail.z;
  }
}

TEST(AlbedoMapStage, TheOptionsDecideWhichRegionsMayHaveAMap) {
  StageFixture f([](double, double) { return 0.5; }, 1, 9);
  EXPECT_TRUE(MapCandidate(f.Data(), 0));
  f.options.albedo_maps = AlbedoMaps::kNone;
  EXPECT_FALSE(MapCandidate(f.Data(), 0));
  f.options.albedo_maps = AlbedoMaps::kAll;
  EXPECT_TRUE(WritesMap(f.Data(), 0, MapAtlas(f.Data(), 0), MapLightOf(f.Data()), nullptr));
  f.options.albedo_map_regions = {"wall"};
  EXPECT_FALSE(MapCandidate(f.Data(), 0));
}

TEST(AlbedoMapStage, TheRefinementsMapIsTheObservationsWhereSeenAndThePatchesElsewhere) {
  // The checker seen on the square's left half only (the right half's observations have no
  // irradiance, so the map leaves them out); the fit's per-patch albedos set by hand, every
  // third patch without one (the region's ρd).
  StageFixture f(Checker, 32, 5);
  for (size_t i = 0; i < f.obs.size(); ++i) {
    if (f.obs[i].position.x() > 0) f.light.e[i].setZero();
  }
  MaterialState& m = f.materials[0];
  m.params.rho_d = Eigen::Vector3d(0.5, 0.4, 0.3);
  for (size_t s = 0; s < m.patch_rho_d.size(); ++s) {
    m.patch_rho_d[s] = s % 3 == 2 ? Eigen::Vector3d::Constant(NAN)
                                  : Eigen::Vector3d(0.1 + 0.001 * s, 0.2, 0.9 - 0.001 * s);
  }
  const MapStageData d = f.Data();
  const RegionAtlas atlas = MapAtlas(d, 0);
  const Image map = RefinementAlbedoMap(d, 0, atlas, MapLightOf(d));
  // Texel (x, y) of the square's UVs (u = x + 0.5 m, v = y + 0.5 m): its centre's triangle and
  // barycentrics (triangle 0: corners (0,0), (1,0), (1,1) in UV; triangle 1: (0,0), (1,1), (0,1)).
  int right = 0, patch_albedo = 0, unseen = 0;
  double left_ratio = 0;
  int left = 0;
  for (int y = 0; y < map.height; ++y) {
    for (int x = 0; x < map.width; ++x) {
      const double u = (x + 0.5) / map.width, v = 1 - (y + 0.5) / map.height;
      const Eigen::Vector3d got(map.at(x, y, 0), map.at(x, y, 1), map.at(x, y, 2));
      if (u < 0.45) {  // seen: the observations' albedo (the checker times the noise's mean)
        left_ratio += got[0] / Checker(u, v);
        ++left;
        continue;
      }
      if (u < 0.55) continue;
      ++right;
      const int q = u >= v ? f.patches.PatchOf(0, u - v, v) : f.patches.PatchOf(1, u, v - u);
      const Eigen::Vector3d want = f.materials.PatchAlbedo(f.patches, q);
      if ((got - want).cwiseAbs().maxCoeff() < 1e-6) {
        ++patch_albedo;
        unseen += want == m.params.rho_d;
      }
    }
  }
  // Unseen: each texel its patch's albedo (texels on the diagonal belong to both triangles).
  EXPECT_GT(patch_albedo, right * 95 / 100);
  EXPECT_GT(unseen, patch_albedo / 5);  // the region's ρd where a patch has none of its own
  // Seen: the observations' checker in a constant ratio (the fireflies' mean, 1.24), not the
  // patches' values (0.1-0.35 in red).
  EXPECT_NEAR(left_ratio / left, 1.24, 0.1);
}

TEST(AlbedoMapStage, TheSpecularTermIsTheOwnDirectLobeAndTheNeighboursIndirectLight) {
  // A glossy square (Ward, α 0.1) seen from straight above, its observations each with one direct
  // sample of 1 W/m²: from the light's mirror direction within 0.1 m of the centre (a
  // highlight), 45° off it elsewhere (no lobe); each T is that direct lobe plus 0.02 of indirect
  // light. Over a smoothing radius of about 0.1 m, a mean of the whole T would raise the
  // highlight's flanks and lower its core; the maps subtract each observation's own direct lobe
  // and the neighbours' mean of the indirect part.
  StageFixture f([](double, double) { return 0.5; }, 4, 3);
  render::BrdfParams& p = f.materials[0].params;
  p.model = recon::BrdfModel::kWard;
  p.rho_s = Eigen::Vector3d::Constant(0.05);
  p.alpha = 0.1;
  for (int k = 0; k < 2; ++k) {
    recon::Photo photo;
    photo.lighting = 0;
    f.scene.photos.push_back(photo);
  }
  GatherSet& gather = f.light.lightings[0].gather;
  const Eigen::Vector3d view(0, 0, 1);
  const render::Frame frame = f.materials.LocalFrame(0, view);
  std::vector<bool> in_highlight(f.obs.size());
  std::vector<Eigen::Vector3d> direct_lobe(f.obs.size());
  for (size_t i = 0; i < f.obs.size(); ++i) {
    const Observation& o = f.obs[i];
    in_highlight[i] = o.position.head<2>().norm() < 0.1;
    DirectSample sample;
    sample.wi = in_highlight[i] ? Eigen::Vector3f(0, 0, 1) : Eigen::Vector3f(1, 0, 1).normalized();
    sample.value = Eigen::Vector3f::Ones();
    GatherPoint point;
    point.direct_begin = int64_t(gather.direct.size());
    point.direct_end = point.direct_begin + 1;
    gather.direct.push_back(sample);
    gather.points.push_back(point);
    f.light.point.push_back(int(i));
    Eigen::Vector3d offset;
    direct_lobe[i] = DirectSpecularTerm(p, 0.0, frame, view, &sample, 1, &offset);
    f.light.t[i] = direct_lobe[i] + Eigen::Vector3d::Constant(0.02);
  }
  const MapStageData d{f.scene, f.options, f.obs, f.materials, f.patches, f.light, 0.02, 10.0};
  const MapLight light = MapLightOf(d);
  int highlight = 0, flank = 0;
  for (size_t i = 0; i < f.obs.size(); ++i) {
    const double r = f.obs[i].position.head<2>().norm();
    if (in_highlight[i]) {
      EXPECT_GT(direct_lobe[i][0], 1.0);
      ++highlight;
    } else if (r < 0.2) {
      EXPECT_LT(direct_lobe[i][0], 1e-6);
      ++flank;
    }
    if (in_highlight[i] || r < 0.2) {
      ASSERT_NEAR(light.t[i][0], direct_lobe[i][0] + 0.02, 1e-6) << "observation " << i;
      ASSERT_NEAR(light.t_indirect[i][0], 0.02, 1e-9) << "observation " << i;
    }
  }
  EXPECT_GT(highlight, 50);
  EXPECT_GT(flank, 100);
}

TEST(AlbedoMapStage, TheWrittenMapIsScaledAndClippedOnlyInAChannelHeldAtOne) {
  // Red fitted at 1.25 (held at 1: scaled by 0.8, then clipped); green and blue within 1 keep
  // their texels, noise above 1 included, so that their mean stays the written ρd.
  Image map(2, 1, 3);
  const float texels[2][3] = {{1.5f, 1.4f, 0.2f}, {1.0f, 0.6f, 0.4f}};
  for (int x = 0; x < 2; ++x) {
    for (int c = 0; c < 3; ++c) map.at(x, 0, c) = texels[x][c];
  }
  EXPECT_EQ(ScaleMapHeldAtOne(Eigen::Vector3d(0.8, 1, 1), &map), 1);
  EXPECT_FLOAT_EQ(map.at(0, 0, 0), 1.0f);  // 1.2 clipped
  EXPECT_FLOAT_EQ(map.at(1, 0, 0), 0.8f);
  EXPECT_FLOAT_EQ(map.at(0, 0, 1), 1.4f);
  EXPECT_FLOAT_EQ(map.at(1, 0, 1), 0.6f);
  EXPECT_FLOAT_EQ(map.at(0, 0, 2), 0.2f);
}

}  // namespace
}  // namespace igi::solver
