#include "tools/common/atomic_file.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "tools/common/error.h"

namespace igi {
namespace {

namespace fs = std::filesystem;

fs::path TempDir(const std::string& name) {
  fs::path dir = fs::temp_directory_path() / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

TEST(AtomicFileTest, WritesAndReplacesWholeFile) {
  fs::path dir = TempDir("igi_atomic_a");
  WriteFileAtomic(dir / "sub" / "f.txt", "first");
  WriteFileAtomic(dir / "sub" / "f.txt", "second");
  EXPECT_EQ(ReadFileToString(dir / "sub" / "f.txt"), "second");
  size_t count = 0;
  for (auto& entry : fs::directory_iterator(dir / "sub")) count += entry.is_regular_file();
  EXPECT_EQ(count, 1u);  // no temporary left behind
  fs::remove_all(dir);
}

TEST(AtomicFileTest, UncommittedOutputLeavesOldContentAndNoTemp) {
  fs::path dir = TempDir("igi_atomic_b");
  WriteFileAtomic(dir / "f.txt", "old");
  {
    AtomicOutput out(dir / "f.txt");
    EXPECT_EQ(out.temp_path().extension(), ".txt");
    WriteFileAtomic(out.temp_path(), "partial");
    // destroyed without Commit(): simulates a failure mid-write
  }
  EXPECT_EQ(ReadFileToString(dir / "f.txt"), "old");
  size_t count = 0;
  for (auto& entry : fs::directory_iterator(dir)) count += entry.is_regular_file();
  EXPECT_EQ(count, 1u);
  fs::remove_all(dir);
}

TEST(AtomicFileTest, AppendLineDurableAppends) {
  fs::path dir = TempDir("igi_atomic_c");
  AppendLineDurable(dir / "m.jsonl", "{\"a\":1}");
  AppendLineDurable(dir / "m.jsonl", "{\"a\":2}");
  EXPECT_EQ(ReadFileToString(dir / "m.jsonl"), "{\"a\":1}\n{\"a\":2}\n");
  fs::remove_all(dir);
}

TEST(AtomicFileTest, ReadMissingFileIsInputError) {
  EXPECT_THROW(ReadFileToString("/nonexistent/igi/file"), InputError);
}

}  // namespace
}  // namespace igi
