// Tests of the COLMAP model readers and writers: round trips, a cross-check against COLMAP 3.8
// itself (its model_converter reads igi's TXT and BIN and writes BIN, TXT and PLY that igi reads
// back or compares; a real reconstruction of the Sceaux castle photos), a corpus of broken model
// folders, and the BIN and PLY writers.
//
// Every comparison of numbers here is exact: TXT carries 17 significant digits, which is enough
// for any double to survive printing and parsing bit for bit, and BIN carries the bits.

#include "recon/colmap_model.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <random>
#include <sstream>
#include <stdexcept>
#include <tuple>

#include "tools/common/atomic_file.h"
#include "tools/common/error.h"
#include "tools/common/strings.h"

namespace igi::recon {
namespace {

namespace fs = std::filesystem;

// ---------------------------------------------------------------------------------------------
// Helpers

class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = fs::temp_directory_path() /
            ("igi_colmap_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

// COLMAP is a declared test dependency (the README's setup installs it): without it the
// cross-check tests fail, they are not skipped.
std::string FindColmap() {
  const char* path = std::getenv("PATH");
  for (const std::string& dir : SplitTokens(path == nullptr ? "" : path, ":")) {
    const fs::path candidate = fs::path(dir) / "colmap";
    if (::access(candidate.c_str(), X_OK) == 0) return candidate.string();
  }
  return "";
}

void RunColmap(const std::string& arguments, const fs::path& log) {
  const std::string colmap = FindColmap();
  ASSERT_FALSE(colmap.empty())
      << "colmap (COLMAP 3.8) is not on PATH; it is required for this test: install it as the "
         "README's setup does (apt-get install colmap)";
  const std::string command =
      "QT_QPA_PLATFORM=offscreen " + colmap + " " + arguments + " > " + log.string() + " 2>&1";
  const int status = std::system(command.c_str());
  ASSERT_EQ(status, 0) << command << "\n" << ReadFileToString(log);
}

// COLMAP's model_converter: `in` (TXT or BIN) to `out` in `type` (BIN or TXT: a folder; PLY: a
// file, its log beside it).
void ConvertWithColmap(const fs::path& in, const fs::path& out, const std::string& type) {
  const bool folder = type != "PLY";
  if (folder) fs::create_directories(out);
  RunColmap("model_converter --input_path " + in.string() + " --output_path " + out.string() +
                " --output_type " + type,
            folder ? out / "colmap.log" : fs::path(out.string() + ".log"));
}

// The first difference between two models, with full precision, or "" if they are equal.
std::string FirstDifference(const ColmapModel& a, const ColmapModel& b) {
  std::ostringstream out;
  out.precision(17);
  if (a.cameras.size() != b.cameras.size() || a.images.size() != b.images.size() ||
      a.points3d.size() != b.points3d.size()) {
    out << "sizes differ: " << a.cameras.size() << "/" << a.images.size() << "/"
        << a.points3d.size() << " vs " << b.cameras.size() << "/" << b.images.size() << "/"
        << b.points3d.size();
    return out.str();
  }
  for (auto [i, j] = std::pair(a.cameras.begin(), b.cameras.begin()); i != a.cameras.end();
       ++i, ++j) {
    if (i->second == j->second) continue;
    out << "camera " << i->first << " vs " << j->first << ": " << i->second.model << " "
        << j->second.model;
    for (size_t k = 0; k < std::min(i->second.params.size(), j->second.params.size()); ++k) {
      out << " [" << i->second.params[k] << " " << j->second.params[k] << "]";
    }
    return out.str();
  }
  for (auto [i, j] = std::pair(a.images.begin(), b.images.begin()); i != a.images.end(); ++i, ++j) {
    const ColmapImage& x = i->second;
    const ColmapImage& y = j->second;
    if (x == y) continue;
    out << "image " << i->first << " vs " << j->first << ": q " << x.qvec.transpose() << " | "
        << y.qvec.transpose() << ", t " << x.tvec.transpose() << " | " << y.tvec.transpose()
        << ", camera " << x.camera_id << " | " << y.camera_id << ", name " << x.name << " | "
        << y.name << ", points " << x.points2d.size() << " | " << y.points2d.size();
    return out.str();
  }
  for (auto [i, j] = std::pair(a.points3d.begin(), b.points3d.begin()); i != a.points3d.end();
       ++i, ++j) {
    const ColmapPoint3D& x = i->second;
    const ColmapPoint3D& y = j->second;
    if (x == y) continue;
    out << "point " << i->first << " vs " << j->first << ": xyz " << x.xyz.transpose() << " | "
        << y.xyz.transpose() << ", error " << x.error << " | " << y.error << ", track "
        << x.track.size() << " | " << y.track.size();
    return out.str();
  }
  return "";
}

// A quaternion q with q / |q| == q bit for bit, as COLMAP normalises each one it reads or
// writes: such a q passes through COLMAP unchanged.
Eigen::Vector4d RandomUnitQuaternion(std::mt19937_64& rng) {
  std::normal_distribution<double> normal;
  while (true) {
    Eigen::Vector4d q(normal(rng), normal(rng), normal(rng), normal(rng));
    for (int i = 0; i < 8; ++i) {
      const Eigen::Vector4d next = q / q.norm();
      if (next == q) return q;
      q = next;
    }
  }
}

// A double of any sign and magnitude from 1e-12 to 1e6 with all 53 bits random, or one of a few
// awkward values (0.1, 1/3, -0, 1e300, ...).
double AwkwardDouble(std::mt19937_64& rng) {
  static constexpr double kSpecial[] = {0.1, 1.0 / 3.0, -0.0, 0.0, 1e300, -2.5e-308, 123456789.0};
  std::uniform_int_distribution<int> pick(0, 9);
  const int k = pick(rng);
  if (k < 3) return kSpecial[std::uniform_int_distribution<int>(0, 6)(rng)];
  const double mantissa = std::uniform_real_distribution<double>(-1.0, 1.0)(rng);
  return mantissa * std::pow(10.0, std::uniform_int_distribution<int>(-12, 6)(rng));
}

// A consistent model using every camera model, large and sparse ids, an image without 2D points
// and a point without a track.
ColmapModel MakeSyntheticModel(uint64_t seed) {
  std::mt19937_64 rng(seed);
  ColmapModel model;
  std::vector<uint32_t> camera_ids;
  const auto names = ColmapModelNames();
  for (size_t m = 0; m < names.size(); ++m) {
    ColmapCamera camera;
    camera.camera_id = m == 0 ? 4294967294u : static_cast<uint32_t>(3 * m + 1);
    camera.model = names[m];
    camera.width = std::uniform_int_distribution<int>(1, 9000)(rng);
    camera.height = std::uniform_int_distribution<int>(1, 9000)(rng);
    for (int p = 0; p < ColmapModelNumParams(names[m]); ++p)
      camera.params.push_back(AwkwardDouble(rng));
    camera_ids.push_back(camera.camera_id);
    model.cameras[camera.camera_id] = camera;
  }
  const std::vector<std::string> image_names = {
      "a.jpg", "sub/dir/b.JPG", "c_ü.png", "d-00001.tif", "e.jpeg", "f.png", "g/h/i/j.jpg"};
  std::vector<uint32_t> image_ids;
  for (size_t i = 0; i < image_names.size(); ++i) {
    ColmapImage image;
    image.image_id = i == 0 ? 4000000000u : static_cast<uint32_t>(10 * i + 7);
    image.qvec = RandomUnitQuaternion(rng);
    image.tvec = Eigen::Vector3d(AwkwardDouble(rng), AwkwardDouble(rng), AwkwardDouble(rng));
    image.camera_id = camera_ids[i % camera_ids.size()];
    image.name = image_names[i];
    const int num_points = i == 2 ? 0 : std::uniform_int_distribution<int>(5, 60)(rng);
    std::uniform_real_distribution<double> pixel(0.0, 5000.0);
    for (int k = 0; k < num_points; ++k) image.points2d.push_back({{pixel(rng), pixel(rng)}, -1});
    image_ids.push_back(image.image_id);
    model.images[image.image_id] = image;
  }
  for (int p = 0; p < 40; ++p) {
    ColmapPoint3D point;
    point.point3d_id = p == 0 ? 5000000001ull : p == 1 ? (1ull << 62) : 100 + 7 * p;
    point.xyz = Eigen::Vector3d(AwkwardDouble(rng), AwkwardDouble(rng), AwkwardDouble(rng));
    for (auto& c : point.rgb) c = static_cast<uint8_t>(rng() & 0xff);
    point.error = p % 5 == 0 ? -1.0 : std::abs(AwkwardDouble(rng));
    const int track_length = p == 2 ? 0 : std::uniform_int_distribution<int>(2, 4)(rng);
    for (int t = 0; t < track_length; ++t) {
      ColmapImage& image = model.images[image_ids[(p + 2 * t) % image_ids.size()]];
      for (size_t k = 0; k < image.points2d.size(); ++k) {
        if (image.points2d[k].point3d_id != -1) continue;
        image.points2d[k].point3d_id = static_cast<int64_t>(point.point3d_id);
        point.track.push_back({image.image_id, static_cast<uint32_t>(k)});
        break;
      }
    }
    model.points3d[point.point3d_id] = point;
  }
  return model;
}

std::vector<std::string> HeadLines(const fs::path& path, size_t n) {
  std::ifstream in(path);
  std::vector<std::string> lines;
  for (std::string line; lines.size() < n && std::getline(in, line);) lines.push_back(line);
  return lines;
}

// ---------------------------------------------------------------------------------------------
// Camera model table

TEST(ColmapCameraModels, MatchColmap38) {
  const std::vector<std::pair<std::string, int>> expected = {{"SIMPLE_PINHOLE", 3},
                                                             {"PINHOLE", 4},
                                                             {"SIMPLE_RADIAL", 4},
                                                             {"RADIAL", 5},
                                                             {"OPENCV", 8},
                                                             {"OPENCV_FISHEYE", 8},
                                                             {"FULL_OPENCV", 12},
                                                             {"FOV", 5},
                                                             {"SIMPLE_RADIAL_FISHEYE", 4},
                                                             {"RADIAL_FISHEYE", 5},
                                                             {"THIN_PRISM_FISHEYE", 12}};
  ASSERT_EQ(ColmapModelNames().size(), expected.size());
  for (size_t id = 0; id < expected.size(); ++id) {
    EXPECT_EQ(ColmapModelNames()[id], expected[id].first);
    EXPECT_EQ(ColmapModelNumParams(expected[id].first), expected[id].second);
    EXPECT_EQ(ColmapModelIdFromName(expected[id].first), static_cast<int>(id));
    EXPECT_EQ(ColmapModelNameFromId(static_cast<int>(id)), expected[id].first);
  }
  EXPECT_EQ(ColmapModelNumParams("pinhole"), -1);
  EXPECT_EQ(ColmapModelIdFromName("BROWN"), std::nullopt);
  EXPECT_EQ(ColmapModelNameFromId(11), std::nullopt);
  EXPECT_EQ(ColmapModelNameFromId(-1), std::nullopt);
}

// ---------------------------------------------------------------------------------------------
// Round trips within igi

TEST(ColmapModelText, WriteReadIsLosslessAndRewriteIsIdentical) {
  TempDir tmp;
  const ColmapModel model = MakeSyntheticModel(1);
  WriteColmapModelText(model, tmp.path() / "a");
  const ColmapModel read = ReadColmapModelText(tmp.path() / "a");
  EXPECT_EQ(FirstDifference(model, read), "");
  EXPECT_TRUE(read == model);
  WriteColmapModelText(read, tmp.path() / "b");
  for (const char* file : {"cameras.txt", "images.txt", "points3D.txt"}) {
    EXPECT_EQ(ReadFileToString(tmp.path() / "a" / file), ReadFileToString(tmp.path() / "b" / file))
        << file;
  }
  EXPECT_TRUE(ReadColmapModel(tmp.path() / "a") == model);  // detects TXT
  ASSERT_NE(read.FindImageByName("sub/dir/b.JPG"), nullptr);
  EXPECT_EQ(read.FindImageByName("sub/dir/b.JPG")->image_id, 17u);
  EXPECT_EQ(read.FindImageByName("nope.jpg"), nullptr);
}

TEST(ColmapModelText, WritesColmapHeadersAndLineLayout) {
  TempDir tmp;
  ColmapModel model;
  model.cameras[1] = {1, "PINHOLE", 640, 480, {500, 500.5, 320, 240}};
  model.images[1] = {1, {1, 0, 0, 0}, {0.1, 0, -2}, 1, "a.jpg", {{{10, 20}, 7}, {{30, 40}, -1}}};
  model.images[2] = {2, {0, 1, 0, 0}, {0, 0, 0}, 1, "b.jpg", {}};
  model.points3d[7] = {7, {1, 2, 3}, {255, 128, 0}, 0.25, {{1, 0}}};
  model.points3d[8] = {8, {0, 0, 0}, {0, 0, 0}, -1, {}};
  WriteColmapModelText(model, tmp.path());
  EXPECT_EQ(ReadFileToString(tmp.path() / "cameras.txt"),
            "# Camera list with one line of data per camera:\n"
            "#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n"
            "# Number of cameras: 1\n"
            "1 PINHOLE 640 480 500 500.5 320 240\n");
  EXPECT_EQ(ReadFileToString(tmp.path() / "images.txt"),
            "# Image list with two lines of data per image:\n"
            "#   IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME\n"
            "#   POINTS2D[] as (X, Y, POINT3D_ID)\n"
            "# Number of images: 2, mean observations per image: 0.5\n"
            "1 1 0 0 0 0.10000000000000001 0 -2 1 a.jpg\n"
            "10 20 7 30 40 -1\n"
            "2 0 1 0 0 0 0 0 1 b.jpg\n"
            "\n");
  EXPECT_EQ(ReadFileToString(tmp.path() / "points3D.txt"),
            "# 3D point list with one line of data per point:\n"
            "#   POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[] as (IMAGE_ID, POINT2D_IDX)\n"
            "# Number of points: 2, mean track length: 0.5\n"
            "7 1 2 3 255 128 0 0.25 1 0\n"
            "8 0 0 0 0 0 0 -1 \n");
}

TEST(ColmapModelText, QuaternionsNearUnitAreNormalisedOthersRejected) {
  TempDir tmp;
  WriteFileAtomic(tmp.path() / "cameras.txt", "1 SIMPLE_PINHOLE 100 100 50 50 50\n");
  WriteFileAtomic(tmp.path() / "points3D.txt", "");
  // Six digits, as many tools print: |q| = 1.0000003, normalised.
  WriteFileAtomic(tmp.path() / "images.txt", "1 0.707107 0.707107 0 0 0 0 0 1 a.jpg\n\n");
  const ColmapModel model = ReadColmapModelText(tmp.path());
  const Eigen::Vector4d q = model.images.at(1).qvec;
  EXPECT_NEAR(q.norm(), 1.0, 1e-15);  // a few ulp of rounding in q / |q|
  EXPECT_EQ(q[0], q[1]);
  // |q| = 1.01: rejected.
  WriteFileAtomic(tmp.path() / "images.txt", "1 1.01 0 0 0 0 0 0 1 a.jpg\n\n");
  try {
    ReadColmapModelText(tmp.path());
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("images.txt: line 1: |q| = 1.01: non-unit quaternion"),
              std::string::npos)
        << e.what();
  }
}

TEST(ColmapModelText, ReadsColmapDocumentationExampleCameras) {
  // The cameras of COLMAP's format documentation (doc/format.rst), with its comment header.
  TempDir tmp;
  WriteFileAtomic(tmp.path() / "cameras.txt",
                  "# Camera list with one line of data per camera:\n"
                  "#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n"
                  "# Number of cameras: 3\n"
                  "1 SIMPLE_PINHOLE 3072 2304 2559.81 1536 1152\n"
                  "2 PINHOLE 3072 2304 2560.56 2560.56 1536 1152\n"
                  "3 SIMPLE_RADIAL 3072 2304 2559.69 1536 1152 -0.0218531\n");
  WriteFileAtomic(tmp.path() / "images.txt",
                  "1 0.851773 0.0165051 0.503764 -0.142941 -0.737434 1.02973 3.74354 1 "
                  "P1180141.JPG\n2362.39 248.498 -1 1784.7 268.254 -1\n");
  WriteFileAtomic(tmp.path() / "points3D.txt", "\n");
  const ColmapModel model = ReadColmapModel(tmp.path());
  ASSERT_EQ(model.cameras.size(), 3u);
  EXPECT_EQ(model.cameras.at(3).model, "SIMPLE_RADIAL");
  EXPECT_EQ(model.cameras.at(3).params, (std::vector<double>{2559.69, 1536, 1152, -0.0218531}));
  EXPECT_EQ(model.cameras.at(2).width, 3072);
  ASSERT_EQ(model.images.at(1).points2d.size(), 2u);
  EXPECT_EQ(model.images.at(1).points2d[1].xy, Eigen::Vector2d(1784.7, 268.254));
  EXPECT_EQ(model.images.at(1).name, "P1180141.JPG");
}

TEST(ColmapModelText, AcceptsCrlfBlankLinesAndAMissingLastPointsLine) {
  // Windows line ends, blank lines between records, and a file that ends right after the last
  // image's first line (read as an image without 2D points).
  TempDir tmp;
  WriteFileAtomic(tmp.path() / "cameras.txt", "# c\r\n\r\n1 SIMPLE_PINHOLE 10 10 5 5 5\r\n");
  WriteFileAtomic(tmp.path() / "images.txt",
                  "# i\r\n1 1 0 0 0 0 0 0 1 a.jpg\r\n1 2 -1 3 4 -1\r\n\r\n2 1 0 0 0 0 0 0 1 b.jpg");
  WriteFileAtomic(tmp.path() / "points3D.txt", "");
  const ColmapModel model = ReadColmapModelText(tmp.path());
  ASSERT_EQ(model.images.size(), 2u);
  EXPECT_EQ(model.images.at(1).points2d.size(), 2u);
  EXPECT_EQ(model.images.at(1).name, "a.jpg");
  EXPECT_TRUE(model.images.at(2).points2d.empty());
  EXPECT_EQ(model.cameras.at(1).params, (std::vector<double>{5, 5, 5}));
}

TEST(ColmapModelText, WriterValidatesFirstAndWritesNothingOnError) {
  TempDir tmp;
  ColmapModel model = MakeSyntheticModel(2);
  model.images.begin()->second.camera_id = 999;
  try {
    WriteColmapModelText(model, tmp.path() / "out");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("images.txt: IMAGE_ID"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("image references a missing camera"), std::string::npos);
  }
  EXPECT_FALSE(fs::exists(tmp.path() / "out"));
}

// ---------------------------------------------------------------------------------------------
// Cross-check with COLMAP 3.8

TEST(ColmapModelCrossCheck, ColmapReadsIgiTextAndIgiReadsColmapBinAndText) {
  TempDir tmp;
  const ColmapModel model = MakeSyntheticModel(3);
  WriteColmapModelText(model, tmp.path() / "igi_txt");
  ASSERT_NO_FATAL_FAILURE(ConvertWithColmap(tmp.path() / "igi_txt", tmp.path() / "bin", "BIN"));
  ASSERT_NO_FATAL_FAILURE(ConvertWithColmap(tmp.path() / "igi_txt", tmp.path() / "txt", "TXT"));
  ASSERT_NO_FATAL_FAILURE(ConvertWithColmap(tmp.path() / "bin", tmp.path() / "bin_txt", "TXT"));

  const ColmapModel from_bin = ReadColmapModelBinary(tmp.path() / "bin");
  EXPECT_EQ(FirstDifference(model, from_bin), "");
  EXPECT_TRUE(ReadColmapModel(tmp.path() / "bin") == model);  // detects BIN
  EXPECT_EQ(FirstDifference(model, ReadColmapModelText(tmp.path() / "txt")), "");
  EXPECT_EQ(FirstDifference(model, ReadColmapModelText(tmp.path() / "bin_txt")), "");
  // COLMAP's header comments, counts and means are what igi writes.
  for (auto [file, n] : {std::pair("cameras.txt", 3), {"images.txt", 4}, {"points3D.txt", 3}}) {
    EXPECT_EQ(HeadLines(tmp.path() / "igi_txt" / file, n), HeadLines(tmp.path() / "txt" / file, n));
  }
}

TEST(ColmapModelCrossCheck, SingleRecordFilesAreByteIdenticalToColmaps) {
  // With one record per file COLMAP's (hash-map) order cannot differ, so the bytes must match.
  TempDir tmp;
  std::mt19937_64 rng(4);
  for (int variant = 0; variant < 2; ++variant) {
    ColmapModel model;
    model.cameras[3] = {3, "OPENCV", 1920, 1080, {}};
    for (int p = 0; p < 8; ++p) model.cameras[3].params.push_back(AwkwardDouble(rng));
    model.images[5] = {5, RandomUnitQuaternion(rng), {AwkwardDouble(rng), 1e-300, -0.0},
                       3, "dir/photo_01.jpg",        {}};
    model.points3d[9] = {9, {AwkwardDouble(rng), 0.1, 3}, {1, 2, 3}, 0.7, {}};
    if (variant == 0) {
      model.images[5].points2d = {{{1.5, 2.25}, -1}, {{1e-3, 4000.123456789}, 9}};
      model.points3d[9].track = {{5, 1}};
    }
    const fs::path igi = tmp.path() / ("igi" + std::to_string(variant));
    const fs::path colmap = tmp.path() / ("colmap" + std::to_string(variant));
    WriteColmapModelText(model, igi);
    ASSERT_NO_FATAL_FAILURE(ConvertWithColmap(igi, colmap, "TXT"));
    for (const char* file : {"cameras.txt", "images.txt", "points3D.txt"}) {
      EXPECT_EQ(ReadFileToString(igi / file), ReadFileToString(colmap / file))
          << "variant " << variant << " " << file;
    }
  }
}

TEST(ColmapModelCrossCheck, RealReconstructionOfSceauxCastle) {
  // COLMAP reconstructs 4 real photos (openMVG's Sceaux castle sample, downscaled to 640 px for
  // speed); igi must read its BIN model and COLMAP's TXT export of it as the same model, and
  // COLMAP must read igi's TXT rewrite back to the same model.
  TempDir tmp;
  const fs::path photos = fs::path(IGI_SHARED_DATA_DIR) / "real/sceaux_castle";
  const fs::path images = tmp.path() / "images";
  fs::create_directories(images);
  for (const char* name : {"100_7100.JPG", "100_7101.JPG", "100_7102.JPG", "100_7103.JPG"}) {
    fs::create_symlink(photos / name, images / name);
  }
  const std::string db = (tmp.path() / "db.db").string();
  ASSERT_NO_FATAL_FAILURE(
      RunColmap("feature_extractor --database_path " + db + " --image_path " + images.string() +
                    " --ImageReader.single_camera 1 --SiftExtraction.use_gpu 0"
                    " --SiftExtraction.max_image_size 640 --SiftExtraction.num_threads 2",
                tmp.path() / "extract.log"));
  ASSERT_NO_FATAL_FAILURE(RunColmap("exhaustive_matcher --database_path " + db +
                                        " --SiftMatching.use_gpu 0 --SiftMatching.num_threads 2",
                                    tmp.path() / "match.log"));
  fs::create_directories(tmp.path() / "sparse");
  ASSERT_NO_FATAL_FAILURE(RunColmap(
      "mapper --database_path " + db + " --image_path " + images.string() + " --output_path " +
          (tmp.path() / "sparse").string() + " --Mapper.num_threads 2",
      tmp.path() / "mapper.log"));
  const fs::path bin = tmp.path() / "sparse/0";
  const ColmapModel model = ReadColmapModel(bin);
  EXPECT_EQ(model.cameras.size(), 1u);
  EXPECT_EQ(model.cameras.begin()->second.model, "SIMPLE_RADIAL");  // COLMAP's default
  EXPECT_GE(model.images.size(), 3u);
  EXPECT_GT(model.points3d.size(), 100u);
  EXPECT_NE(model.FindImageByName("100_7100.JPG"), nullptr);

  ASSERT_NO_FATAL_FAILURE(ConvertWithColmap(bin, tmp.path() / "colmap_txt", "TXT"));
  EXPECT_EQ(FirstDifference(model, ReadColmapModelText(tmp.path() / "colmap_txt")), "");
  WriteColmapModelText(model, tmp.path() / "igi_txt");
  ASSERT_NO_FATAL_FAILURE(ConvertWithColmap(tmp.path() / "igi_txt", tmp.path() / "back", "BIN"));
  EXPECT_EQ(FirstDifference(model, ReadColmapModelBinary(tmp.path() / "back")), "");
  for (const char* file : {"cameras.bin", "points3D.bin"}) {
    // Single camera: identical; points: same set (order may differ), so compare sizes.
    EXPECT_EQ(fs::file_size(bin / file), fs::file_size(tmp.path() / "back" / file)) << file;
  }
  // igi's BIN writer on COLMAP's real model: the same model back, and files of COLMAP's sizes
  // (records in id order rather than COLMAP's hash order, so the bytes themselves may differ).
  WriteColmapModelBinary(model, tmp.path() / "igi_bin");
  EXPECT_EQ(FirstDifference(model, ReadColmapModelBinary(tmp.path() / "igi_bin")), "");
  for (const char* file : {"cameras.bin", "images.bin", "points3D.bin"}) {
    EXPECT_EQ(fs::file_size(bin / file), fs::file_size(tmp.path() / "igi_bin" / file)) << file;
  }
}

// ---------------------------------------------------------------------------------------------
// Broken model folders: each must give an InputError naming the file, the line (TXT) or record
// and byte (BIN), the value and the rule.

// A valid model: 1 camera, 2 images, 1 point seen by both (line numbers matter below).
const std::map<std::string, std::string> kGoodText = {
    {"cameras.txt",
     "# Camera list with one line of data per camera:\n"
     "#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n"
     "# Number of cameras: 1\n"
     "1 PINHOLE 640 480 500 500 320 240\n"},
    {"images.txt",
     "# Image list with two lines of data per image:\n"
     "#   IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME\n"
     "#   POINTS2D[] as (X, Y, POINT3D_ID)\n"
     "# Number of images: 2, mean observations per image: 1\n"
     "1 1 0 0 0 0 0 0 1 a.jpg\n"
     "10 20 7 30 40 -1\n"
     "2 1 0 0 0 1 0 0 1 b.jpg\n"
     "11 21 7\n"},
    {"points3D.txt",
     "# 3D point list with one line of data per point:\n"
     "#   POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[] as (IMAGE_ID, POINT2D_IDX)\n"
     "# Number of points: 1, mean track length: 2\n"
     "7 0 0 5 255 128 0 0.5 1 0 2 0\n"}};

// The same model in COLMAP's binary layout (little-endian; the test assumes a little-endian
// host). Byte offsets: cameras.bin record 0 at 8 (model id at 12); images.bin record 0 at 8
// (qw at 12, name at 72, points2D count at 78), record 1 at 134; points3D.bin record 0 at 8.
std::map<std::string, std::string> GoodBinary() {
  std::string cameras, images, points;
  auto put = [](std::string& out, auto value) {
    char bytes[sizeof(value)];
    std::memcpy(bytes, &value, sizeof(value));
    out.append(bytes, sizeof(value));
  };
  put(cameras, uint64_t{1});
  put(cameras, uint32_t{1});
  put(cameras, int32_t{1});  // PINHOLE
  put(cameras, uint64_t{640});
  put(cameras, uint64_t{480});
  for (double p : {500.0, 500.0, 320.0, 240.0}) put(cameras, p);
  put(images, uint64_t{2});
  const std::array<std::tuple<uint32_t, double, const char*, double, uint64_t>, 2> rows = {
      {{1, 0.0, "a.jpg", 10.0, 7}, {2, 1.0, "b.jpg", 11.0, 7}}};
  for (const auto& [id, tx, name, x, point3d] : rows) {
    put(images, id);
    for (double v : {1.0, 0.0, 0.0, 0.0, tx, 0.0, 0.0}) put(images, v);
    put(images, uint32_t{1});
    images.append(name, std::strlen(name) + 1);
    put(images, uint64_t{id == 1 ? 2u : 1u});
    put(images, x);
    put(images, x + 10);
    put(images, point3d);
    if (id == 1) {
      for (double v : {30.0, 40.0}) put(images, v);
      put(images, ~uint64_t{0});  // -1
    }
  }
  put(points, uint64_t{1});
  put(points, uint64_t{7});
  for (double v : {0.0, 0.0, 5.0}) put(points, v);
  for (uint8_t c : {255, 128, 0}) put(points, c);
  put(points, 0.5);
  put(points, uint64_t{2});
  for (uint32_t v : {1u, 0u, 2u, 0u}) put(points, v);
  return {{"cameras.bin", cameras}, {"images.bin", images}, {"points3D.bin", points}};
}

void WriteFolder(const fs::path& dir, const std::map<std::string, std::string>& files) {
  for (const auto& [name, text] : files) WriteFileAtomic(dir / name, text);
}

void ExpectInputError(const fs::path& dir, const std::vector<std::string>& expected) {
  try {
    ReadColmapModel(dir);
    ADD_FAILURE() << dir << ": no error";
  } catch (const InputError& e) {
    for (const std::string& part : expected) {
      EXPECT_NE(std::string(e.what()).find(part), std::string::npos)
          << dir.filename() << ": expected \"" << part << "\" in:\n"
          << e.what();
    }
  }
}

TEST(ColmapModelBroken, GoodFoldersReadTheSameInTextAndBinary) {
  TempDir tmp;
  WriteFolder(tmp.path() / "txt", kGoodText);
  WriteFolder(tmp.path() / "bin", GoodBinary());
  const ColmapModel text = ReadColmapModel(tmp.path() / "txt");
  EXPECT_EQ(text.images.at(1).points2d.at(1).point3d_id, -1);
  EXPECT_EQ(text.points3d.at(7).track, (std::vector<ColmapTrackElement>{{1, 0}, {2, 0}}));
  EXPECT_EQ(FirstDifference(text, ReadColmapModel(tmp.path() / "bin")), "");
}

TEST(ColmapModelBroken, TextCorpus) {
  struct Case {
    const char* name;
    const char* file;
    std::string from, to;  // replaced in the good file; an empty `from` deletes the file
    std::vector<std::string> expected;
  };
  const std::vector<Case> cases = {
      {"unknown_model",
       "cameras.txt",
       "1 PINHOLE",
       "1 PINHOLEX",
       {"cameras.txt: line 4: PINHOLEX: unknown camera model"}},
      {"param_count",
       "cameras.txt",
       "500 500 320 240",
       "500 500 320",
       {"cameras.txt: line 4: 3 params: wrong number of params: PINHOLE needs 4"}},
      {"negative_width",
       "cameras.txt",
       "640 480",
       "-640 480",
       {"cameras.txt: line 4: -640: WIDTH must be an integer in [1, 2147483647]"}},
      {"duplicate_camera",
       "cameras.txt",
       "320 240\n",
       "320 240\n1 PINHOLE 64 48 5 5 3 2\n",
       {"cameras.txt: line 5: 1: duplicate CAMERA_ID (first on line 4)"}},
      {"non_numeric",
       "images.txt",
       "10 20 7",
       "10 2O 7",
       {"images.txt: line 6: 2O: POINTS2D[0] Y is not a finite number"}},
      {"non_unit_quaternion",
       "images.txt",
       "2 1 0 0 0",
       "2 1 0.5 0 0",
       {"images.txt: line 7: |q| = 1.118", "non-unit quaternion"}},
      {"missing_camera",
       "images.txt",
       "0 0 1 b.jpg",
       "0 0 3 b.jpg",
       {"images.txt: line 7: CAMERA_ID 3: image references a missing camera"}},
      {"missing_point3d",
       "images.txt",
       "11 21 7",
       "11 21 8",
       {"images.txt: line 7: POINTS2D[0] POINT3D_ID 8: 2D point references a missing 3D point"}},
      {"not_triples",
       "images.txt",
       "11 21 7",
       "11 21",
       {"images.txt: line 8: 2 values: POINTS2D[] must be (X, Y, POINT3D_ID) triples"}},
      {"duplicate_name",
       "images.txt",
       "b.jpg",
       "a.jpg",
       {"images.txt: line 7: a.jpg: duplicate NAME (also IMAGE_ID 1)"}},
      {"track_missing_image",
       "points3D.txt",
       "1 0 2 0",
       "1 0 5 0",
       {"points3D.txt: line 4: TRACK IMAGE_ID 5: track references a missing image"}},
      {"track_missing_point2d",
       "points3D.txt",
       "1 0 2 0",
       "1 0 2 4",
       {"points3D.txt: line 4: TRACK (IMAGE_ID 2, POINT2D_IDX 4): track references a missing 2D "
        "point (that image has 1)"}},
      {"colour_range",
       "points3D.txt",
       "255 128",
       "256 128",
       {"points3D.txt: line 4: 256: R must be an integer in [0, 255]"}},
      {"odd_track",
       "points3D.txt",
       "1 0 2 0",
       "1 0 2",
       {"points3D.txt: line 4: 11 values: a 3D point line needs"}},
      {"missing_file", "points3D.txt", "", "", {"points3D.txt: missing file"}},
  };
  TempDir tmp;
  for (const Case& c : cases) {
    const fs::path dir = tmp.path() / c.name;
    std::map<std::string, std::string> files = kGoodText;
    if (c.from.empty()) {
      files.erase(c.file);
    } else {
      std::string& text = files.at(c.file);
      const size_t at = text.find(c.from);
      ASSERT_NE(at, std::string::npos) << c.name;
      text.replace(at, c.from.size(), c.to);
    }
    WriteFolder(dir, files);
    ExpectInputError(dir, c.expected);
  }
}

TEST(ColmapModelBroken, BinaryCorpus) {
  struct Case {
    const char* name;
    const char* file;
    std::function<void(std::string&)> mutate;
    std::vector<std::string> expected;
  };
  auto put_at = [](size_t offset, auto value) {
    return [offset, value](std::string& bytes) {
      std::memcpy(bytes.data() + offset, &value, sizeof(value));
    };
  };
  auto truncate = [](size_t size) { return [size](std::string& bytes) { bytes.resize(size); }; };
  const std::vector<Case> cases = {
      {"truncated_params",
       "cameras.bin",
       truncate(40),
       {"cameras.bin: camera record 0 (byte 8): 8 bytes needed at byte 40, file has 40: "
        "truncated file"}},
      {"unknown_model_id",
       "cameras.bin",
       put_at(12, int32_t{42}),
       {"cameras.bin: camera record 0 (byte 8): model id 42: unknown camera model"}},
      {"truncated_name",
       "images.bin",
       truncate(203),
       {"images.bin: image record 1 (byte 134): NAME starting at byte 198 has no terminating "
        "NUL: truncated file"}},
      {"count_beyond_file",
       "images.bin",
       truncate(75),
       {"images.bin: header (byte 0): 2 images need at least 146 bytes, 67 left: truncated file "
        "or corrupt count"}},
      {"huge_count",
       "images.bin",
       put_at(78, uint64_t{1} << 60),
       {"images.bin: image record 0 (byte 8): 1152921504606846976 points2D need at least",
        "truncated file or corrupt count"}},
      {"non_unit_quaternion",
       "images.bin",
       put_at(12, 2.0),
       {"images.bin: image record 0 (byte 8): |q| = 2: non-unit quaternion"}},
      {"missing_camera",
       "images.bin",
       put_at(134 + 60, uint32_t{9}),
       {"images.bin: image record 1 (byte 134): CAMERA_ID 9: image references a missing camera"}},
      {"track_missing_image",
       "points3D.bin",
       put_at(8 + 8 + 24 + 3 + 8 + 8 + 8, uint32_t{99}),
       {"points3D.bin: point record 0 (byte 8): TRACK IMAGE_ID 99: track references a missing "
        "image"}},
      {"trailing_bytes",
       "points3D.bin",
       [](std::string& bytes) { bytes += "abc"; },
       {"points3D.bin: byte 75: 3 bytes: trailing bytes after the last record"}},
      {"empty_file",
       "points3D.bin",
       truncate(0),
       {"points3D.bin: header (byte 0): 8 bytes needed at byte 0, file has 0: truncated file"}},
  };
  TempDir tmp;
  for (const Case& c : cases) {
    std::map<std::string, std::string> files = GoodBinary();
    c.mutate(files.at(c.file));
    WriteFolder(tmp.path() / c.name, files);
    ExpectInputError(tmp.path() / c.name, c.expected);
  }
}

TEST(ColmapModelBroken, ListsEveryProblemAndNamesMissingFiles) {
  TempDir tmp;
  std::map<std::string, std::string> files = kGoodText;
  files["cameras.txt"] += "2 FISHEYE 1 1 1\n3 PINHOLE 1 1 x 1 1 1\n";
  WriteFolder(tmp.path() / "two", files);
  try {
    ReadColmapModelText(tmp.path() / "two");
    FAIL() << "no error";
  } catch (const InputError& e) {
    ASSERT_EQ(e.problems().size(), 2u) << e.what();
    EXPECT_NE(e.problems()[0].find("line 5: FISHEYE: unknown camera model"), std::string::npos);
    EXPECT_NE(e.problems()[1].find("line 6: x: PARAMS[0] is not a finite number"),
              std::string::npos);
  }
  // An empty folder: every missing .txt file is named.
  fs::create_directories(tmp.path() / "empty");
  try {
    ReadColmapModel(tmp.path() / "empty");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.problems().size(), 3u) << e.what();
  }
}

// ---------------------------------------------------------------------------------------------
// The BIN and PLY writers

// The three files of a model folder, by name.
std::map<std::string, std::string> ReadFolder(const fs::path& dir, const char* extension) {
  std::map<std::string, std::string> files;
  for (const char* stem : {"cameras", "images", "points3D"}) {
    const std::string name = std::string(stem) + extension;
    files[name] = ReadFileToString(dir / name);
  }
  return files;
}

// A binary PLY point cloud as COLMAP writes it: its header text and its (x, y, z, r, g, b)
// records.
struct PlyPoints {
  std::string header;
  std::vector<std::tuple<float, float, float, uint8_t, uint8_t, uint8_t>> records;
};

PlyPoints ReadPlyPoints(const fs::path& path) {
  const std::string bytes = ReadFileToString(path);
  const std::string end = "end_header\n";
  const size_t at = bytes.find(end);
  if (at == std::string::npos) throw std::runtime_error(path.string() + ": no end_header");
  PlyPoints ply;
  ply.header = bytes.substr(0, at + end.size());
  const size_t kRecordBytes = 3 * sizeof(float) + 3;
  for (size_t pos = ply.header.size(); pos + kRecordBytes <= bytes.size(); pos += kRecordBytes) {
    float xyz[3];
    std::memcpy(xyz, bytes.data() + pos, sizeof(xyz));  // little-endian host assumed
    const auto* rgb = reinterpret_cast<const uint8_t*>(bytes.data() + pos + sizeof(xyz));
    ply.records.emplace_back(xyz[0], xyz[1], xyz[2], rgb[0], rgb[1], rgb[2]);
  }
  if ((bytes.size() - ply.header.size()) % kRecordBytes != 0) {
    throw std::runtime_error(path.string() + ": a partial record at the end");
  }
  return ply;
}

// The synthetic model with every coordinate scaled into float's range, for the PLY.
ColmapModel MakeSyntheticModelForPly(uint64_t seed) {
  ColmapModel model = MakeSyntheticModel(seed);
  for (auto& [id, point] : model.points3d) {
    for (int k = 0; k < 3; ++k) {
      if (std::abs(point.xyz[k]) > 1e30) point.xyz[k] = std::copysign(1e30, point.xyz[k]);
    }
  }
  return model;
}

TEST(ColmapModelBinary, WriteReadIsBitExactAndRewriteIsIdentical) {
  // Every camera model, sparse and extreme ids, names with folders and non-ASCII letters, an
  // image without 2D points, 2D points with and without 3D points, tracks of 0 to 4 elements.
  TempDir tmp;
  const ColmapModel model = MakeSyntheticModel(5);
  WriteColmapModelBinary(model, tmp.path() / "a");
  const ColmapModel read = ReadColmapModelBinary(tmp.path() / "a");
  EXPECT_EQ(FirstDifference(model, read), "");
  EXPECT_TRUE(read == model);
  EXPECT_TRUE(ReadColmapModel(tmp.path() / "a") == model);  // detects BIN
  // == cannot tell -0.0 from 0.0; the rewrite's bytes can.
  WriteColmapModelBinary(read, tmp.path() / "b");
  EXPECT_EQ(ReadFolder(tmp.path() / "a", ".bin"), ReadFolder(tmp.path() / "b", ".bin"));
}

TEST(ColmapModelBinary, WritesColmapsByteLayout) {
  // The good folder of the broken-folder corpus, whose bytes are laid out by hand from COLMAP's
  // format (a -1 point id stored as 2^64 - 1 among them).
  TempDir tmp;
  WriteFolder(tmp.path() / "txt", kGoodText);
  WriteColmapModelBinary(ReadColmapModelText(tmp.path() / "txt"), tmp.path() / "bin");
  EXPECT_EQ(ReadFolder(tmp.path() / "bin", ".bin"), GoodBinary());
}

TEST(ColmapModelBinary, TextToBinaryToTextIsIdentical) {
  TempDir tmp;
  WriteColmapModelText(MakeSyntheticModel(6), tmp.path() / "txt");
  WriteColmapModelBinary(ReadColmapModelText(tmp.path() / "txt"), tmp.path() / "bin");
  WriteColmapModelText(ReadColmapModelBinary(tmp.path() / "bin"), tmp.path() / "txt2");
  EXPECT_EQ(ReadFolder(tmp.path() / "txt", ".txt"), ReadFolder(tmp.path() / "txt2", ".txt"));
}

TEST(ColmapModelBinary, WriterValidatesFirstAndWritesNothingOnError) {
  TempDir tmp;
  ColmapModel model = MakeSyntheticModel(7);
  model.points3d.begin()->second.track.push_back({4000000000u, 100000});
  try {
    WriteColmapModelBinary(model, tmp.path() / "out");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("points3D.bin: POINT3D_ID"), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("track references a missing 2D point"), std::string::npos)
        << e.what();
  }
  EXPECT_FALSE(fs::exists(tmp.path() / "out"));
}

