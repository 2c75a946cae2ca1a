#include "tools/common/image.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "tests/temp_dir.h"
#include "tools/common/error.h"

namespace igi {
namespace {

class ImageTest : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = test::UniqueTempDir("igi_image_test"); }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  static Image Gradient(int w, int h, int c) {
    Image im(w, h, c);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        for (int k = 0; k < c; ++k) im.at(x, y, k) = float(x + 2 * y + k) / float(w + 2 * h + c);
    return im;
  }
  std::filesystem::path dir_;
};

TEST_F(ImageTest, ExrFloatRoundTripIsExactAndKeepsMetadata) {
  Image im = Gradient(17, 9, 3);
  im.at(3, 4, 1) = 1234.5f;  // radiance is not limited to [0, 1]
  im.metadata["igi:camera"] = std::string("cam0");
  im.metadata["ExposureTime"] = 0.004;
  im.metadata["igi:frame"] = int64_t(7);
  WriteImage(dir_ / "a.exr", im);
  Image back = ReadImage(dir_ / "a.exr");
  ASSERT_EQ(back.width, 17);
  ASSERT_EQ(back.height, 9);
  ASSERT_EQ(back.channels, 3);
  EXPECT_EQ(back.pixels, im.pixels);
  EXPECT_EQ(std::get<std::string>(back.metadata.at("igi:camera")), "cam0");
  EXPECT_NEAR(std::get<double>(back.metadata.at("ExposureTime")), 0.004, 1e-9);
  EXPECT_EQ(std::get<int64_t>(back.metadata.at("igi:frame")), 7);
}

TEST_F(ImageTest, ExposureTimeSurvivesTiffExif) {
  // igi-calib reads exposure times from EXIF: a TIFF's ExposureTime must come back as 1/250.
  Image im = Gradient(4, 4, 3);
  im.metadata["ExposureTime"] = 0.004;
  WriteImage(dir_ / "e.tif", im);
  const ImageInfo info = ReadImageInfo(dir_ / "e.tif");
  ASSERT_TRUE(info.metadata.count("ExposureTime"));
  EXPECT_NEAR(std::get<double>(info.metadata.at("ExposureTime")), 0.004, 1e-7);
}

TEST_F(ImageTest, HalfExrRoundTripWithinHalfPrecision) {
  Image im = Gradient(8, 8, 3);
  WriteImageOptions half;
  half.type = PixelType::kHalf;
  half.compression = "piz";
  WriteImage(dir_ / "h.exr", im, half);
  EXPECT_EQ(ReadImageInfo(dir_ / "h.exr").type, PixelType::kHalf);
  Image back = ReadImage(dir_ / "h.exr");
  for (size_t i = 0; i < im.pixels.size(); ++i) EXPECT_NEAR(back.pixels[i], im.pixels[i], 1e-3);
}

TEST_F(ImageTest, IntegerFormatsQuantiseToTheirLevels) {
  Image im = Gradient(32, 16, 3);
  for (auto [name, levels] : {std::pair{"a.png", 255.0}, {"a.tif", 65535.0}}) {
    WriteImage(dir_ / name, im);
    Image back = ReadImage(dir_ / name);
    for (size_t i = 0; i < im.pixels.size(); ++i) {
      EXPECT_NEAR(back.pixels[i], std::round(im.pixels[i] * levels) / levels, 1e-6) << name;
    }
  }
  WriteImageOptions sixteen;
  sixteen.type = PixelType::kUInt16;
  WriteImage(dir_ / "b.png", im, sixteen);
  EXPECT_EQ(ReadImageInfo(dir_ / "b.png").type, PixelType::kUInt16);
  WriteImage(dir_ / "a.jpg", im);
  Image jpg = ReadImage(dir_ / "a.jpg");
  double err = 0;
  for (size_t i = 0; i < im.pixels.size(); ++i) err += std::abs(jpg.pixels[i] - im.pixels[i]);
  EXPECT_LT(err / im.pixels.size(), 0.02);  // lossy, but close at quality 95
}

TEST_F(ImageTest, ChannelSelectionExpandsGrey) {
  Image grey = Gradient(4, 4, 1);
  WriteImage(dir_ / "g.exr", grey);
  Image rgb = ReadImage(dir_ / "g.exr", 3);
  ASSERT_EQ(rgb.channels, 3);
  EXPECT_EQ(rgb.at(2, 1, 2), grey.at(2, 1, 0));
}

