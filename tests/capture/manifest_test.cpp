#include "capture/manifest.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "tools/common/error.h"

namespace igi::capture {
namespace {
namespace fs = std::filesystem;

fs::path TempManifest(const std::string& name) {
  const fs::path path = fs::temp_directory_path() / name;
  fs::remove(path);
  return path;
}

TEST(Manifest, AppendsAndReadsBackEveryKey) {
  const fs::path path = TempManifest("igi_manifest_roundtrip.jsonl");
  ManifestEntry entry;
  entry.file = "frames/b00_e000001000us_f000.png";
  entry.camera = "Aravis-Fake-GV01";
  entry.exposure_us = 1000;
  entry.gain = 2.0;
  entry.pixel_format = "Mono16";
  entry.timestamp = "2025-01-31T12:00:00.000001Z";
  entry.extra["frame_id"] = 65001;
  AppendManifest(path, entry);
  entry.frame = 1;
  entry.gain.reset();
  AppendManifest(path, entry);
  const ManifestContents contents = ReadManifest(path);
  ASSERT_EQ(contents.entries.size(), 2u);
  EXPECT_FALSE(contents.truncated_last_line);
  EXPECT_EQ(ManifestEntryToJson(contents.entries[1]), ManifestEntryToJson(entry));
  EXPECT_EQ(contents.entries[0].gain, 2.0);
  EXPECT_FALSE(contents.entries[1].gain);
  EXPECT_EQ(contents.entries[0].extra["frame_id"], 65001);
  // The contract's keys come first, in the contract's order.
  std::ifstream file(path);
  std::string first;
  std::getline(file, first);
  EXPECT_EQ(first.rfind(R"({"file":"frames/b00_e000001000us_f000.png","camera":)", 0), 0u) << first;
  fs::remove(path);
}

TEST(Manifest, SkipsALastLineCutShortByACrash) {
  const fs::path path = TempManifest("igi_manifest_truncated.jsonl");
  std::ofstream(path) << R"({"file":"frames/a.png","camera":"c","exposure_us":10,"gain":0,)"
                      << R"("pixel_format":"Mono8","timestamp":null,"bracket":0,"frame":0})"
                      << "\n{\"file\":\"frames/b.p";
  const ManifestContents contents = ReadManifest(path);
  EXPECT_EQ(contents.entries.size(), 1u);
  EXPECT_TRUE(contents.truncated_last_line);
  fs::remove(path);
}

TEST(Manifest, NamesTheLineOfABadEntry) {
  const fs::path path = TempManifest("igi_manifest_bad.jsonl");
  const std::string rest = R"(,"gain":0,"pixel_format":"Mono8","timestamp":null,"bracket":0,)"
                           R"("frame":0})";
  std::ofstream(path) << R"({"file":"frames/a.png","camera":"c","exposure_us":10)" << rest << "\n"
                      << R"({"file":"frames/b.png","camera":"c","exposure_us":-1)" << rest << "\n";
  try {
    ReadManifest(path);
    FAIL() << "accepted exposure_us -1";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(":2"), std::string::npos) << e.what();
  }
  fs::remove(path);
}

TEST(FormatTimestamp, IsIso8601Utc) {
  EXPECT_EQ(FormatTimestamp(0), "1970-01-01T00:00:00.000000Z");
  EXPECT_EQ(FormatTimestamp(1738324800123456789ull), "2025-01-31T12:00:00.123456Z");
}

}  // namespace
}  // namespace igi::capture
