#include "calib/bracket.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "tools/common/error.h"

namespace igi::calib {
namespace {

namespace fs = std::filesystem;

std::string Memorial(int i) {
  return std::string(IGI_SHARED_DATA_DIR) + "/real/memorial/memorial00" + std::to_string(i) +
         ".png";
}

std::string ErrorOf(const std::vector<fs::path>& paths, const ExposureSource& source) {
  try {
    LoadBracket(paths, source);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(Bracket, LoadsEightBitImagesWithTimes) {
  ExposureSource source;
  source.list = "1,1/2";
  const Bracket b = LoadBracket({Memorial(66), Memorial(67)}, source);
  EXPECT_EQ(b.bits_per_sample, 8);
  EXPECT_EQ(b.width(), 512);
  EXPECT_EQ(b.height(), 768);
  EXPECT_EQ(b.levels(), 256);
  EXPECT_DOUBLE_EQ(b.exposures_s[1], 0.5);
}

TEST(Bracket, SixteenBitAndSizeMismatch) {
  const fs::path dir = fs::temp_directory_path() / "igi_bracket_test";
  fs::create_directories(dir);
  Image a(8, 6, 3, 0.25f), b(8, 6, 3, 0.5f), small(4, 6, 3, 0.5f);
  WriteImageOptions u16;
  u16.type = PixelType::kUInt16;
  WriteImage(dir / "a.png", a, u16);
  WriteImage(dir / "b.png", b, u16);
  WriteImage(dir / "small.png", small, u16);
  ExposureSource source;
  source.list = "0.1,0.2";
  const Bracket loaded = LoadBracket({dir / "a.png", dir / "b.png"}, source);
  EXPECT_EQ(loaded.bits_per_sample, 16);
  EXPECT_NEAR(loaded.images[1].pixels[0], 0.5f, 1e-4f);
  const std::string error = ErrorOf({dir / "a.png", dir / "small.png"}, source);
  EXPECT_NE(error.find("small.png: size: 4x6x3: every image of a bracket must have the size of"),
            std::string::npos)
      << error;
  fs::remove_all(dir);
}

TEST(Bracket, CorruptFileAndMissingTimesNameTheImage) {
  const fs::path dir = fs::temp_directory_path() / "igi_bracket_corrupt";
  fs::create_directories(dir);
  std::ofstream(dir / "bad.png") << "not a png";
  ExposureSource source;
  source.list = "1,2";
  const std::string corrupt = ErrorOf({Memorial(66), dir / "bad.png"}, source);
  EXPECT_NE(corrupt.find("bad.png"), std::string::npos) << corrupt;
  const std::string no_exif = ErrorOf({Memorial(66), Memorial(67)}, {});
  EXPECT_NE(no_exif.find("memorial0066.png: ExposureTime: missing"), std::string::npos) << no_exif;
  source.list = "1,1";
  const std::string duplicate = ErrorOf({Memorial(66), Memorial(67)}, source);
  EXPECT_NE(duplicate.find("duplicate exposure time"), std::string::npos) << duplicate;
  const std::string one = ErrorOf({Memorial(66)}, source);
  EXPECT_NE(one.find("at least 2 images"), std::string::npos) << one;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace igi::calib