// Band by band (ImageRowWriter / ImageRowReader, for images too large to hold whole): written in
// bands of 4 rows (the last one short), the file equals a whole-image write of the same pixels
// (EXR float: exactly; 16-bit PNG: the same levels), and any band read back equals those rows.
TEST_F(ImageTest, RowBandsWriteAndReadAsWholeImages) {
  const Image im = Gradient(13, 11, 3);
  for (const char* name : {"rows.exr", "rows.png"}) {
    WriteImageOptions wo;
    if (std::string(name) == "rows.png") wo.type = PixelType::kUInt16;
    ImageRowWriter writer(dir_ / name, im.width, im.height, im.channels, {}, wo);
    const size_t row = size_t(im.width) * im.channels;
    for (int y0 = 0; y0 < im.height; y0 += 4) {
      const int y1 = std::min(im.height, y0 + 4);
      writer.WriteRows(y0, y1, im.pixels.data() + y0 * row);
    }
    writer.Commit();
    WriteImage(dir_ / (std::string("whole_") + name), im, wo);
    const Image a = ReadImage(dir_ / name), b = ReadImage(dir_ / (std::string("whole_") + name));
    ASSERT_EQ(a.width, im.width);
    ASSERT_EQ(a.height, im.height);
    EXPECT_EQ(a.pixels, b.pixels) << name;
    ImageRowReader reader(dir_ / name);
    EXPECT_EQ(reader.info().width, im.width);
    std::vector<float> band(3 * row);
    reader.ReadRows(5, 8, band.data());
    for (size_t k = 0; k < band.size(); ++k) EXPECT_EQ(band[k], a.pixels[5 * row + k]) << name;
  }
}

// A writer never committed (an error part way) leaves nothing behind: no file, no temporary.
TEST_F(ImageTest, UncommittedRowWriterLeavesNoFile) {
  const Image im = Gradient(8, 6, 3);
  {
    ImageRowWriter writer(dir_ / "partial.exr", im.width, im.height, im.channels);
    writer.WriteRows(0, 2, im.pixels.data());
  }
  EXPECT_TRUE(std::filesystem::is_empty(dir_));
}

TEST_F(ImageTest, UnreadableFileIsInputErrorNamingTheFile) {
  std::ofstream(dir_ / "bad.exr") << "not an exr";
  try {
    ReadImage(dir_ / "bad.exr");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.exr"), std::string::npos);
  }
  EXPECT_THROW(ReadImageInfo(dir_ / "missing.exr"), InputError);
}

TEST_F(ImageTest, FailedWriteLeavesNoFileBehind) {
  Image empty;
  EXPECT_THROW(WriteImage(dir_ / "e.exr", empty), Error);
  EXPECT_THROW(WriteImage(dir_ / "x.unknownext", Gradient(2, 2, 3)), Error);
  EXPECT_TRUE(std::filesystem::is_empty(dir_));
}

TEST(ReductionFactor, IsTheSmallestThatBringsThePhotoWithinTheLimit) {
  EXPECT_EQ(ReductionFactor(5656, 4242, 0.5), 7);  // 808 x 606
  EXPECT_EQ(ReductionFactor(160, 120, 0.5), 1);
  EXPECT_EQ(ReductionFactor(320, 240, 0.02), 2);
  EXPECT_EQ(ReductionFactor(6000, 4000, 0), 1);
  for (int w : {101, 640, 1999, 4032, 6000}) {
    for (double mp : {0.01, 0.05, 0.3, 1.0}) {
      const int h = w * 2 / 3, f = ReductionFactor(w, h, mp);
      EXPECT_LE(double(w / f) * (h / f), mp * 1e6) << w << " " << mp;
      if (f > 1) {
        EXPECT_GT(double(w / (f - 1)) * (h / (f - 1)), mp * 1e6) << w << " " << mp;
      }
    }
  }
}

TEST(BlockMeans, AreTheMeansOfWholeBlocks) {
  Image img(7, 5, 2);
  for (int y = 0; y < 5; ++y) {
    for (int x = 0; x < 7; ++x) {
      img.at(x, y, 0) = float(x + 10 * y);
      img.at(x, y, 1) = 1.0f;
    }
  }
  const Image out = BlockMeans(img, 3);
  ASSERT_EQ(out.width, 2);  // the seventh column and the last two rows fill no block
  ASSERT_EQ(out.height, 1);
  ASSERT_EQ(out.channels, 2);
  EXPECT_FLOAT_EQ(out.at(0, 0, 0), 1.0f + 10.0f);  // columns 0-2, rows 0-2
  EXPECT_FLOAT_EQ(out.at(1, 0, 0), 4.0f + 10.0f);  // columns 3-5
  EXPECT_FLOAT_EQ(out.at(1, 0, 1), 1.0f);
  EXPECT_EQ(BlockMeans(img, 1).pixels, img.pixels);
}

}  // namespace
}  // namespace igi
