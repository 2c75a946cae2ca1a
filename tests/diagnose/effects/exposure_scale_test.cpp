// exposure_scale (solver/diagnose/effects/exposure_scale.cpp): a photo's own scale is found
// relative to its lighting's photos, and a scale common to one lighting's photos is left to the
// lights' effects. And its Write: each photo's exposure_scale is multiplied by its fitted scale.
#include <gtest/gtest.h>

#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "solver/diagnose/candidates.h"
#include "solver/diagnose/effects/effects.h"
#include "solver/render/sampling.h"
#include "tests/diagnose/one_light_record.h"
#include "tests/diagnose/room_records.h"

namespace igi::diagnose {
namespace {

using Eigen::Vector3d;
using Eigen::Vector3f;
using namespace test::room;

// Photos under two lightings (with the materials solved, the albedos shared by both): 4 photos
// under the lamp, 4 under lamp2, on the floor and the wall. The photos under lamp2 record 0.6x the
// model (lamp2 is dimmer than declared: a scale common to its lighting, another effect's), and
// photo `off` (under lamp2; -1: none) records a further `off_scale`.
CandidateResult ExposureWithTwoLightings(int off, double off_scale, bool solved = true) {
  const recon::Scene model = TwoLightingRoomModel();
  const Json declared = {
      {"lights", {{"lamp", {{"type", "point"}}}, {"lamp2", {{"type", "point"}}}}}};
  const std::vector<PixelRecord> records = TwoLightingRoomRecords(
      5, [&](int photo) { return (photo < 4 ? 1.0 : 0.6) * (photo == off ? off_scale : 1.0); });
  std::vector<std::string> excluded;
  for (const char* e : {"vignetting", "camera_response", "ambient_light"}) excluded.push_back(e);
  for (const char* l : {"lamp", "lamp2"}) {
    for (const char* e : {"light_emission_profile:", "light_intensity:", "light_source_extent:"}) {
      excluded.push_back(std::string(e) + l);
    }
  }
  for (const char* r : {"floor", "wall"}) {
    for (const char* e :
         {"specular_lobe_shape:", "fresnel:", "anisotropic_reflection:", "specular_reflection:"}) {
      excluded.push_back(std::string(e) + r);
    }
  }
  const std::vector<CandidateResult> cands =
      EvaluateCandidates(MakeEffects(), {model, declared, solved}, records, excluded);
  for (const CandidateResult& c : cands) {
    if (c.effect == "exposure_scale") return c;
  }
  ADD_FAILURE() << "no exposure_scale candidate among " << cands.size();
  return {};
}

// A scale common to one lighting's photos is not credited to per-photo scales (it is the
// lighting's lights': light_intensity, light_emission_profile): fitted free, the 8 photos'
// scales (0.6 under lamp2, relative to the median photo) explained nearly all the residual, and
// the suite's seed-107 emission-profile capture applied them in the profile's place.
TEST(ExposureScaleTest, ALightingsCommonScaleIsNotThePhotos) {
  const CandidateResult c = ExposureWithTwoLightings(-1, 1.0);
  if (c.valid) {
    std::printf("exposure_scale: predicted held-out gain %.4f, z %.1f, %s\n", c.Gain(), c.z,
                c.params.dump().c_str());
    EXPECT_LT(c.Gain(), 0.02);
    for (const auto& [file, v] : c.params["scale"].items()) {
      EXPECT_NEAR(v.get<double>(), 1.0, 0.01) << file;
    }
  } else {
    EXPECT_FALSE(c.note.empty());
  }
}

// One photo off within its lighting is still found, relative to its lighting's other photos.
TEST(ExposureScaleTest, OnePhotoOffWithinItsLightingIsFound) {
  const CandidateResult c = ExposureWithTwoLightings(5, 0.8);
  ASSERT_TRUE(c.valid) << c.note;
  std::printf("exposure_scale: predicted held-out gain %.4f, z %.1f, %s\n", c.Gain(), c.z,
              c.params.dump().c_str());
  EXPECT_EQ(c.num_params, 6);  // 8 photos less one reference per lighting
  EXPECT_GT(c.Gain(), 0.2);
  for (const auto& [file, v] : c.params["scale"].items()) {
    EXPECT_NEAR(v.get<double>(), file == "cam1_L1.exr" ? 0.8 : 1.0, 0.01) << file;
  }
}

// With the materials given the same holds: lamp2 0.6x as bright as declared is a scale of its
// lighting's photos, not of each photo (in the RADIANCE room rendered by Cycles with its lamp
// 1.3x as bright, free photo scales were named in light_intensity's place), and one photo off
// within its lighting is still found.
TEST(ExposureScaleTest, WithTheMaterialsGivenALightingsScaleIsStillItsLights) {
  const CandidateResult common = ExposureWithTwoLightings(-1, 1.0, false);
  if (common.valid) {
    EXPECT_LT(common.Gain(), 0.02);
    for (const auto& [file, v] : common.params["scale"].items()) {
      EXPECT_NEAR(v.get<double>(), 1.0, 0.01) << file;
    }
  }
  const CandidateResult off = ExposureWithTwoLightings(5, 0.8, false);
  ASSERT_TRUE(off.valid) << off.note;
  EXPECT_EQ(off.num_params, 6);
  EXPECT_GT(off.Gain(), 0.2);
  for (const auto& [file, v] : off.params["scale"].items()) {
    EXPECT_NEAR(v.get<double>(), file == "cam1_L1.exr" ? 0.8 : 1.0, 0.01) << file;
  }
}

// Write matches the params' scales to the document's photos by file name (the document's paths
// are absolute, the params' names bare): a declared exposure_scale is multiplied, an absent one
// (1) becomes the scale, and a photo without a scale in the params is left as it was.
TEST(ExposureScaleTest, WriteMultipliesEachPhotosScaleMatchedByFileName) {
  CandidateResult c;
  c.effect = "exposure_scale";
  c.params = {{"scale", {{"cam0_L0.exr", 0.75}, {"cam1_L0.exr", 1.25}, {"cam9_L0.exr", 3.0}}}};
  Json doc = {
      {"photos",
       {{{"file", "/capture/photos/cam0_L0.exr"}, {"camera", "cam0"}, {"lighting", "L0"}},
        {{"file", "/capture/photos/cam1_L0.exr"},
         {"camera", "cam1"},
         {"lighting", "L0"},
         {"exposure_scale", 2.0}},
        {{"file", "/capture/photos/cam2_L0.exr"}, {"camera", "cam2"}, {"lighting", "L0"}}}}};
  Json expected = doc;
  expected["photos"][0]["exposure_scale"] = 0.75;
  expected["photos"][1]["exposure_scale"] = 2.5;
  test::WriteCandidate(c, &doc);
  EXPECT_EQ(doc, expected) << doc.dump();
}

}  // namespace
}  // namespace igi::diagnose
