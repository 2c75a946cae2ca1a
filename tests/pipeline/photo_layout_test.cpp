// PHOTOS_DIR layouts (tools/pipeline/photo_layout.h): each kind is recognised with its lighting from
// the folder-name suffix; every broken layout is an InputError with one line per problem.
#include "tools/pipeline/photo_layout.h"

#include <gtest/gtest.h>

#include <fstream>

#include "tests/temp_dir.h"
#include "tools/common/error.h"

namespace igi::pipeline {
namespace {
namespace fs = std::filesystem;

void Touch(const fs::path& p, const std::string& text = "x") {
  fs::create_directories(p.parent_path());
  std::ofstream(p) << text;
}

TEST(PhotoLayoutTest, RecognisesEachKindAndLighting) {
  const fs::path dir = test::UniqueTempDir("igi_layout");
  Touch(dir / "cam0_L0/00.png");
  Touch(dir / "cam0_L0/01.png");
  Touch(dir / "cam0_L0/02.png");
  Touch(dir / "cam0_L0/exposures.txt", "0.01\n# comment\n0.04\n0.16\n");
  Touch(dir / "cam1_L1/a.dng");
  Touch(dir / "cam2_L0/radiance.exr");
  Touch(dir / "cam3_L1/manifest.jsonl", "{}\n");
  Touch(dir / "cam4_L1/x.png");
  Touch(dir / "cam4_L1/y.png");
  Touch(dir / "camera.json", "{}");
  Touch(dir / "markers.json", "{}");
  const PhotoLayout layout = ScanPhotosDir(dir, {"L0", "L1"});
  ASSERT_EQ(layout.photos.size(), 5u);
  EXPECT_EQ(layout.photos[0].kind, PhotoSourceKind::kBracket);
  EXPECT_EQ(layout.photos[0].lighting, "L0");
  EXPECT_EQ(layout.photos[0].images.size(), 3u);
  EXPECT_FALSE(layout.photos[0].exposure_file.empty());
  EXPECT_EQ(layout.photos[1].kind, PhotoSourceKind::kRaw);
  EXPECT_EQ(layout.photos[1].lighting, "L1");
  EXPECT_EQ(layout.photos[2].kind, PhotoSourceKind::kRadiance);
  EXPECT_EQ(layout.photos[3].kind, PhotoSourceKind::kCapture);
  EXPECT_TRUE(layout.photos[4].exposure_file.empty());  // EXIF
  EXPECT_EQ(layout.ResponseSource(), 0);                // the longest bracket
  EXPECT_FALSE(layout.camera.empty());
  EXPECT_FALSE(layout.markers.empty());
  fs::remove_all(dir);
}

TEST(PhotoLayoutTest, SingleLightingNeedsNoSuffix) {
  const fs::path dir = test::UniqueTempDir("igi_layout");
  Touch(dir / "front/r.exr");
  const PhotoLayout layout = ScanPhotosDir(dir, {"only"});
  ASSERT_EQ(layout.photos.size(), 1u);
  EXPECT_EQ(layout.photos[0].lighting, "only");
  EXPECT_EQ(layout.ResponseSource(), -1);
  fs::remove_all(dir);
}

// Each broken layout: one problem line naming the file and the rule.
TEST(PhotoLayoutTest, BrokenLayoutsAreInputErrors) {
  const fs::path dir = test::UniqueTempDir("igi_layout");
  Touch(dir / "cam0_L9/00.png");          // unknown lighting, and a bracket of 1
  Touch(dir / "cam1_L0/00.png");
  Touch(dir / "cam1_L0/01.png");
  Touch(dir / "cam1_L0/exposures.txt", "0.1\n");  // 1 exposure for 2 images
  Touch(dir / "cam2_L0/a.png");
  Touch(dir / "cam2_L0/b.exr");            // mixed kinds
  Touch(dir / "cam3_L0/notes.doc");        // not an image
  Touch(dir / "stray.txt");                // not part of the layout
  fs::create_directories(dir / "cam4_L0");  // empty
  try {
    ScanPhotosDir(dir, {"L0", "L1"});
    FAIL() << "no error";
  } catch (const InputError& e) {
    const std::vector<std::string> lines = e.Lines();
    EXPECT_EQ(lines.size(), 7u) << e.what();
    const std::string all = e.what();
    for (const char* needle : {"cam0_L9", "bracket needs at least 2", "must list one per image",
                               "mixed kinds", "notes.doc", "stray.txt", "empty"}) {
      EXPECT_NE(all.find(needle), std::string::npos) << needle << "\n" << all;
    }
  }
  EXPECT_THROW(ScanPhotosDir(dir / "absent", {"L0"}), InputError);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace igi::pipeline
