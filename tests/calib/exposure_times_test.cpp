#include "calib/exposure_times.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "tools/common/error.h"

namespace igi::calib {
namespace {

std::string ErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(ExposureTimes, ParsesDecimalsAndFractions) {
  EXPECT_DOUBLE_EQ(ParseExposureTime("0.004", "x", "k"), 0.004);
  EXPECT_DOUBLE_EQ(ParseExposureTime(" 1/250 ", "x", "k"), 0.004);
  EXPECT_DOUBLE_EQ(ParseExposureTime("32", "x", "k"), 32.0);
  const auto list = ParseExposureList("1/1024, 0.5,2");
  ASSERT_EQ(list.size(), 3u);
  EXPECT_DOUBLE_EQ(list[0], 1.0 / 1024);
}

TEST(ExposureTimes, RejectsBadValuesWithTheRule) {
  EXPECT_NE(ErrorOf([] { ParseExposureTime("0", "f.txt", "line 3"); }).find("f.txt: line 3: 0:"),
            std::string::npos);
  EXPECT_NE(ErrorOf([] { ParseExposureTime("-1/2", "f", "k"); }).find("must be > 0"),
            std::string::npos);
  EXPECT_NE(ErrorOf([] { ParseExposureTime("abc", "f", "k"); }).find("exposure time"),
            std::string::npos);
  EXPECT_THROW(ParseExposureTime("1/0", "f", "k"), InputError);
}

TEST(ExposureTimes, ReadsMemorialShutterTimes) {
  const auto times =
      ReadExposureFile(std::string(IGI_SHARED_DATA_DIR) + "/real/memorial/shutter_times.txt");
  ASSERT_EQ(times.size(), 16u);
  EXPECT_DOUBLE_EQ(times.front(), 32.0);
  EXPECT_DOUBLE_EQ(times.back(), 1.0 / 1024);
}

TEST(ExposureTimes, FileCommentsAndLineNumbers) {
  const auto path = std::filesystem::temp_directory_path() / "igi_exposures_test.txt";
  std::ofstream(path) << "# bracket\n1/100  # first\n\n0.1\nfast\n";
  const std::string error = ErrorOf([&] { ReadExposureFile(path); });
  EXPECT_NE(error.find("line 5: fast"), std::string::npos) << error;
  std::ofstream(path) << "# bracket\n1/100  # first\n\n0.1\n";
  EXPECT_EQ(ReadExposureFile(path).size(), 2u);
  std::filesystem::remove(path);
}

TEST(ExposureTimes, ValidateNamesDuplicatesAndCounts) {
  const std::vector<std::string> names = {"a.png", "b.png", "c.png"};
  EXPECT_NO_THROW(ValidateExposures({1, 2, 4}, names, "--exposures"));
  EXPECT_NE(ErrorOf([&] {
              ValidateExposures({1, 2, 2}, names, "x");
            }).find("c.png: exposure: 2 s: duplicate exposure time (same as b.png)"),
            std::string::npos);
  EXPECT_NE(ErrorOf([&] {
              ValidateExposures({1, 2}, names, "times.txt");
            }).find("must give one exposure time per image (3 images)"),
            std::string::npos);
}

TEST(ExposureTimes, FromMetadata) {
  ImageMetadata metadata;
  metadata["ExposureTime"] = 0.01;
  EXPECT_DOUBLE_EQ(ExposureFromMetadata(metadata, "a.jpg"), 0.01);
  EXPECT_NE(ErrorOf([] { ExposureFromMetadata({}, "b.jpg"); }).find("b.jpg: ExposureTime: missing"),
            std::string::npos);
}

}  // namespace
}  // namespace igi::calib
