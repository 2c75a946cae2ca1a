#include "capture/frame_writer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "tools/common/image.h"

namespace igi::capture {
namespace {

TEST(WidenTo16Bits, IsExactlyInvertibleAndMapsFullScaleTo65535) {
  for (int bits : {8, 10, 12, 14, 16}) {
    SCOPED_TRACE(bits);
    const int max_level = (1 << bits) - 1;
    EXPECT_EQ(WidenTo16Bits(uint16_t(max_level), bits), 65535);
    EXPECT_EQ(WidenTo16Bits(0, bits), 0);
    for (int level = 0; level <= max_level; level += std::max(1, max_level / 997)) {
      EXPECT_EQ(WidenTo16Bits(uint16_t(level), bits) >> (16 - bits), level);
    }
  }
  EXPECT_EQ(WidenTo16Bits(200, 8), 200 * 257);
}

Frame TestFrame(const PixelFormatInfo& format, int width, int height) {
  Frame frame;
  frame.width = width;
  frame.height = height;
  frame.format = format;
  const int max_level = (1 << format.significant_bits) - 1;
  std::vector<uint16_t> levels;
  for (int i = 0; i < width * height * format.channels; ++i) {
    levels.push_back(uint16_t((i * 7919) % (max_level + 1)));
  }
  frame.SetLevels(levels);
  EXPECT_EQ(frame.Levels(), levels);
  return frame;
}

// Lossless: every level comes back exactly, through OpenImageIO's reader.
void ExpectRoundTrip(const Frame& frame, const std::string& extension) {
  const auto path = std::filesystem::temp_directory_path() / ("igi_frame_writer" + extension);
  WriteFrame(path, frame);
  const ImageInfo info = ReadImageInfo(path);
  EXPECT_EQ(info.bits_per_sample, 16);
  const Image image = ReadImage(path);
  ASSERT_EQ(image.width, frame.width);
  ASSERT_EQ(image.height, frame.height);
  ASSERT_EQ(image.channels, frame.format.channels);
  const int shift = 16 - frame.format.significant_bits;
  for (size_t i = 0; i < frame.sample_count(); ++i) {
    const long stored = std::lround(image.pixels[i] * 65535.0);
    ASSERT_EQ(stored, WidenTo16Bits(frame.level(i), frame.format.significant_bits))
        << "sample " << i;
    ASSERT_EQ(stored >> shift, frame.level(i)) << "sample " << i;
  }
  std::filesystem::remove(path);
}

TEST(WriteFrame, PngAndTiffAreLosslessForEveryDepth) {
  for (const char* name : {"Mono8", "Mono10", "Mono12", "Mono14", "Mono16", "RGB8", "BayerRG12"}) {
    SCOPED_TRACE(name);
    const Frame frame = TestFrame(*FindPixelFormat(name), 37, 11);
    ExpectRoundTrip(frame, ".png");
    ExpectRoundTrip(frame, ".tif");
  }
}

TEST(PixelFormat, KnowsStorableFormatsOnly) {
  EXPECT_EQ(FindPixelFormat("Mono12")->significant_bits, 12);
  EXPECT_EQ(FindPixelFormat("RGB8")->channels, 3);
  EXPECT_TRUE(FindPixelFormat("BayerGB16")->bayer);
  EXPECT_FALSE(FindPixelFormat("Mono12Packed"));
  EXPECT_FALSE(FindPixelFormat("YUV422_8"));
}

}  // namespace
}  // namespace igi::capture
