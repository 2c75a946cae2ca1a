// The band-by-band merge against the whole-image merge: the same values bit for bit (each pixel's
// merge reads only that pixel, and the files' levels convert to the same floats either way), on
// synthetic brackets written as 8-bit PNG and 16-bit TIFF and on the real Memorial bracket; the
// same MTB shifts from grey levels read band by band; buffers that do not grow with the height.
#include "hdr/merge_stream.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>

#include "calib/bracket.h"
#include "calib/response_recovery.h"
#include "hdr/align.h"
#include "hdr/merge.h"
#include "tests/calib/synthetic_bracket.h"
#include "tests/temp_dir.h"
#include "tools/common/error.h"

namespace igi::hdr {
namespace {

namespace fs = std::filesystem;

// The synthetic bracket's true response with `levels` levels (one curve for all channels).
calib::ResponseCurve TrueResponse(int levels) {
  calib::ResponseCurve curve;
  curve.levels = levels;
  curve.channels = {"Y"};
  std::vector<double> g(static_cast<size_t>(levels));
  for (int z = 0; z < levels; ++z) {
    g[size_t(z)] = testing::SyntheticLnExposure(std::max(double(z), 0.5) / (levels - 1));
  }
  curve.g.assign(1, g);
  return curve;
}

// Writes a synthetic bracket of `width` x `height` as 8-bit PNG or 16-bit TIFF files into `dir`.
std::vector<fs::path> WriteBracket(const fs::path& dir, int width, int height, int bits,
                                   std::vector<double>* exposures_s) {
  testing::SyntheticOptions o;
  o.width = width;
  o.height = height;
  o.bits = bits;
  const testing::SyntheticBracket s = testing::MakeSyntheticBracket(o);
  WriteImageOptions write;
  write.type = bits == 8 ? PixelType::kUInt8 : PixelType::kUInt16;
  std::vector<fs::path> paths;
  for (size_t j = 0; j < s.bracket.images.size(); ++j) {
    paths.push_back(dir / ("frame" + std::to_string(j) + (bits == 8 ? ".png" : ".tif")));
    WriteImage(paths.back(), s.bracket.images[j], write);
  }
  *exposures_s = s.bracket.exposures_s;
  return paths;
}

// The whole-image merge of the files, after ShiftImage when `shifts` are given.
MergeResult MergeWhole(const std::vector<fs::path>& paths, const std::vector<double>& exposures_s,
                       const std::vector<PixelShift>& shifts, const calib::ResponseCurve& response,
                       const MergeOptions& options) {
  std::vector<Image> images;
  for (size_t j = 0; j < paths.size(); ++j) {
    images.push_back(ReadImage(paths[j]));
    if (!shifts.empty()) images.back() = ShiftImage(images.back(), shifts[j]);
  }
  return MergeBracket(images, exposures_s, response, options);
}

// Streams the merge into `dir` and checks its outputs equal `whole` bit for bit.
StreamMergeSummary ExpectSameAsWhole(const fs::path& dir, const std::vector<fs::path>& paths,
                                     const std::vector<double>& exposures_s,
                                     const std::vector<PixelShift>& shifts,
                                     const calib::ResponseCurve& response,
                                     const MergeOptions& options, int band_rows) {
  const MergeResult whole = MergeWhole(paths, exposures_s, shifts, response, options);
  StreamOutputs outputs;
  outputs.radiance = dir / "streamed.exr";
  outputs.mask = dir / "streamed_mask.png";
  HdrStreamOptions stream;
  stream.band_rows = band_rows;
  const StreamMergeSummary summary =
      MergeBracketStreamed(paths, exposures_s, shifts, response, options, stream, outputs);
  EXPECT_EQ(summary.width, whole.radiance.width);
  EXPECT_EQ(summary.height, whole.radiance.height);
  EXPECT_EQ(summary.bands, (whole.radiance.height + band_rows - 1) / band_rows);
  EXPECT_EQ(summary.saturated_pixels, whole.saturated_pixels);
  EXPECT_EQ(summary.black_pixels, whole.black_pixels);
  const Image radiance = ReadImage(outputs.radiance);
  const Image mask = ReadImage(outputs.mask);
  // Bit-identical: the EXR holds float32 losslessly and the mask is 0 or 1.
  EXPECT_TRUE(radiance.pixels == whole.radiance.pixels);
  EXPECT_TRUE(mask.pixels == whole.mask.pixels);
  size_t differing = 0;
  for (size_t i = 0; i < std::min(radiance.pixels.size(), whole.radiance.pixels.size()); ++i) {
    differing += radiance.pixels[i] != whole.radiance.pixels[i] ? 1 : 0;
  }
  EXPECT_EQ(differing, 0u);
  return summary;
}

// 70 rows in bands of 16: four full bands and a partial one; every weighting path of the kernel.
TEST(MergeStream, SyntheticPngBracketEqualsWholeMergeBitForBit) {
  const fs::path dir = test::UniqueTempDir("igi_merge_stream");
  std::vector<double> exposures_s;
  const std::vector<fs::path> paths = WriteBracket(dir, 96, 70, 8, &exposures_s);
  const calib::ResponseCurve response = TrueResponse(256);
  for (const std::string weighting : {"noise", "hat"}) {
    for (bool shared : {false, true}) {
      MergeOptions options;
      options.weighting = MergeWeightingFromName(weighting).value();
      options.shared_weights = shared;
      SCOPED_TRACE(weighting + (shared ? " shared" : ""));
      ExpectSameAsWhole(dir, paths, exposures_s, {}, response, options, 16);
    }
  }
}

TEST(MergeStream, Synthetic16BitTiffBracketEqualsWholeMergeBitForBit) {
  const fs::path dir = test::UniqueTempDir("igi_merge_stream");
  std::vector<double> exposures_s;
  const std::vector<fs::path> paths = WriteBracket(dir, 64, 50, 16, &exposures_s);
  MergeOptions options;
  options.bits = 16;
  ExpectSameAsWhole(dir, paths, exposures_s, {}, TrueResponse(65536), options, 7);
}

// Shifts larger than a band, both signs: rows and columns shifted in from outside repeat the
// border, as ShiftImage does.
TEST(MergeStream, ShiftedFramesEqualShiftImageThenMerge) {
  const fs::path dir = test::UniqueTempDir("igi_merge_stream");
  std::vector<double> exposures_s;
  const std::vector<fs::path> paths = WriteBracket(dir, 48, 40, 8, &exposures_s);
  const std::vector<PixelShift> shifts = {{0, 0}, {3, -2}, {-5, 11}, {0, -13}, {9, 0}};
  ExpectSameAsWhole(dir, paths, exposures_s, shifts, TrueResponse(256), {}, 8);
}

// The buffers are a band of every frame, the merged band and its mask (plus a row of each shifted
// frame): the same for a 4x taller image, and within that bound.
TEST(MergeStream, PeakBufferDoesNotGrowWithHeight) {
  const fs::path dir = test::UniqueTempDir("igi_merge_stream");
  const int width = 40, band_rows = 8, channels = 3;
  size_t peak[2] = {};
  for (int k = 0; k < 2; ++k) {
    const fs::path sub = dir / std::to_string(k);
    fs::create_directories(sub);
    std::vector<double> exposures_s;
    const std::vector<fs::path> paths = WriteBracket(sub, width, 32 << (2 * k), 8, &exposures_s);
    StreamOutputs outputs;
    outputs.radiance = sub / "out.exr";
    HdrStreamOptions stream;
    stream.band_rows = band_rows;
    const StreamMergeSummary summary =
        MergeBracketStreamed(paths, exposures_s, {}, TrueResponse(256), {}, stream, outputs);
    peak[k] = summary.peak_buffer_bytes;
    const size_t frames = paths.size();
    const size_t band_bytes = size_t(band_rows) * width * channels * sizeof(float);
    // A band of every frame, plus the merged band and its 1-channel mask.
    EXPECT_LE(summary.peak_buffer_bytes,
              frames * band_bytes + band_bytes + size_t(band_rows) * width * sizeof(float));
    EXPECT_GE(summary.peak_buffer_bytes, frames * band_bytes);
  }
  EXPECT_EQ(peak[0], peak[1]);
}

TEST(MergeStream, GreyFramesGiveTheWholeImageShifts) {
  const fs::path dir = test::UniqueTempDir("igi_merge_stream");
  const std::string memorial = std::string(IGI_SHARED_DATA_DIR) + "/real/memorial/";
  const std::vector<PixelShift> applied = {{0, 0}, {7, -4}, {-12, 9}};
  std::vector<Image> images;
  std::vector<fs::path> paths;
  for (int k = 0; k < 3; ++k) {
    images.push_back(ShiftImage(
        ReadImage(memorial + "memorial00" + std::to_string(68 + k) + ".png"), applied[size_t(k)]));
    paths.push_back(dir / ("shifted" + std::to_string(k) + ".png"));
    WriteImage(paths.back(), images.back());
  }
  HdrStreamOptions stream;
  stream.band_rows = 50;
  const std::vector<GreyImage> grey = ReadGreyFrames(paths, stream);
  ASSERT_EQ(grey.size(), 3u);
  for (size_t k = 0; k < 3; ++k) EXPECT_TRUE(grey[k].levels == ToGrey(images[k]).levels);
  const std::vector<PixelShift> from_grey = ComputeMtbShifts(grey, 0);
  const std::vector<PixelShift> from_images = ComputeMtbShifts(images, 0);
  for (size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(from_grey[k].dx, from_images[k].dx);
    EXPECT_EQ(from_grey[k].dy, from_images[k].dy);
    EXPECT_EQ(from_grey[k].dx, -applied[k].dx);
  }
}

// The real Memorial bracket (16 exposures, 512x768) with a recovered response, in bands of 64.
TEST(MergeStream, MemorialEqualsWholeMergeBitForBit) {
  const fs::path dir = test::UniqueTempDir("igi_merge_stream");
  const std::string memorial = std::string(IGI_SHARED_DATA_DIR) + "/real/memorial/";
  std::vector<fs::path> paths;
  for (int i = 61; i <= 76; ++i)
    paths.push_back(memorial + "memorial00" + std::to_string(i) + ".png");
  calib::ExposureSource source;
  source.file = memorial + "shutter_times.txt";
  const calib::Bracket bracket = calib::LoadBracket(paths, source);
  calib::ResponseOptions response_options;
  response_options.lambda = 50;
  response_options.samples = 200;
  const calib::ResponseCurve response = calib::RecoverResponse(bracket, response_options).curve;
  const StreamMergeSummary summary =
      ExpectSameAsWhole(dir, paths, bracket.exposures_s, {}, response, {}, 64);
  EXPECT_EQ(summary.bands, 12);
  // 16 bands of 64 x 512 x 3 floats, the merged band and the mask: 6.9 MB, not 75 MB whole.
  EXPECT_LT(summary.peak_buffer_bytes, size_t(18) * 64 * 512 * 3 * 4);
}

// Bad input: an InputError naming the file, and no output (not even a temporary file).
TEST(MergeStream, BadFramesAreInputErrorsAndWriteNothing) {
  const fs::path dir = test::UniqueTempDir("igi_merge_stream");
  std::vector<double> exposures_s;
  std::vector<fs::path> paths = WriteBracket(dir, 32, 24, 8, &exposures_s);
  StreamOutputs outputs;
  outputs.radiance = dir / "out" / "radiance.exr";
  outputs.mask = dir / "out" / "mask.png";
  HdrStreamOptions stream;
  stream.band_rows = 4;  // the cut frame below fails in a later band, after outputs are opened
  const auto expect_error = [&](const std::vector<fs::path>& frames, const std::string& needle) {
    try {
      MergeBracketStreamed(frames, exposures_s, {}, TrueResponse(256), {}, stream, outputs);
      ADD_FAILURE() << "no error for " << needle;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(outputs.radiance));
    EXPECT_FALSE(fs::exists(outputs.mask));
    if (fs::exists(dir / "out")) {
      EXPECT_TRUE(fs::is_empty(dir / "out"));
    }
  };
  std::vector<fs::path> wrong = paths;
  WriteImage(dir / "small.png", Image(16, 24, 3, 0.5f));
  wrong[2] = dir / "small.png";
  expect_error(wrong, "small.png: size: 16x24x3: every image of a bracket must have the size");
  wrong[2] = dir / "missing.png";
  expect_error(wrong, "missing.png");
  // A header that reads, pixel data cut short: found while streaming, the partial outputs go.
  const fs::path cut = dir / "cut.png";
  fs::copy_file(paths[3], cut);
  fs::resize_file(cut, fs::file_size(cut) / 2);
  wrong[2] = paths[2];
  wrong[3] = cut;
  expect_error(wrong, "cut.png");
  HdrStreamOptions bad;
  bad.band_rows = 0;
  EXPECT_THROW(bad.Validate(), InputError);
}

}  // namespace
}  // namespace igi::hdr
