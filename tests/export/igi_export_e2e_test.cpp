// igi-export end to end: each format exits 0 and writes its report; bad input exits 2 with one
// stderr line and writes nothing.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "tests/e2e/run.h"
#include "tests/export/export_test_scene.h"
#include "tests/temp_dir.h"
#include "tools/common/atomic_file.h"
#include "tools/common/json.h"

namespace igi::exporter {
namespace {

using test::Quote;
using test::RunTool;

int Lines(const std::string& text) { return int(std::count(text.begin(), text.end(), '\n')); }

std::string RoomScene() { return Quote((test::RadianceRoomDir() / "scene.json").string()); }

TEST(IgiExport, EveryFormatWritesItsFilesAndReport) {
  const auto dir = test::UniqueTempDir("igi_export_e2e");
  for (const std::string format : {"radiance", "mitsuba", "gltf"}) {
    const auto out = dir / format;
    const auto r = RunTool("igi-export", RoomScene() + " --format " + format + " --out " +
                                             Quote(out.string()) + " --quiet");
    EXPECT_EQ(r.exit_code, 0) << format << ": " << r.err;
    const Json report = ReadJsonFile(out / "export_report.json");
    EXPECT_EQ(report["format"], "igi-export-report");
    EXPECT_EQ(report["target"], format);
    for (const auto& f : report["files"]) {
      EXPECT_TRUE(std::filesystem::exists(out / f.get<std::string>())) << f;
    }
  }
  // An existing empty folder is fine.
  std::filesystem::create_directories(dir / "empty");
  EXPECT_EQ(RunTool("igi-export",
                    RoomScene() + " --format gltf --quiet --out " + Quote((dir / "empty").string()))
                .exit_code,
            0);
}

TEST(IgiExport, BadInputExitsTwoAndWritesNothing) {
  const auto dir = test::UniqueTempDir("igi_export_e2e");
  const std::string out = Quote((dir / "out").string());
  // Unknown format.
  auto r = RunTool("igi-export", RoomScene() + " --format povray --out " + out);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(Lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("--format"), std::string::npos);
  // Non-empty output folder: left as it was.
  WriteFileAtomic(dir / "busy" / "keep.txt", "x");
  r = RunTool("igi-export",
              RoomScene() + " --format radiance --out " + Quote((dir / "busy").string()));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(Lines(r.err), 1) << r.err;
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir / "busy"),
                          std::filesystem::directory_iterator()),
            1);
  // Incomplete materials (the glossy box without alpha): one line naming the key.
  Json scene = ReadJsonFile(test::RadianceRoomDir() / "scene.json");
  scene["geometry"][0]["file"] = (test::RadianceRoomDir() / "geometry" / "room.obj").string();
  scene["materials"]["glossy_box"].erase("alpha");
  scene.erase("photos");
  WriteJsonFile(dir / "scene.json", scene);
  r = RunTool("igi-export", Quote((dir / "scene.json").string()) + " --format gltf --out " + out);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(Lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("glossy_box"), std::string::npos) << r.err;
  // Missing scene file.
  r = RunTool("igi-export", Quote((dir / "nope.json").string()) + " --format gltf --out " + out);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(Lines(r.err), 1) << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "out"));
}

}  // namespace
}  // namespace igi::exporter
