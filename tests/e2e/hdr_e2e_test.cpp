// End to end: igi-calib response and igi-hdr as a user runs them (exit codes, one-line errors
// naming the image and the rule, outputs written only when the input is good).
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "tests/e2e/run.h"
#include "tools/common/atomic_file.h"
#include "tools/common/image.h"
#include "tools/common/json.h"

namespace igi {
namespace {

namespace fs = std::filesystem;

const std::string kMemorial = std::string(IGI_SHARED_DATA_DIR) + "/real/memorial/";

struct RunResult {
  int code = -1;
  std::string output;  // stdout and stderr
};

class HdrE2e : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("igi_hdr_e2e_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  RunResult Run(const std::string& tool, const std::string& args) {
    const test::RunResult r = test::RunTool(tool, args);
    return {r.exit_code, r.out + r.err};
  }

  // Five Memorial frames (4 s .. 1/4 s) and their times.
  static std::string Frames() {
    std::string s;
    for (int i = 64; i <= 68; ++i) s += kMemorial + "memorial00" + std::to_string(i) + ".png ";
    return s;
  }
  static constexpr const char* kTimes = "--exposures 4,2,1,1/2,1/4";

  fs::path dir_;
};

TEST_F(HdrE2e, CalibrateThenMerge) {
  const fs::path response = dir_ / "response.json";
  RunResult r = Run("igi-calib", "response " + Frames() + kTimes + " --out " + response.string());
  ASSERT_EQ(r.code, 0) << r.output;
  const Json doc = ReadJsonFile(response);
  EXPECT_EQ(doc["format"], "igi-response");
  EXPECT_EQ(doc["levels"], 256);
  EXPECT_EQ(doc["g"].size(), 3u);
  EXPECT_TRUE(fs::exists(dir_ / "response.svg"));

  const fs::path out = dir_ / "radiance.exr";
  r = Run("igi-hdr",
          Frames() + kTimes + " --response " + response.string() + " --out " + out.string());
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("saturated in every exposure"), std::string::npos) << r.output;
  const ImageInfo info = ReadImageInfo(out);
  EXPECT_EQ(info.width, 512);
  EXPECT_EQ(info.height, 768);
  EXPECT_EQ(info.format, "openexr");
  EXPECT_TRUE(fs::exists(dir_ / "radiance_mask.png"));

  r = Run("igi-calib", "response " + Frames() + kTimes + " --method robertson --out " +
                           (dir_ / "robertson.json").string() + " --no-plot");
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_FALSE(fs::exists(dir_ / "robertson.svg"));
}

TEST_F(HdrE2e, ExposureFileAndAlignment) {
  const fs::path times = dir_ / "times.txt";
  std::ofstream(times) << "# memorial 64..68\n4\n2\n1\n1/2\n0.25\n";
  const fs::path out = dir_ / "aligned.exr";
  const RunResult r = Run("igi-hdr", Frames() + "--exposure-file " + times.string() +
                                         " --align --weighting hat --out " + out.string());
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_TRUE(fs::exists(out));
}

// Exposure times from the images' EXIF: 16-bit TIFFs written with ExposureTime. (TIFF, because
// OpenImageIO 2.4.7 writes a float ExposureTime into JPEG EXIF wrongly: 0.5 reads back as inf;
// camera JPEGs store a rational and read fine.)
TEST_F(HdrE2e, ExposureTimesFromExif) {
  std::string files;
  const double times[3] = {1.0, 0.5, 0.25};
  for (int k = 0; k < 3; ++k) {
    Image frame = ReadImage(kMemorial + "memorial00" + std::to_string(66 + k) + ".png");
    frame.metadata["ExposureTime"] = times[k];
    const fs::path path = dir_ / ("exif" + std::to_string(k) + ".tif");
    WriteImage(path, frame);
    files += path.string() + " ";
  }
  const RunResult r =
      Run("igi-calib", "response " + files + "--out " + (dir_ / "exif.json").string());
  ASSERT_EQ(r.code, 0) << r.output;
  const Json doc = ReadJsonFile(dir_ / "exif.json");
  EXPECT_EQ(doc["info"]["exposures_s"][1], 0.5);
  EXPECT_EQ(doc["info"]["bits_per_sample"], 16);
  EXPECT_EQ(doc["levels"], 1024);
}

