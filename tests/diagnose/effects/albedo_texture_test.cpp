// albedo_texture (solver/diagnose/effects/albedo_texture.cpp): its step changes the refit's albedo
// maps, not the document. TryLast offers maps wherever the albedo varies while the model lacks
// them for some region; PlanTrial gives the refit maps for the regions a texture test named, or
// for every region; DescribeKept names the regions a last-resort step's refit gave maps; Write
// leaves the document as it is. The texture test it runs first (texture_evidence.h) is tested in
// tests/diagnose/texture_evidence_test.cpp.
#include <gtest/gtest.h>

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "solver/diagnose/candidates.h"
#include "solver/diagnose/effect.h"
#include "solver/diagnose/effects/effects.h"
#include "tests/diagnose/one_light_record.h"

namespace igi::diagnose {
namespace {

// A diagnosis's model with regions floor, wall and box, no photos, the albedo maps `maps`.
struct Model {
  recon::Scene scene;
  Json declared = {{"materials",
                    {{"floor", {{"brdf", "lambert"}}},
                     {"wall", {{"brdf", "lambert"}}},
                     {"box", {{"brdf", "lambert"}}}}}};
  PhotoSet photos;
  std::vector<Image> sims;
  std::vector<PixelRecord> records;
  solver::PixelHoldout holdout;
  DiagnoseOptions options;
  MapMode maps;

  explicit Model(MapMode m) : maps(std::move(m)) {
    for (const char* name : {"floor", "wall", "box"}) {
      recon::Material mat;
      mat.name = name;
      scene.materials.push_back(mat);
    }
  }
  DiagnosisModel View() const {
    return {scene, scene, declared, photos, sims, records, holdout, options, maps, true, 0.05, {}};
  }
};

// While the model's maps are not every region's ("none", or only some regions'), TryLast offers
// maps wherever the solver finds the albedo varies: a valid candidate of one albedo per texel
// (num_params −1) that names no regions, so that its trial maps every region. With maps for
// every region already ("auto" for all), it offers nothing.
TEST(AlbedoTextureTest, TryLastOnlyWhileTheMapsAreNotEveryRegions) {
  for (const MapMode& maps : {MapMode{}, MapMode{solver::AlbedoMaps::kAuto, {"floor"}}}) {
    const Model m(maps);
    const std::unique_ptr<Effect> e = MakeAlbedoTexture();
    const std::optional<CandidateResult> c = e->TryLast(m.View());
    ASSERT_TRUE(c.has_value()) << solver::AlbedoMapsName(maps.maps) << " " << maps.only.size();
    EXPECT_EQ(c->effect, "albedo_texture");
    EXPECT_TRUE(c->valid);
    EXPECT_EQ(c->num_params, -1);
    EXPECT_FALSE(c->params.contains("regions"));
  }
  const Model full(MapMode{solver::AlbedoMaps::kAuto, {}});
  EXPECT_FALSE(MakeAlbedoTexture()->TryLast(full.View()).has_value());
}

// The trial's maps are "auto" for the regions the candidate's params name ("regions", the texture
// test's), and only those; without "regions" (TryLast's candidate) for every region. The document
// is the declared one, the photos' valid pixels unchanged.
TEST(AlbedoTextureTest, PlanTrialMapsTheNamedRegionsOrEvery) {
  const Model m(MapMode{});
  const std::unique_ptr<Effect> e = MakeAlbedoTexture();
  CandidateResult named;
  named.effect = "albedo_texture";
  named.params = {{"regions", {"floor", "box"}}};
  const TrialPlan some = e->PlanTrial(&named, m.View());
  EXPECT_EQ(some.maps.maps, solver::AlbedoMaps::kAuto);
  EXPECT_EQ(some.maps.only, (std::vector<std::string>{"floor", "box"}));
  EXPECT_FALSE(some.maps.Full());
  EXPECT_EQ(some.document, m.declared);
  EXPECT_FALSE(some.photos.has_value());
  CandidateResult last;
  last.effect = "albedo_texture";
  const TrialPlan every = e->PlanTrial(&last, m.View());
  EXPECT_EQ(every.maps.maps, solver::AlbedoMaps::kAuto);
  EXPECT_TRUE(every.maps.only.empty());
  EXPECT_TRUE(every.maps.Full());
  EXPECT_EQ(every.document, m.declared);
  EXPECT_FALSE(every.photos.has_value());
}

// A last-resort step (no "regions") is described, once kept, by the regions its refit gave an
// albedo map (Material::rho_d_map set), in the refit's order; a step that named its regions is
// left as it was.
TEST(AlbedoTextureTest, DescribeKeptNamesTheRegionsTheRefitGaveMaps) {
  recon::Scene refit;
  for (const char* name : {"floor", "wall", "box"}) {
    recon::Material mat;
    mat.name = name;
    mat.rho_d = Eigen::Vector3d::Constant(0.5);
    if (std::string(name) != "wall") {
      mat.rho_d_map = std::filesystem::path("/out/refit") / (std::string(name) + "_albedo.exr");
    }
    refit.materials.push_back(mat);
  }
  const std::unique_ptr<Effect> e = MakeAlbedoTexture();
  CandidateResult last;
  last.effect = "albedo_texture";
  e->DescribeKept(&last, refit);
  const Json regions = Json::array({"floor", "box"});
  EXPECT_EQ(last.params, Json({{"regions", regions}}));
  EXPECT_EQ(last.where["regions"], regions);
  EXPECT_EQ(last.where["frame"], "position on the surfaces");
  EXPECT_NE(last.evidence.find(regions.dump()), std::string::npos) << last.evidence;

  CandidateResult named;
  named.effect = "albedo_texture";
  named.params = {{"regions", {"wall"}}};
  named.evidence = "the texture test";
  e->DescribeKept(&named, refit);
  EXPECT_EQ(named.params, Json({{"regions", Json::array({"wall"})}}));
  EXPECT_EQ(named.evidence, "the texture test");
}

// Write leaves the document as it is: the maps are the refit's (PlanTrial), which the solver
// writes into its own scene.
TEST(AlbedoTextureTest, WriteLeavesTheDocumentUnchanged) {
  CandidateResult c;
  c.effect = "albedo_texture";
  c.valid = true;
  c.params = {{"regions", {"floor"}}};
  const Json declared = {{"materials", {{"floor", {{"brdf", "lambert"}}}}},
                         {"photos", {{{"file", "/capture/cam0_L0.exr"}}}}};
  Json doc = declared;
  test::WriteCandidate(c, &doc);
  EXPECT_EQ(doc, declared);
}

}  // namespace
}  // namespace igi::diagnose
