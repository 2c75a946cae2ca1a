// igi-run --hdr-photos through every stage, diagnosis included, on a 2 m box room whose photos
// igi-render made (tests/e2e/box_room.h), recording half the radiance: the photos are declared
// 4x darker still (exposure_scale 0.125) and the ceiling's albedo is given, so igi-solve
// --photo-scale solve (passed with --solve-arg) recovers the factor; igi-diagnose then gets the
// solve's input scene (materials still unknown, so that it solves them itself without its
// held-out pixels and refits them with each candidate) with the solved exposure_scale, and writes
// its diagnosis; the report shows it, its re-render at the photo's scale. About a minute on 2
// cores.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "tests/e2e/box_room.h"
#include "tests/e2e/run.h"
#include "tests/temp_dir.h"
#include "tools/common/atomic_file.h"
#include "tools/common/image.h"
#include "tools/common/json.h"

namespace igi {
namespace {

namespace fs = std::filesystem;
using test::Quote;
using test::RunTool;
using test::box_room::PhotoEntry;
using test::box_room::RoomObj;
using test::box_room::SceneDoc;
using test::box_room::TrueMaterials;

TEST(RunChainE2eTest, DiagnosisGetsTheSolvesInputWithTheSolvedPhotoScale) {
  const fs::path dir = test::UniqueTempDir("igi_run_chain");
  const fs::path scene_dir = dir / "scene";
  fs::create_directories(scene_dir / "geometry");
  fs::create_directories(scene_dir / "photos");
  std::ofstream(scene_dir / "geometry" / "room.obj") << RoomObj(false);
  WriteJsonFile(scene_dir / "render.json", SceneDoc(TrueMaterials(false), Json::array()));
  Json photos = Json::array();
  for (const char* cam : {"cam0", "cam1"}) {
    const std::string file = std::string("photos/") + cam + "_L0.exr";
    const auto r = RunTool("igi-render", Quote((scene_dir / "render.json").string()) +
                                             " --camera " + cam +
                                             " --lighting L0 --spp 64 --threads 2 --quiet --out " +
                                             Quote((scene_dir / file).string()));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    // The camera records half the radiance (its true exposure_scale 0.5).
    Image photo = ReadImage(scene_dir / file);
    for (float& v : photo.pixels) v *= 0.5f;
    WriteImage(scene_dir / file, photo);
    photos.push_back(PhotoEntry(file, cam, "L0"));
    photos.back()["exposure_scale"] = 0.125;
  }
  Json materials = TrueMaterials(false);
  materials["floor"].erase("rho_d");
  materials["walls"].erase("rho_d");
  WriteJsonFile(scene_dir / "scene.json", SceneDoc(materials, photos));

  const fs::path out = dir / "run";
  const auto r = RunTool(
      "igi-run", "--hdr-photos --scene " + Quote((scene_dir / "scene.json").string()) + " --out " +
                     Quote(out.string()) +
                     " --threads 2 --report-photos 1 --report-lightings 1 --report-spp 4"
                     " --report-megapixels 0.001"
                     " --solve-arg=--photo-scale=solve --solve-arg=--indirect-rays=32"
                     " --solve-arg=--refine-iterations=0 --diagnose-arg=--max-steps=1"
                     " --diagnose-arg=--spp=8 --diagnose-arg=--spp-max=0 --diagnose-arg=--refine-iterations=0"
                     "");
  ASSERT_EQ(r.exit_code, 0) << r.err << r.out;

  const Json solved = ReadJsonFile(out / "04-solve" / "scene.json");
  const Json diagnosed_input = ReadJsonFile(out / "05-diagnose" / "input" / "scene.json");
  ASSERT_EQ(diagnosed_input["photos"].size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    // The solved factor (4, measured on the ceiling) makes the photos' scale the true 0.5
    // (tolerance 3 %, as in solve_e2e_test's PhotoScale case), and igi-diagnose gets it.
    const double e = solved["photos"][i]["exposure_scale"].get<double>();
    EXPECT_NEAR(e, 0.5, 0.015);
    EXPECT_DOUBLE_EQ(diagnosed_input["photos"][i]["exposure_scale"].get<double>(), e);
    // Paths rebased: the photo is found from the new folder.
    const fs::path photo = out / "05-diagnose" / "input" /
                           diagnosed_input["photos"][i]["file"].get<std::string>();
    EXPECT_TRUE(fs::exists(photo)) << photo;
  }
  // The materials stay unknown where they were (igi-diagnose solves them), the reference given.
  EXPECT_FALSE(diagnosed_input["materials"]["floor"].contains("rho_d"));
  EXPECT_FALSE(diagnosed_input["materials"]["walls"].contains("rho_d"));
  EXPECT_TRUE(diagnosed_input["materials"]["ceiling"].contains("rho_d"));
  const Json diagnosis = ReadJsonFile(out / "05-diagnose" / "diagnosis.json");
  EXPECT_EQ(diagnosis["format"], "igi-diagnosis");
  EXPECT_TRUE(diagnosis["baseline"]["residual"].is_number());
  EXPECT_TRUE(fs::exists(out / "05-diagnose" / "scene.json"));
  const std::string report = ReadFileToString(out / "report.html");
  EXPECT_NE(report.find("iagnos"), std::string::npos);
  // The report's renders within --report-megapixels (64 × 48 photos: blocks of 2 × 2), and the
  // photo shown beside its render as the residual at that size.
  const ImageInfo render = ReadImageInfo(out / "06-report" / "renders" / "photo_0.exr");
  EXPECT_EQ(render.width, 32);
  EXPECT_EQ(render.height, 24);
  EXPECT_NE(report.find("residual render"), std::string::npos);
  // The re-render is the model as the photo records it (its solved exposure_scale applied): its
  // mean within 5 % of the photo's (4 paths per pixel against 64).
  const Image photo = ReadImage(scene_dir / "photos" / "cam0_L0.exr");
  const Image rerender = ReadImage(out / "06-report" / "renders" / "photo_0.exr");
  const auto mean = [](const Image& im) {
    double sum = 0;
    for (float v : im.pixels) sum += v;
    return sum / double(im.pixels.size());
  };
  EXPECT_NEAR(mean(rerender) / mean(photo), 1.0, 0.05);
  EXPECT_EQ(report.find("not finished"), std::string::npos) << "every stage finished";
  // The solved scene exported for other renderers, and the report links each export.
  for (const char* format : {"radiance", "mitsuba", "gltf"}) {
    const fs::path dir = out / "06-report" / "export" / format;
    ASSERT_TRUE(fs::is_directory(dir)) << dir;
    EXPECT_FALSE(fs::is_empty(dir)) << dir;
    EXPECT_NE(report.find(std::string("href=\"06-report/export/") + format + "/"),
              std::string::npos)
        << format;
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace igi
