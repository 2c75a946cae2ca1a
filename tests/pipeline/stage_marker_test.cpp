// Stage markers and fingerprints (tools/pipeline/stage_marker.h): a fingerprint changes when a file's
// contents change and not otherwise; a marker round-trips; a damaged marker = unfinished.
#include "tools/pipeline/stage_marker.h"

#include <gtest/gtest.h>

#include <fstream>

#include "tests/temp_dir.h"

namespace igi::pipeline {
namespace {
namespace fs = std::filesystem;

std::string Hash(const fs::path& p, const std::string& extra = "") {
  Fingerprint fp;
  fp.AddText(extra);
  fp.AddFile(p);
  return fp.Hex();
}

TEST(StageMarkerTest, FingerprintFollowsContents) {
  const fs::path dir = test::UniqueTempDir("igi_marker");
  std::ofstream(dir / "a.txt") << "one";
  fs::create_directories(dir / "sub");
  std::ofstream(dir / "sub" / "b.txt") << "two";
  const std::string h1 = Hash(dir);
  EXPECT_EQ(Hash(dir), h1);
  EXPECT_NE(Hash(dir, "option"), h1);
  std::ofstream(dir / "sub" / "b.txt") << "TWO";
  EXPECT_NE(Hash(dir), h1);
  EXPECT_NE(Hash(dir / "missing"), Hash(dir / "a.txt"));
  EXPECT_EQ(Hash(dir / "a.txt").size(), 16u);
  fs::remove_all(dir);
}

TEST(StageMarkerTest, RoundTripAndDamagedMarker) {
  const fs::path dir = test::UniqueTempDir("igi_marker");
  EXPECT_FALSE(ReadStageMarker(dir).has_value());
  StageMarker m{"04-solve", "0123456789abcdef", "partial", 12.5, UtcNow(), {"igi-solve a"},
                Json{{"k", 1}}};
  WriteStageMarker(dir, m);
  const auto r = ReadStageMarker(dir);
  ASSERT_TRUE(r.has_value());
  EXPECT_EQ(r->stage, "04-solve");
  EXPECT_EQ(r->fingerprint, m.fingerprint);
  EXPECT_EQ(r->status, "partial");
  EXPECT_DOUBLE_EQ(r->seconds, 12.5);
  EXPECT_EQ(r->commands, m.commands);
  EXPECT_EQ(r->details["k"], 1);
  std::ofstream(MarkerPath(dir)) << "{ broken";
  EXPECT_FALSE(ReadStageMarker(dir).has_value());
  fs::remove_all(dir);
}

}  // namespace
}  // namespace igi::pipeline
