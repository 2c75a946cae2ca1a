// Albedo maps (solver/inverse/albedo_map.h): splatting ratio samples into an atlas, push-pull
// filling, and PSNR.
#include "solver/inverse/albedo_map.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <random>
#include <utility>
#include <vector>

#include "solver/render/ray_scene.h"
#include "tools/common/error.h"

namespace igi::solver {
namespace {

constexpr float kQuadW = 1.0f, kQuadH = 0.5f;

// A 1 × 0.5 m rectangle in z = 0 with UVs [0,1]² (u = x / 1 m, v = y / 0.5 m), region "floor".
recon::TriangleMesh Quad() {
  recon::TriangleMesh mesh;
  mesh.positions = {{0, 0, 0}, {kQuadW, 0, 0}, {kQuadW, kQuadH, 0}, {0, kQuadH, 0}};
  mesh.normals.assign(4, Eigen::Vector3f::UnitZ());
  mesh.uvs = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  mesh.triangle_region = {0, 0};
  mesh.region_names = {"floor"};
  return mesh;
}

// A 1 × 0.6 × 0.4 m box without UVs (generated charts), 12 triangles, one region.
recon::TriangleMesh Box() {
  recon::TriangleMesh mesh;
  for (int i = 0; i < 8; ++i) {
    mesh.positions.emplace_back((i & 1) ? 1.0f : 0, (i & 2) ? 0.6f : 0, (i & 4) ? 0.4f : 0);
  }
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    mesh.triangles.emplace_back(q[0], q[1], q[2]);
    mesh.triangles.emplace_back(q[0], q[2], q[3]);
  }
  mesh.triangle_region.assign(12, 0);
  mesh.region_names = {"box"};
  return mesh;
}

// The renderer's own lookup (solver/render/ray_scene.h SampleTexture): the map must match what it
// reads.
Eigen::Vector3d Lookup(const Image& tex, const Eigen::Vector2d& uv) {
  return render::SampleTexture(tex, uv);
}

// A smooth albedo over the quad, different in every channel and asymmetric in x and y (so a
// flipped or transposed map cannot pass).
Eigen::Vector3d Albedo(double x, double y) {
  return Eigen::Vector3d(0.5 + 0.3 * std::sin(2 * M_PI * x) * std::cos(M_PI * y),
                         0.2 + 0.6 * y / kQuadH, 0.2 + 0.5 * x / kQuadW + 0.1 * y / kQuadH);
}

struct Sample {
  int triangle;
  double b1, b2;
  Eigen::Vector3d position;
};

Sample RandomPoint(const recon::TriangleMesh& mesh, const std::vector<int>& tris,
                   std::mt19937& rng) {
  std::uniform_real_distribution<double> u01(0, 1);
  Sample s;
  s.triangle = tris[std::uniform_int_distribution<size_t>(0, tris.size() - 1)(rng)];
  const double r1 = std::sqrt(u01(rng)), r2 = u01(rng);  // uniform over the triangle
  s.b1 = r1 * (1 - r2);
  s.b2 = r1 * r2;
  const Eigen::Vector3i& t = mesh.triangles[s.triangle];
  s.position = (1 - s.b1 - s.b2) * mesh.positions[t[0]].cast<double>() +
               s.b1 * mesh.positions[t[1]].cast<double>() +
               s.b2 * mesh.positions[t[2]].cast<double>();
  return s;
}

// Adds `n` samples of albedo `f` with random irradiance E in [0.2, 2] and weights in [0.5, 1.5]
// at random points of `tris` for which `keep(position)` holds.
template <typename F, typename Keep>
void AddSamples(const recon::TriangleMesh& mesh, const std::vector<int>& tris, int n, F f,
                Keep keep, AlbedoMapBuilder* builder, std::mt19937& rng) {
  std::uniform_real_distribution<double> e_dist(0.2, 2.0), w_dist(0.5, 1.5);
  for (int i = 0; i < n;) {
    const Sample s = RandomPoint(mesh, tris, rng);
    if (!keep(s.position)) continue;
    const Eigen::Vector3d e(e_dist(rng), e_dist(rng), e_dist(rng));
    const double w = w_dist(rng);
    builder->Add(s.triangle, s.b1, s.b2, w * f(s.position).cwiseProduct(e), w * e);
    ++i;
  }
}

TEST(AlbedoMap, SmoothAlbedoOnQuadIsRecoveredWhereTheRendererLooksItUp) {
  const recon::TriangleMesh mesh = Quad();
  AtlasOptions options;
  options.texel_size_m = 0.01;
  const RegionAtlas atlas = BuildRegionAtlas(mesh, 0, options);
  ASSERT_EQ(atlas.width, 100);
  ASSERT_EQ(atlas.height, 50);
  std::mt19937 rng(7);
  AlbedoMapBuilder builder(atlas);
  const auto f = [](const Eigen::Vector3d& p) { return Albedo(p.x(), p.y()); };
  AddSamples(
      mesh, atlas.triangles, 100000, f, [](auto&) { return true; }, &builder, rng);
  EXPECT_GT(builder.Coverage(), 0.999);
  const Image map = builder.Finish(Eigen::Vector3d::Zero());
  ASSERT_EQ(map.width, 100);
  ASSERT_EQ(map.height, 50);

  // Looked up at random points as the renderer does. Each texel is a weighted average of f over
  // the random samples within ±1 texel, and the lookup interpolates between texel centres:
  // - inside, the bias is second order, about h²·|f''|/4 ≈ 1e-4 · 12 / 4 = 3e-4 (h = 1 cm,
  //   |f''| <= 0.3·(2π)² ≈ 12 per m²), and the random sample positions add noise of about
  //   h·|f'|/sqrt(12·n) ≈ 0.01 · 1.9 / sqrt(12 · 20) ≈ 1.2e-3 (|f'| <= 1.9 per m, n ≈ 20 samples
  //   per texel): RMS < 1e-3, max over 5000 lookups (≈ 4σ) < 5e-3;
  // - within 1.5 texels of the border the clamped footprint is one-sided: a first-order bias of
  //   about h·|f'|/3 ≈ 6e-3 plus that noise: max < 2.5e-2.
  double max_inner = 0, max_border = 0, sum_sq_inner = 0;
  int n_inner = 0;
  std::uniform_real_distribution<double> u01(0, 1);
  for (int i = 0; i < 5000; ++i) {
    const double u = u01(rng), v = u01(rng);
    const double error =
        (Lookup(map, {u, v}) - Albedo(u * kQuadW, v * kQuadH)).cwiseAbs().maxCoeff();
    if (std::min(u, 1 - u) * atlas.width < 1.5 || std::min(v, 1 - v) * atlas.height < 1.5) {
      max_border = std::max(max_border, error);
    } else {
      max_inner = std::max(max_inner, error);
      sum_sq_inner += error * error;
      ++n_inner;
    }
  }
  const double rms_inner = std::sqrt(sum_sq_inner / n_inner);
  std::printf("error inside: RMS %.2e, max %.2e; near the border: max %.2e\n", rms_inner, max_inner,
              max_border);
  EXPECT_LT(rms_inner, 1e-3);
  EXPECT_LT(max_inner, 5e-3);
  EXPECT_LT(max_border, 2.5e-2);

  // PSNR against f at the texel centres (peak 1): the same errors; > 60 dB means RMS < 1e-3.
  Image truth(map.width, map.height, 3);
  for (int y = 0; y < truth.height; ++y) {
    for (int x = 0; x < truth.width; ++x) {
      const Eigen::Vector3d a =
          Albedo((x + 0.5) / truth.width * kQuadW, (1 - (y + 0.5) / truth.height) * kQuadH);
      for (int c = 0; c < 3; ++c) truth.at(x, y, c) = float(a[c]);
    }
  }
  const double psnr = AlbedoPsnr(map, truth, 1.0);
  std::printf("PSNR %.1f dB\n", psnr);
  EXPECT_GT(psnr, 60.0);
}

TEST(AlbedoMap, TexelConventionMatchesTheRenderer) {
  const RegionAtlas atlas = BuildRegionAtlas(Quad(), 0, {});  // 100 × 50
  AlbedoMapBuilder builder(atlas);
  // Triangle 0 has corner UVs (0,0), (1,0), (1,1): UV = (b1 + b2, b2). A sample exactly at the
  // centre of texel (column 80, row 10) — u = 80.5/100, v = 1 − 10.5/50 — lands on it alone.
  const double u = 80.5 / 100, v = 1 - 10.5 / 50;
  builder.Add(0, u - v, v, Eigen::Vector3d(0.1, 0.2, 0.3), Eigen::Vector3d::Ones());
  builder.Add(1, 0.0, 0.0, Eigen::Vector3d(0.9, 0.9, 0.9),
              Eigen::Vector3d::Ones());  // texel (0, 49)
  const Image map = builder.Finish(Eigen::Vector3d::Zero());
  EXPECT_FLOAT_EQ(map.at(80, 10, 0), 0.1f);
  EXPECT_FLOAT_EQ(map.at(80, 10, 2), 0.3f);
  EXPECT_FLOAT_EQ(map.at(0, 49, 1), 0.9f);  // UV (0, 0): bottom-left texel, last row
  EXPECT_NEAR(Lookup(map, {u, v}).y(), 0.2, 1e-6);
}

TEST(AlbedoMap, TexelCentresTakeTheValueAtTheirSurfacePoint) {
  // The box's generated charts: every texel centre on the surface gets Albedo() of its own
  // world point, exactly (the barycentrics of the centre, not of a sample near it); the gutters
  // and the space between charts are filled.
  const recon::TriangleMesh mesh = Box();
  const RegionAtlas atlas = BuildRegionAtlas(mesh, 0, {});
  ASSERT_TRUE(atlas.generated);
  AlbedoMapBuilder builder(atlas);
  auto point = [&](int t, double b1, double b2) {
    const Eigen::Vector3i& tri = mesh.triangles[t];
    return Eigen::Vector3d(((1 - b1 - b2) * mesh.positions[tri[0]].cast<double>() +
                            b1 * mesh.positions[tri[1]].cast<double>() +
                            b2 * mesh.positions[tri[2]].cast<double>()));
  };
  builder.FillTexelCentres([&](int t, double b1, double b2) {
    const Eigen::Vector3d p = point(t, b1, b2);
    return Albedo(p.x() + p.z(), p.y());
  });
  EXPECT_DOUBLE_EQ(builder.Coverage(), 1.0);
  const Image map = builder.Finish(Eigen::Vector3d(9, 9, 9));
  // Each triangle's centroid read back at its texel (nearest centre, within half a texel of
  // the centroid: the albedo changes by at most 1.9 per m · 0.5 cm · √2 there).
  for (int t : atlas.triangles) {
    const Eigen::Vector2d uv = atlas.UvAt(t, 1.0 / 3, 1.0 / 3);
    const int x = std::clamp(int(uv.x() * map.width), 0, map.width - 1);
    const int y = std::clamp(int((1 - uv.y()) * map.height), 0, map.height - 1);
    const Eigen::Vector3d p = point(t, 1.0 / 3, 1.0 / 3);
    const Eigen::Vector3d want = Albedo(p.x() + p.z(), p.y());
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(map.at(x, y, c), want[c], 0.015) << t << " " << c;
  }
  for (int y = 0; y < map.height; ++y) {
    for (int x = 0; x < map.width; ++x) ASSERT_LT(map.at(x, y, 0), 9.f);  // nothing unfilled
  }
}

TEST(AlbedoMap, ConstantAlbedoFillsEveryTexelIncludingGutters) {
  const recon::TriangleMesh mesh = Box();
  const RegionAtlas atlas = BuildRegionAtlas(mesh, 0, {});
  ASSERT_TRUE(atlas.generated);
  AlbedoMapBuilder builder(atlas);
  std::mt19937 rng(3);
  const Eigen::Vector3d albedo(0.3, 0.5, 0.7);
  // 200 samples over ~ 3 m² of 1-cm texels: almost every texel is a hole.
  AddSamples(
      mesh, atlas.triangles, 200, [&](auto&) { return albedo; }, [](auto&) { return true; },
      &builder, rng);
  EXPECT_GT(builder.Coverage(), 0.0);
  EXPECT_LT(builder.Coverage(), 0.02);
  const Image map = builder.Finish(Eigen::Vector3d(9, 9, 9));
  double max_error = 0;
  for (int y = 0; y < map.height; ++y) {
    for (int x = 0; x < map.width; ++x) {
      for (int c = 0; c < 3; ++c)
        max_error = std::max(max_error, std::abs(map.at(x, y, c) - albedo[c]));
    }
  }
  // Push-pull only forms convex combinations of the (float) texel values: float rounding.
  EXPECT_LT(max_error, 1e-6);
}

TEST(AlbedoMap, HolesGetValuesFromTheirNeighbourhood) {
  const recon::TriangleMesh mesh = Quad();
  const RegionAtlas atlas = BuildRegionAtlas(mesh, 0, {});
  AlbedoMapBuilder builder(atlas);
  std::mt19937 rng(5);
  // Albedo 0.2 + 0.5·x observed only on x < 0.4 m (texel columns < 40).
  const auto f = [](const Eigen::Vector3d& p) {
    return Eigen::Vector3d::Constant(0.2 + 0.5 * p.x());
  };
  AddSamples(
      mesh, atlas.triangles, 50000, f, [](const auto& p) { return p.x() < 0.4; }, &builder, rng);
  EXPECT_NEAR(builder.Coverage(), 0.4, 0.02);
  const Image map = builder.Finish(Eigen::Vector3d::Zero());
  for (int y = 0; y < map.height; ++y) {
    for (int x = 0; x < map.width; ++x) {
      // Every value is a convex combination of observed ones: within [0.2, 0.4] (± float).
      EXPECT_GE(map.at(x, y, 0), 0.2f - 1e-5f);
      EXPECT_LE(map.at(x, y, 0), 0.4f + 1e-5f);
    }
    // Next to the hole's edge the fill continues the observed value (0.4 − 0.005 at column 39):
    // the nearest coarse levels average a few texels back, so within 0.02.
    EXPECT_NEAR(map.at(41, y, 0), 0.395, 0.02) << "row " << y;
  }
}

TEST(AlbedoMap, EmptyBuilderGivesFallback) {
  const RegionAtlas atlas = BuildRegionAtlas(Box(), 0, {});
  AlbedoMapBuilder builder(atlas);
  EXPECT_EQ(builder.Coverage(), 0.0);
  // Non-finite samples are ignored.
  builder.Add(0, 0.2, 0.2, Eigen::Vector3d::Constant(NAN), Eigen::Vector3d::Ones());
  EXPECT_EQ(builder.num_samples(), 0);
  const Image map = builder.Finish(Eigen::Vector3d(0.25, 0.5, 0.75));
  ASSERT_EQ(map.width, atlas.width);
  ASSERT_EQ(map.height, atlas.height);
  ASSERT_EQ(map.channels, 3);
  for (size_t i = 0; i < map.pixels.size(); ++i) EXPECT_EQ(map.pixels[i], 0.25f * (1 + i % 3));
  EXPECT_THROW(builder.Add(99, 0, 0, Eigen::Vector3d::Ones(), Eigen::Vector3d::Ones()), Error);
}

TEST(AlbedoMap, ChannelWithoutIrradianceFallsBack) {
  const RegionAtlas atlas = BuildRegionAtlas(Quad(), 0, {});
  AlbedoMapBuilder builder(atlas);
  for (int i = 0; i < 100; ++i) {  // red light only: blue cannot be estimated
    builder.Add(i % 2, 0.3, 0.3, Eigen::Vector3d(0.5, 0.25, 0), Eigen::Vector3d(1, 0.5, 0));
  }
  const Image map = builder.Finish(Eigen::Vector3d(0.1, 0.1, 0.1));
  EXPECT_FLOAT_EQ(map.at(50, 25, 0), 0.5f);
  EXPECT_FLOAT_EQ(map.at(50, 25, 1), 0.5f);
  EXPECT_FLOAT_EQ(map.at(50, 25, 2), 0.1f);
}

TEST(AlbedoMap, MergeEqualsOneBuilder) {
  const recon::TriangleMesh mesh = Box();
  const RegionAtlas atlas = BuildRegionAtlas(mesh, 0, {});
  AlbedoMapBuilder all(atlas), even(atlas), odd(atlas);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u01(0.1, 0.9);
  for (int i = 0; i < 20000; ++i) {
    const Sample s = RandomPoint(mesh, atlas.triangles, rng);
    const Eigen::Vector3d num(u01(rng), u01(rng), u01(rng)), den(1, 1, 1);
    all.Add(s.triangle, s.b1, s.b2, num, den);
    (i % 2 ? odd : even).Add(s.triangle, s.b1, s.b2, num, den);
  }
  even.Merge(odd);
  EXPECT_EQ(even.num_samples(), 20000);
  EXPECT_DOUBLE_EQ(even.Coverage(), all.Coverage());
  const Image a = all.Finish(Eigen::Vector3d::Zero()), b = even.Finish(Eigen::Vector3d::Zero());
  // Same sums in a different order: double rounding, then float output.
  EXPECT_GT(AlbedoPsnr(a, b, 1.0), 120.0);

  const RegionAtlas other = BuildRegionAtlas(Quad(), 0, {});
  AlbedoMapBuilder different(other);
  EXPECT_THROW(all.Merge(different), Error);
}

TEST(AlbedoMap, MinTexelWeightDecidesWhatIsDirect) {
  const RegionAtlas atlas = BuildRegionAtlas(Quad(), 0, {});
  // One sample at a texel corner gives each of 4 texels weight 1/4.
  const double u = 0.5, v = 0.5;
  for (double min_weight : {0.2, 0.5}) {
    AlbedoMapBuilder builder(atlas, min_weight);
    builder.Add(0, u - v, v, Eigen::Vector3d::Constant(0.4), Eigen::Vector3d::Ones());
    EXPECT_EQ(builder.Coverage() > 0, min_weight < 0.25) << min_weight;
  }
}

TEST(AlbedoPsnr, KnownImages) {
  Image truth(4, 3, 3, 0.0f), estimate(4, 3, 3, 0.1f);
  EXPECT_NEAR(AlbedoPsnr(estimate, truth, 1.0), 20.0, 1e-5);  // MSE 0.01
  EXPECT_NEAR(AlbedoPsnr(estimate, truth, 2.0), 20.0 + 20 * std::log10(2.0), 1e-5);
  Image one_off = truth;
  one_off.at(2, 1, 1) = 1.0f;  // MSE 1/36
  EXPECT_NEAR(AlbedoPsnr(one_off, truth, 1.0), 10 * std::log10(36.0), 1e-9);
  EXPECT_TRUE(std::isinf(AlbedoPsnr(truth, truth, 1.0)));
  EXPECT_THROW(AlbedoPsnr(Image(4, 4, 3), truth, 1.0), Error);
  EXPECT_THROW(AlbedoPsnr(Image(4, 3, 1), truth, 1.0), Error);
  EXPECT_THROW(AlbedoPsnr(truth, truth, 0.0), Error);
}

// The seen mask marks exactly the texels estimated directly: samples only on the left half of
// the quad leave the right half unseen (0) while Finish() fills it.
TEST(AlbedoMap, DirectMaskMarksTheTexelsTheSamplesReach) {
  const recon::TriangleMesh mesh = Quad();
  AtlasOptions options;
  options.texel_size_m = 0.02;
  const RegionAtlas atlas = BuildRegionAtlas(mesh, 0, options);
  std::mt19937 rng(3);
  AlbedoMapBuilder builder(atlas);
  AddSamples(
      mesh, atlas.triangles, 20000, [](const Eigen::Vector3d& p) { return Albedo(p.x(), p.y()); },
      [](const Eigen::Vector3d& p) { return p.x() < 0.5; }, &builder, rng);
  const Image mask = builder.DirectMask();
  ASSERT_EQ(mask.width, atlas.width);
  ASSERT_EQ(mask.channels, 1);
  int left = 0, right = 0;
  for (int y = 0; y < mask.height; ++y) {
    for (int x = 0; x < mask.width; ++x) {
      const double u = (x + 0.5) / mask.width;
      if (u < 0.45) left += mask.at(x, y) > 0.5f;
      if (u > 0.55) right += mask.at(x, y) > 0.5f;
    }
  }
  EXPECT_EQ(left, mask.height * 22);  // every texel centre at u < 0.45 (22 columns) is seen
  EXPECT_EQ(right, 0);
}

// CompareAlbedoMaps resamples the estimate at the truth's texels and, with a mask, compares only
// where the estimate was seen: an estimate wrong only in its unseen half is perfect over the seen.
TEST(AlbedoMap, CompareAlbedoMapsCountsOnlyTheSeenTexels) {
  Image truth(64, 32, 3), estimate(32, 16, 3), seen(32, 16, 1);
  for (int y = 0; y < 32; ++y) {
    for (int x = 0; x < 64; ++x) {
      for (int c = 0; c < 3; ++c) truth.at(x, y, c) = 0.5f;
    }
  }
  for (int y = 0; y < 16; ++y) {
    for (int x = 0; x < 32; ++x) {
      for (int c = 0; c < 3; ++c) estimate.at(x, y, c) = x < 16 ? 0.5f : 0.9f;
      seen.at(x, y) = x < 16 ? 1.f : 0.f;
    }
  }
  const AlbedoComparison all = CompareAlbedoMaps(estimate, nullptr, truth, 1.0);
  EXPECT_NEAR(all.compared, 1.0, 1e-12);
  EXPECT_LT(all.psnr_db, 12.0);  // half the texels off by 0.4: rms ≈ 0.28
  const AlbedoComparison part = CompareAlbedoMaps(estimate, &seen, truth, 1.0);
  // Truth columns whose lookup reads estimate columns < 16 only: x < 31 of 64.
  EXPECT_NEAR(part.compared, 31.0 / 64.0, 1e-12);
  EXPECT_TRUE(std::isinf(part.psnr_db));
  Image nothing(32, 16, 1);
  EXPECT_THROW(CompareAlbedoMaps(estimate, &nothing, truth, 1.0), Error);
  EXPECT_THROW(CompareAlbedoMaps(estimate, &truth, truth, 1.0), Error);  // mask size differs
}

// The seen means: SeenTexelMean over the map's own texels, TextureMeanOverSeenTexels over a
// finer texture's texels by the map texel their centre falls in (here 4 × 4 per map texel).
TEST(AlbedoMap, SeenMeansCountOnlyTheSeenTexels) {
  Image map(4, 2, 3, 0.0f), seen(4, 2, 1, 0.0f), texture(16, 8, 3, 0.0f);
  for (int y = 0; y < 2; ++y) {
    for (int x = 0; x < 4; ++x) {
      for (int c = 0; c < 3; ++c) map.at(x, y, c) = float(0.1 * (x + 4 * y) + 0.01 * c);
    }
  }
  seen.at(1, 0) = seen.at(2, 1) = 1.0f;  // values 0.1 and 0.6 (+0.01 c)
  const Eigen::Vector3d m = SeenTexelMean(map, seen);
  EXPECT_NEAR(m[0], 0.35, 1e-6);
  EXPECT_NEAR(m[2], 0.37, 1e-6);
  for (int y = 0; y < 8; ++y) {
    for (int x = 0; x < 16; ++x) {
      for (int c = 0; c < 3; ++c) texture.at(x, y, c) = float(x + 100 * y + 1000 * c);
    }
  }
  // Map texel (1, 0) holds texture columns 4..7 and rows 0..3; (2, 1) columns 8..11, rows 4..7.
  const Eigen::Vector3d t = TextureMeanOverSeenTexels(texture, seen);
  EXPECT_NEAR(t[0], (155.5 + 559.5) / 2, 1e-3);  // mean x 5.5 + 100 × mean y 1.5, and 9.5 + 550
  EXPECT_NEAR(t[2], 357.5 + 2000, 1e-3);
  EXPECT_TRUE(std::isnan(SeenTexelMean(map, Image(4, 2, 1, 0.0f))[0]));
  EXPECT_TRUE(std::isnan(TextureMeanOverSeenTexels(texture, Image(4, 2, 1, 0.0f))[1]));
}

// Two maps of a 96 × 96-texel region from disjoint halves of the photos: `albedo` times each
// half's own noise, a few paths per pixel (3 % of the texels take a firefly of 8× the mean).
std::pair<Image, Image> NoisyHalves(const std::function<double(int, int)>& albedo, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> gauss(0.0, 0.1);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Image h[2] = {Image(96, 96, 3), Image(96, 96, 3)};
  for (Image& m : h) {
    for (int y = 0; y < 96; ++y) {
      for (int x = 0; x < 96; ++x) {
        const double noise = 1 + gauss(rng) + (u(rng) < 0.03 ? 8.0 : 0.0);
        for (int c = 0; c < 3; ++c) m.at(x, y, c) = float(albedo(x, y) * noise);
      }
    }
  }
  return {h[0], h[1]};
}

std::vector<int> AllTexels(int n) {
  std::vector<int> all(n);
  for (int i = 0; i < n; ++i) all[i] = i;
  return all;
}

TEST(SharedTexelDetail, HeavyTailedNoiseIsNotTakenForTextureButATextureIs) {
  const std::vector<int> both = AllTexels(96 * 96);
  int variation_over_bar = 0, significant = 0, textures_found = 0;
  for (unsigned seed = 1; seed <= 30; ++seed) {
    const auto [a, b] = NoisyHalves([](int, int) { return 0.5; }, seed);
    const TexelDetail d = SharedTexelDetail(a, b, both);
    ASSERT_TRUE(std::isfinite(d.variation) && std::isfinite(d.z));
    variation_over_bar += d.variation > 0.1;
    significant += d.variation > 0.1 && d.z > 3;
    // A checker of 3-texel cells, ±40 % (a relative standard deviation of 0.4), under the same
    // noise.
    const auto [ta, tb] = NoisyHalves(
        [](int x, int y) { return 0.5 * ((x / 3 + y / 3) % 2 ? 1.4 : 0.6); }, 100 + seed);
    const TexelDetail t = SharedTexelDetail(ta, tb, both);
    textures_found += t.variation > 0.1 && t.z > 3;
    EXPECT_NEAR(t.variation, 0.4, 0.1) << seed;
  }
  // The noise alone reads a variation over the 10 % bar in some draws (so that the bar alone
  // would give the region a map), never significantly; the texture is found in every draw.
  EXPECT_GE(variation_over_bar, 3);
  EXPECT_EQ(significant, 0);
  EXPECT_EQ(textures_found, 30);
}

TEST(SharedTexelDetail, IsNaNOnFewTexelsOrADarkChannel) {
  const auto [a, b] = NoisyHalves([](int, int) { return 0.5; }, 7);
  EXPECT_TRUE(std::isnan(SharedTexelDetail(a, b, AllTexels(63)).variation));
  Image dark[2] = {a, b};
  for (Image& m : dark) {
    for (size_t i = 2; i < m.pixels.size(); i += 3) m.pixels[i] = 0;
  }
  EXPECT_TRUE(std::isnan(SharedTexelDetail(dark[0], dark[1], AllTexels(96 * 96)).z));
}

}  // namespace
}  // namespace igi::solver
