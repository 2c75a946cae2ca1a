#pragma once
// A temporary folder unique to this test process and test (ctest runs test cases in parallel
// processes, so a fixed name would be shared and removed under another test's feet).
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>

namespace igi::test {

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
  return dir;
}

}  // namespace igi::test
