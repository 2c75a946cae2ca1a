// Raw import on the real raw files of ../shared/data/real/raw (a Canon EOS Kiss
// X4 DNG and a Kodak DC50 KDC; see the data README). Their metadata, as LibRaw
// reads it: the DNG records ExposureTime 1 s and no ISO; the KDC 1/230 s
// (0.00435 s) at ISO 84.
#include "capture/raw_import.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "capture/manifest.h"
#include "tools/common/atomic_file.h"
#include "tools/common/error.h"

namespace igi::capture {
namespace {
namespace fs = std::filesystem;

const fs::path kRawDir = fs::path(IGI_SHARED_DATA_DIR) / "real" / "raw";

TEST(ReadRawInfo, ReadsExposureIsoAndCameraOfRealFiles) {
  const RawFileInfo kodak = ReadRawInfo(kRawDir / "kodak_dc50.kdc");
  EXPECT_EQ(kodak.camera, "Kodak DC50");
  EXPECT_NEAR(kodak.exposure_us, 4350.0,
              0.01);  // LibRaw's float shutter: ~1e-6 relative
  ASSERT_TRUE(kodak.iso);
  EXPECT_DOUBLE_EQ(*kodak.iso, 84.0);
  EXPECT_FALSE(kodak.timestamp.empty());
  const RawFileInfo canon = ReadRawInfo(kRawDir / "colorchart.dng");
  EXPECT_EQ(canon.camera, "Canon EOS Kiss X4");
  EXPECT_DOUBLE_EQ(canon.exposure_us, 1e6);
  EXPECT_FALSE(canon.iso);
  EXPECT_EQ(canon.black_level, 2056);
  EXPECT_EQ(canon.white_level, 15000);
}

class RawImportTest : public ::testing::Test {
 protected:
  void SetUp() override {
    out_ = fs::temp_directory_path() / ("igi_raw_import_" + std::to_string(::getpid()));
    fs::remove_all(out_);
  }
  void TearDown() override { fs::remove_all(out_); }
  fs::path out_;
};

TEST_F(RawImportTest, CopiesRawFilesUnchangedAndListsThem) {
  const RawImportSummary summary = ImportRaw({kRawDir, out_, false});
  EXPECT_EQ(summary.files_imported, 2);
  EXPECT_EQ(summary.ignored.size(),
            4u);  // the ColorChecker .cht/.cie references
  const ManifestContents manifest = ReadManifest(out_ / "manifest.jsonl");
  ASSERT_EQ(manifest.entries.size(), 2u);
  // Shortest exposure first: the Kodak (4350 µs) is bracket 0, the Canon (1 s)
  // bracket 1.
  const ManifestEntry& kodak = manifest.entries[1];
  EXPECT_EQ(kodak.file, "frames/kodak_dc50.kdc");
  EXPECT_EQ(kodak.bracket, 0);
  EXPECT_EQ(kodak.pixel_format, "raw:kdc");
  EXPECT_NEAR(*kodak.gain, 0.84, 1e-12);
  EXPECT_EQ(kodak.extra["iso"], 84.0);
  const ManifestEntry& canon = manifest.entries[0];
  EXPECT_EQ(canon.bracket, 1);
  EXPECT_EQ(canon.camera, "Canon EOS Kiss X4");
  EXPECT_FALSE(canon.gain);
  for (const char* name : {"colorchart.dng", "kodak_dc50.kdc"}) {
    EXPECT_EQ(ReadFileToString(out_ / "frames" / name), ReadFileToString(kRawDir / name)) << name;
  }
  // A second import into the same folder must not overwrite; --resume adds
  // nothing new.
  EXPECT_THROW(ImportRaw({kRawDir, out_, false}), InputError);
  const RawImportSummary again = ImportRaw({kRawDir, out_, true});
  EXPECT_EQ(again.files_imported, 0);
  EXPECT_EQ(again.files_already_done, 2);
  EXPECT_EQ(ReadManifest(out_ / "manifest.jsonl").entries.size(), 2u);
}

TEST_F(RawImportTest, ABrokenRawFileWritesNothing) {
  const fs::path in = out_.string() + "_in";
  fs::create_directories(in);
  fs::copy_file(kRawDir / "kodak_dc50.kdc", in / "good.kdc");
  std::ofstream(in / "broken.dng") << "not a raw file";
  try {
    ImportRaw({in, out_, false});
    FAIL() << "imported a broken raw file";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("broken.dng"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(out_));
  fs::remove_all(in);
}

}  // namespace
}  // namespace igi::capture
