#pragma once
// A temporary folder unique to this test process and test (ctest runs test cases in parallel
// processes, so a fixed name would be shared and removed under another test's feet).
// The folders a test made are removed when it ends and passed; a failed test's stay for a look
// (their paths are printed). Without this every run of the suite left ~70 folders in /tmp.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <string>
#include <system_error>
#include <vector>

namespace igi::test {

namespace internal {

// Removes, at the end of each test, the folders UniqueTempDir made during it, if it passed.
class TempDirCleaner : public ::testing::EmptyTestEventListener {
 public:
  static TempDirCleaner& Instance() {
    // gtest owns the listener once appended (it deletes it at exit).
    static TempDirCleaner* const cleaner = [] {
      auto* c = new TempDirCleaner;
      ::testing::UnitTest::GetInstance()->listeners().Append(c);
      return c;
    }();
    return *cleaner;
  }
  void Track(const std::filesystem::path& dir) { dirs_.push_back(dir); }
  void OnTestEnd(const ::testing::TestInfo& info) override {
    for (const std::filesystem::path& dir : dirs_) {
      if (info.result() != nullptr && info.result()->Passed()) {
        std::error_code ec;
        std::filesystem::remove_all(dir, ec);
      } else {
        std::fprintf(stderr, "kept for a look: %s\n", dir.c_str());
      }
    }
    dirs_.clear();
  }

 private:
  std::vector<std::filesystem::path> dirs_;
};

}  // namespace internal

inline std::filesystem::path UniqueTempDir(const std::string& prefix) {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  std::string name = prefix + "_" + std::to_string(::getpid());
  if (info != nullptr) name += std::string("_") + info->test_suite_name() + "_" + info->name();
  for (char& c : name) {
    if (c == '/') c = '_';
  }
  const auto dir = std::filesystem::temp_directory_path() / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  // Inside a test: removed when it ends (passed). Outside one (a suite's SetUpTestSuite, a
  // static), the caller owns it.
  if (info != nullptr) internal::TempDirCleaner::Instance().Track(dir);
  return dir;
}

}  // namespace igi::test