TEST(ColmapModelPly, HeaderAndValuesReadBack) {
  TempDir tmp;
  const ColmapModel model = MakeSyntheticModelForPly(8);
  WriteColmapPointsPly(model, tmp.path() / "points.ply");
  const PlyPoints ply = ReadPlyPoints(tmp.path() / "points.ply");
  EXPECT_EQ(ply.header,
            "ply\nformat binary_little_endian 1.0\nelement vertex 40\nproperty float x\n"
            "property float y\nproperty float z\nproperty uchar red\nproperty uchar green\n"
            "property uchar blue\nend_header\n");
  ASSERT_EQ(ply.records.size(), model.points3d.size());
  size_t i = 0;
  for (const auto& [id, point] : model.points3d) {  // id order; values exact after float rounding
    const auto& [x, y, z, r, g, b] = ply.records[i++];
    EXPECT_EQ(x, static_cast<float>(point.xyz[0])) << id;
    EXPECT_EQ(y, static_cast<float>(point.xyz[1])) << id;
    EXPECT_EQ(z, static_cast<float>(point.xyz[2])) << id;
    EXPECT_EQ((std::array<uint8_t, 3>{r, g, b}), point.rgb) << id;
  }
}

TEST(ColmapModelPly, RejectsCoordinatesBeyondFloatAndWritesNothing) {
  TempDir tmp;
  ColmapModel model = MakeSyntheticModelForPly(9);
  model.points3d.at(114).xyz.y() = 1e300;
  try {
    WriteColmapPointsPly(model, tmp.path() / "points.ply");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("points.ply: POINT3D_ID 114:"), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("within float range"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(tmp.path() / "points.ply"));
}

TEST(ColmapModelCrossCheck, ColmapReadsIgiBinary) {
  // COLMAP's model_converter reads igi's BIN and writes TXT and BIN that igi reads back as the
  // same model: the independent check that igi's layout is COLMAP's.
  TempDir tmp;
  const ColmapModel model = MakeSyntheticModel(10);
  WriteColmapModelBinary(model, tmp.path() / "igi_bin");
  ASSERT_NO_FATAL_FAILURE(ConvertWithColmap(tmp.path() / "igi_bin", tmp.path() / "txt", "TXT"));
  ASSERT_NO_FATAL_FAILURE(ConvertWithColmap(tmp.path() / "igi_bin", tmp.path() / "bin", "BIN"));
  EXPECT_EQ(FirstDifference(model, ReadColmapModelText(tmp.path() / "txt")), "");
  EXPECT_EQ(FirstDifference(model, ReadColmapModelBinary(tmp.path() / "bin")), "");
  // COLMAP's counts and means of igi's BIN are those igi writes.
  WriteColmapModelText(model, tmp.path() / "igi_txt");
  for (auto [file, n] : {std::pair("cameras.txt", 3), {"images.txt", 4}, {"points3D.txt", 3}}) {
    EXPECT_EQ(HeadLines(tmp.path() / "igi_txt" / file, n), HeadLines(tmp.path() / "txt" / file, n));
  }
}

TEST(ColmapModelCrossCheck, SingleRecordBinaryAndPlyAreByteIdenticalToColmaps) {
  // With one record per file COLMAP's order cannot differ: its BIN and PLY from igi's BIN must be
  // igi's bytes. Several cameras of a larger model are compared as PLY record sets below.
  TempDir tmp;
  std::mt19937_64 rng(11);
  ColmapModel model;
  model.cameras[3] = {3, "FULL_OPENCV", 4000, 3000, {}};
  for (int p = 0; p < 12; ++p) model.cameras[3].params.push_back(AwkwardDouble(rng));
  model.images[5] = {
      5, RandomUnitQuaternion(rng), {AwkwardDouble(rng), 1e-300, -0.0},
      3, "dir/photo_01.jpg",        {{{1.5, 2.25}, -1}, {{1e-3, 4000.123456789}, 9}}};
  model.points3d[9] = {9, {-1.25, 0.1, 3e7}, {1, 2, 250}, 0.7, {{5, 1}}};
  WriteColmapModelBinary(model, tmp.path() / "igi");
  WriteColmapPointsPly(model, tmp.path() / "igi.ply");
  ASSERT_NO_FATAL_FAILURE(ConvertWithColmap(tmp.path() / "igi", tmp.path() / "colmap", "BIN"));
  ASSERT_NO_FATAL_FAILURE(ConvertWithColmap(tmp.path() / "igi", tmp.path() / "colmap.ply", "PLY"));
  EXPECT_EQ(ReadFolder(tmp.path() / "igi", ".bin"), ReadFolder(tmp.path() / "colmap", ".bin"));
  EXPECT_EQ(ReadFileToString(tmp.path() / "igi.ply"), ReadFileToString(tmp.path() / "colmap.ply"));

  // Many points: the same header and the same set of records.
  const ColmapModel many = MakeSyntheticModelForPly(12);
  WriteColmapModelBinary(many, tmp.path() / "many");
  WriteColmapPointsPly(many, tmp.path() / "many_igi.ply");
  ASSERT_NO_FATAL_FAILURE(
      ConvertWithColmap(tmp.path() / "many", tmp.path() / "many_colmap.ply", "PLY"));
  PlyPoints igi = ReadPlyPoints(tmp.path() / "many_igi.ply");
  PlyPoints colmap = ReadPlyPoints(tmp.path() / "many_colmap.ply");
  EXPECT_EQ(igi.header, colmap.header);
  std::sort(igi.records.begin(), igi.records.end());
  std::sort(colmap.records.begin(), colmap.records.end());
  EXPECT_EQ(igi.records, colmap.records);
}

}  // namespace
}  // namespace igi::recon
