// The installed package: `cmake --install` of this build into a temporary prefix, then a small
// project outside the tree (tests/export/consumer) configured with find_package(igi), built,
// and run on the radiance_room scene. Needs a complete build (every installed target built).
#include <gtest/gtest.h>

#include <filesystem>

#include "tests/e2e/run.h"
#include "tests/export/export_test_scene.h"
#include "tests/temp_dir.h"
#include "tools/common/atomic_file.h"

namespace igi::exporter {
namespace {

using test::Quote;

// Runs a shell command, its output into `log`; returns the exit status.
int Shell(const std::string& command, const std::filesystem::path& log) {
  return std::system((command + " >" + Quote(log.string()) + " 2>&1").c_str());
}

TEST(InstalledPackage, ConsumerFindsIgiAndLoadsAScene) {
  const std::string cmake = IGI_CMAKE_COMMAND;
  if (!std::filesystem::exists(cmake) && Shell("command -v cmake", "/dev/null") != 0) {
    GTEST_SKIP() << "cmake not found";
  }
  const auto dir = test::UniqueTempDir("igi_install");
  const auto prefix = dir / "prefix", build = dir / "build", log = dir / "log.txt";
  ASSERT_EQ(Shell(Quote(cmake) + " --install " + Quote(IGI_BUILD_DIR) + " --prefix " +
                      Quote(prefix.string()),
                  log),
            0)
      << ReadFileToString(log);
  EXPECT_TRUE(std::filesystem::exists(prefix / "include/igi/recon/scene.h"));
  EXPECT_TRUE(std::filesystem::exists(prefix / "include/igi/tools/common/json.h"));
  EXPECT_TRUE(std::filesystem::exists(prefix / "include/igi/solver/export/export.h"));
  EXPECT_TRUE(std::filesystem::exists(prefix / "bin/igi-export"));

  const std::string source = std::string(IGI_SOURCE_DIR) + "/tests/export/consumer";
  ASSERT_EQ(Shell(Quote(cmake) + " -S " + Quote(source) + " -B " + Quote(build.string()) + " -G " +
                      Quote(IGI_CMAKE_GENERATOR) +
                      " -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH=" + Quote(prefix.string()),
                  log),
            0)
      << ReadFileToString(log);
  ASSERT_EQ(Shell(Quote(cmake) + " --build " + Quote(build.string()), log), 0)
      << ReadFileToString(log);
  const auto out = dir / "out.txt";
  ASSERT_EQ(Shell(Quote((build / "igi_consumer").string()) + " " +
                      Quote((test::RadianceRoomDir() / "scene.json").string()),
                  out),
            0)
      << ReadFileToString(out);
  EXPECT_EQ(ReadFileToString(out), "materials 8 lights 2 cameras 3 triangles 36\n");
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace igi::exporter