TEST_F(HdrE2e, RawIsMergedWithoutAResponse) {
  const fs::path out = dir_ / "chart.exr";
  const RunResult r =
      Run("igi-hdr", std::string(IGI_SHARED_DATA_DIR) +
                         "/real/raw/colorchart.dng --half-size --out " + out.string());
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("raw (linear)"), std::string::npos) << r.output;
  EXPECT_EQ(ReadImageInfo(out).width, 867);
}

TEST_F(HdrE2e, ManifestMergesEachCamera) {
  fs::create_directories(dir_ / "frames");
  std::ofstream manifest(dir_ / "manifest.jsonl");
  WriteImageOptions u16;
  u16.type = PixelType::kUInt16;
  const double times_us[3] = {1000, 4000, 16000};
  for (const std::string camera : {"left", "right"}) {
    for (int k = 0; k < 3; ++k) {
      Image frame(16, 8, 1);
      for (int i = 0; i < 128; ++i) {
        frame.pixels[size_t(i)] = float(std::min(1.0, (0.5 + i) * 1e-4 * times_us[k] / 16));
      }
      const std::string name = "frames/" + camera + std::to_string(k) + ".png";
      WriteImage(dir_ / name, frame, u16);
      manifest << R"({"file":")" << name << R"(","camera":")" << camera << R"(","exposure_us":)"
               << times_us[k] << R"(,"gain":0,"pixel_format":"Mono16","timestamp":"t"})"
               << "\n";
    }
  }
  manifest.close();
  const RunResult r = Run("igi-hdr", "--manifest " + (dir_ / "manifest.jsonl").string() +
                                         " --out " + (dir_ / "hdr.exr").string());
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_TRUE(fs::exists(dir_ / "hdr_left.exr"));
  EXPECT_TRUE(fs::exists(dir_ / "hdr_right.exr"));
  // Linear frames: radiance = value / time, the same in every exposure that is not clipped.
  const Image left = ReadImage(dir_ / "hdr_left.exr");
  EXPECT_NEAR(left.pixels[10] / left.pixels[100], 10.5 / 100.5, 1e-3);
}

