#include "capture/bracket_plan.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "tools/common/error.h"
#include "tools/common/json.h"

namespace igi::capture {
namespace {

TEST(ParseExposureList, AcceptsCommasAndSpaces) {
  EXPECT_EQ(ParseExposureList("1000,4000, 16000 64000.5"),
            (std::vector<double>{1000, 4000, 16000, 64000.5}));
}

TEST(ParseExposureList, RejectsBadValuesNamingThem) {
  for (const char* bad : {"", "1000,abc", "0", "-5", "1000,1000", "inf"}) {
    SCOPED_TRACE(bad);
    EXPECT_THROW(ParseExposureList(bad), InputError);
  }
  try {
    ParseExposureList("1000,abc");
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--exposures-us: abc"), std::string::npos) << e.what();
  }
}

TEST(SlotFileName, NamesBracketExposureAndFrame) {
  BracketPlan plan;
  plan.exposures_us = {125.4, 1e6};
  EXPECT_EQ(SlotFileName(plan, {0, 2}), "frames/b00_e000000125us_f002.png");
  plan.file_format = PlanFileFormat::kTiff;
  EXPECT_EQ(SlotFileName(plan, {1, 0}), "frames/b01_e001000000us_f000.tif");
}

TEST(PlanFileFormat, NamesRoundTripAndOthersAreRejected) {
  for (PlanFileFormat f : {PlanFileFormat::kPng, PlanFileFormat::kTiff}) {
    EXPECT_EQ(PlanFileFormatFromName(PlanFileFormatName(f)), f);
  }
  EXPECT_EQ(PlanFileFormatName(PlanFileFormat::kTiff), "tiff");
  EXPECT_FALSE(PlanFileFormatFromName("tif"));
  EXPECT_FALSE(PlanFileFormatFromName("PNG"));
}

TEST(BracketPlan, RoundTripsThroughPlanJson) {
  BracketPlan plan;
  plan.camera = "Aravis-Fake-GV01";
  plan.exposures_us = {1000, 4000};
  plan.frames = 3;
  plan.settle_frames = 2;
  plan.pixel_format = "Mono16";
  plan.gain = 1.5;
  plan.file_format = PlanFileFormat::kTiff;
  plan.auto_metered = true;
  const auto path = std::filesystem::temp_directory_path() / "igi_plan_roundtrip.json";
  WritePlan(path, plan);
  const BracketPlan read = ReadPlan(path);
  EXPECT_EQ(PlanToJson(read), PlanToJson(plan));
  EXPECT_EQ(ReadJsonFile(path)["format"], "igi-capture-plan");
  EXPECT_EQ(ReadJsonFile(path)["version"], 1);
  EXPECT_EQ(ReadJsonFile(path)["file_format"], "tiff");
  std::filesystem::remove(path);
}

TEST(BracketPlan, ReadsAPlanWithoutFormatButNotOneOfAnotherFormat) {
  const auto path = std::filesystem::temp_directory_path() / "igi_plan_format.json";
  const std::string body = R"("camera": "x", "exposures_us": [1000], "frames": 1,
      "settle_frames": 0, "pixel_format": "Mono8", "gain": 0, "file_format": "png",
      "auto_metered": false})";
  std::ofstream(path) << "{" << body;
  EXPECT_EQ(ReadPlan(path).camera, "x");
  std::ofstream(path) << R"({"format": "igi-response", "version": 1, )" << body;
  EXPECT_THROW(ReadPlan(path), InputError);
  std::ofstream(path) << R"({"format": "igi-capture-plan", "version": 2, )" << body;
  EXPECT_THROW(ReadPlan(path), InputError);
  std::filesystem::remove(path);
}

TEST(BracketPlan, ReadRejectsABadPlan) {
  const auto path = std::filesystem::temp_directory_path() / "igi_plan_bad.json";
  {
    std::ofstream(path) << R"({"camera": "x", "exposures_us": [1000, -1], "frames": 0,
      "settle_frames": 1, "pixel_format": "Mono8", "gain": 0, "file_format": "jpeg",
      "auto_metered": false})";
  }
  try {
    ReadPlan(path);
    FAIL() << "accepted a bad plan";
  } catch (const InputError& e) {
    EXPECT_GE(e.problems().size(), 3u) << e.what();  // exposure, frames, file_format
  }
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace igi::capture
