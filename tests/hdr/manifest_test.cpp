#include "hdr/manifest.h"

#include <gtest/gtest.h>

#include "tests/temp_dir.h"

#include <filesystem>
#include <fstream>

#include "tools/common/error.h"

namespace igi::hdr {
namespace {

namespace fs = std::filesystem;

class ManifestTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::UniqueTempDir("igi_manifest_test");
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path Write(const std::string& text) {
    std::ofstream(dir_ / "manifest.jsonl") << text;
    return dir_ / "manifest.jsonl";
  }
  fs::path dir_;
};

std::string Frame(const std::string& file, const std::string& camera, double us, double gain,
                  const std::string& extra = "") {
  return R"({"file":")" + file + R"(","camera":")" + camera + R"(","exposure_us":)" +
         std::to_string(us) + R"(,"gain":)" + std::to_string(gain) +
         R"(,"pixel_format":"Mono16","timestamp":"2026-01-01T00:00:00Z")" + extra + "}\n";
}

TEST_F(ManifestTest, GroupsByCameraGainAndBracketKey) {
  const fs::path path =
      Write(Frame("frames/a0.png", "cam A", 1000, 0) + Frame("frames/b0.png", "camB", 1000, 0) +
            Frame("frames/a1.png", "cam A", 4000, 0, R"(,"extra_key":1)") +
            Frame("frames/a2.png", "cam A", 1000, 6) + "\n" +
            Frame("frames/a3.png", "camB", 500, 0, R"(,"bracket":2)"));
  const auto brackets = ReadManifest(path);
  ASSERT_EQ(brackets.size(), 4u);
  EXPECT_EQ(brackets[0].camera, "cam A");
  ASSERT_EQ(brackets[0].frames.size(), 2u);
  EXPECT_EQ(brackets[0].frames[0].file, dir_ / "frames/a0.png");
  EXPECT_DOUBLE_EQ(brackets[0].frames[1].exposure_s, 0.004);
  EXPECT_EQ(brackets[0].frames[1].line, 3);
  EXPECT_EQ(brackets[0].label, "cam_A_g0");
  EXPECT_EQ(brackets[1].label, "camB");
  EXPECT_EQ(brackets[2].label, "cam_A_g6");
  EXPECT_EQ(brackets[3].bracket, "2");
  EXPECT_EQ(brackets[3].label, "camB_2");
}

TEST_F(ManifestTest, ANullGainOrTimestampIsUnknownNotMissing) {
  // As igi-capture imports raw files that record no ISO and no time.
  const std::string line0 =
      R"({"file":"r0.dng","camera":"raw","exposure_us":1000,"gain":null,"pixel_format":"raw",)"
      R"("timestamp":null})";
  const std::string line1 =
      R"({"file":"r1.dng","camera":"raw","exposure_us":4000,"gain":null,"pixel_format":"raw",)"
      R"("timestamp":null})";
  const auto brackets = ReadManifest(Write(line0 + "\n" + line1 + "\n"));
  ASSERT_EQ(brackets.size(), 1u);
  ASSERT_EQ(brackets[0].frames.size(), 2u);
  EXPECT_EQ(brackets[0].gain, 0.0);
  // The keys themselves stay required.
  EXPECT_THROW(ReadManifest(Write(R"({"file":"r0.dng","camera":"raw","exposure_us":1000,)"
                                  R"("pixel_format":"raw","timestamp":null})"
                                  "\n")),
               InputError);
}

TEST_F(ManifestTest, ALastLineCutShortIsSkippedButABadLineIsNot) {
  const std::string whole = Frame("a0.png", "c", 1000, 0) + Frame("a1.png", "c", 4000, 0);
  const auto brackets = ReadManifest(Write(whole + R"({"file":"a2.png","camera":"c","expo)"));
  ASSERT_EQ(brackets.size(), 1u);
  EXPECT_EQ(brackets[0].frames.size(), 2u);
  EXPECT_THROW(ReadManifest(Write(whole + R"({"file":"a2.png","camera":"c","expo)" + "\n")),
               InputError);
}

TEST_F(ManifestTest, ReportsEveryBadLine) {
  const fs::path path =
      Write(Frame("a.png", "c", 1000, 0) + "not json\n" + Frame("b.png", "c", -5, 0) +
            R"({"file":"c.png","camera":"c","exposure_us":10,"gain":0,"pixel_format":"x"})" + "\n");
  try {
    ReadManifest(path);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    ASSERT_EQ(e.problems().size(), 3u) << e.what();
    EXPECT_NE(e.problems()[0].find("line 2"), std::string::npos) << e.problems()[0];
    EXPECT_NE(e.problems()[1].find("line 3: exposure_us"), std::string::npos) << e.problems()[1];
    EXPECT_NE(e.problems()[2].find("line 4: timestamp"), std::string::npos) << e.problems()[2];
  }
}

TEST_F(ManifestTest, EmptyManifestIsAnError) {
  EXPECT_THROW(ReadManifest(Write("\n")), InputError);
  EXPECT_THROW(ReadManifest(dir_ / "missing.jsonl"), InputError);
}

}  // namespace
}  // namespace igi::hdr