// Bad input: exit 2, one line naming the image (or file) and the rule, nothing written.
TEST_F(HdrE2e, BadInputIsExitTwoWithOneLine) {
  const fs::path out = dir_ / "bad.exr";
  const std::string two = kMemorial + "memorial0066.png " + kMemorial + "memorial0067.png ";
  RunResult r = Run("igi-hdr", two + "--exposures 1,1 --out " + out.string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("memorial0067.png: exposure: 1 s: duplicate exposure time"),
            std::string::npos)
      << r.output;
  r = Run("igi-hdr", two + "--out " + out.string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("memorial0066.png: ExposureTime: missing"), std::string::npos)
      << r.output;
  r = Run("igi-hdr", two + "--exposures 1 --out " + out.string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("must give one exposure time per image (2 images)"), std::string::npos)
      << r.output;
  Image small(10, 10, 3, 0.5f);
  WriteImage(dir_ / "small.png", small);
  r = Run("igi-hdr",
          two + (dir_ / "small.png").string() + " --exposures 1,2,3 --out " + out.string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("small.png: size: 10x10x3: every image of a bracket must have the size"),
            std::string::npos)
      << r.output;
  std::ofstream(dir_ / "corrupt.png") << "garbage";
  r = Run("igi-hdr",
          two + (dir_ / "corrupt.png").string() + " --exposures 1,2,3 --out " + out.string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("corrupt.png"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(out));
  EXPECT_FALSE(fs::exists(dir_ / "bad_mask.png"));
}

// 8/16-bit frames with a known response are merged band by band: the same radiance map and mask
// as --whole-images, bit for bit (each pixel's merge reads only that pixel), aligned or not.
TEST_F(HdrE2e, BandByBandEqualsWholeImages) {
  for (const std::string extra : {"", " --align --weighting hat"}) {
    const fs::path streamed = dir_ / "streamed.exr", whole = dir_ / "whole.exr";
    RunResult r = Run("igi-hdr", Frames() + kTimes + " --linear --band-rows 7" + extra + " --out " +
                                     streamed.string());
    ASSERT_EQ(r.code, 0) << r.output;
    r = Run("igi-hdr",
            Frames() + kTimes + " --linear --whole-images" + extra + " --out " + whole.string());
    ASSERT_EQ(r.code, 0) << r.output;
    EXPECT_TRUE(ReadImage(streamed).pixels == ReadImage(whole).pixels) << extra;
    EXPECT_TRUE(ReadImage(dir_ / "streamed_mask.png").pixels ==
                ReadImage(dir_ / "whole_mask.png").pixels)
        << extra;
  }
  const RunResult r = Run(
      "igi-hdr", Frames() + kTimes + " --linear --band-rows 0 --out " + (dir_ / "x.exr").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("--band-rows: 0: must be 1 .. 65536"), std::string::npos) << r.output;
}

// The band-by-band path checks the headers before writing anything, and a frame whose pixel data
// is cut short (found part way through) leaves no output, not even a temporary file.
TEST_F(HdrE2e, BandByBandBadInputIsExitTwoAndWritesNothing) {
  const fs::path out = dir_ / "out" / "bad.exr";
  const std::string two = kMemorial + "memorial0066.png " + kMemorial + "memorial0067.png ";
  WriteImage(dir_ / "small.png", Image(10, 10, 3, 0.5f));
  RunResult r = Run("igi-hdr", two + (dir_ / "small.png").string() +
                                   " --linear --exposures 1,2,3 --out " + out.string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("small.png: size: 10x10x3: every image of a bracket must have the size"),
            std::string::npos)
      << r.output;
  std::ofstream(dir_ / "corrupt.png") << "garbage";
  r = Run("igi-hdr", two + (dir_ / "corrupt.png").string() + " --linear --exposures 1,2,3 --out " +
                         out.string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("corrupt.png"), std::string::npos) << r.output;
  const fs::path cut = dir_ / "cut.png";
  fs::copy_file(kMemorial + "memorial0068.png", cut);
  fs::resize_file(cut, fs::file_size(cut) * 3 / 4);
  r = Run("igi-hdr", two + cut.string() + " --linear --exposures 1,2,3 --out " + out.string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("cut.png: cannot read image data"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(out));
  EXPECT_FALSE(fs::exists(dir_ / "out" / "bad_mask.png"));
  if (fs::exists(dir_ / "out")) {
    EXPECT_TRUE(fs::is_empty(dir_ / "out"));
  }
}

TEST_F(HdrE2e, TooFewUsablePixelsAndUsage) {
  // Two nearly black frames: no usable equations for the response.
  Image dark(64, 64, 3, 0.0f);
  WriteImage(dir_ / "d1.png", dark);
  WriteImage(dir_ / "d2.png", dark);
  RunResult r =
      Run("igi-calib", "response " + (dir_ / "d1.png").string() + " " + (dir_ / "d2.png").string() +
                           " --exposures 1,2 --out " + (dir_ / "r.json").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("too few usable pixels"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir_ / "r.json"));
  EXPECT_EQ(Run("igi-calib", "").code, 2);
  EXPECT_EQ(Run("igi-calib", "--version").code, 0);
  EXPECT_EQ(Run("igi-hdr", "--help").code, 0);
  r = Run("igi-hdr", kMemorial + "memorial0066.png --out x.tif");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("OpenEXR"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace igi
