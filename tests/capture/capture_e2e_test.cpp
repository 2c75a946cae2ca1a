// End-to-end tests of igi-capture against a real GigE Vision protocol peer:
// Aravis's fake camera (arv-fake-gv-camera-0.8 from Debian's aravis-tools),
// started here on 127.0.0.1 and always killed at the end of each test. Each
// test process gets its own network namespace when the system allows it (see
// fake_camera.h), so tests never see each other's cameras.
//
// The fake camera draws a known pattern: level(x, y) = clamp(((x + y +
// frame_id) % 255) * s, 0, 255) with s = 1 + gain + log10(exposure_us / 10000),
// in Mono8. A frame whose content matches its manifest line's exposure and
// frame_id therefore proves that the manifest tells the truth and that no frame
// from before an exposure change slipped through settling.

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <set>
#include <thread>

#include "tests/capture/fake_camera.h"
#include "tools/common/image.h"
#include "tools/common/json.h"

namespace igi::capture::testing {
namespace {
namespace fs = std::filesystem;

const std::string kCapture = std::string(IGI_BIN_DIR) + "/igi-capture";
// Small, fast frames: the tests take a few seconds each.
const std::vector<std::string> kFast = {"--width",      "32",  "--height",       "16",
                                        "--frame-rate", "100", "--pixel-format", "Mono8",
                                        "--timeout-ms", "500"};

class CaptureE2eTest : public ::testing::Test {
 protected:
  void SetUp() override {
    IsolateFakeCameras();
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("igi_capture_e2e_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    out_ = dir_ / "out";
    ASSERT_FALSE(GvcpPortInUse()) << "another GigE camera emulator is on 127.0.0.1:3956";
  }
  void TearDown() override {
    camera_.reset();  // kills the fake camera
    if (!HasFailure()) fs::remove_all(dir_);
  }
  void StartCamera(const std::string& serial, const std::vector<std::string>& extra = {}) {
    camera_ = std::make_unique<FakeCamera>(serial, dir_ / "fake_camera.log", extra);
    ASSERT_TRUE(camera_->ready()) << ReadText(dir_ / "fake_camera.log");
  }
  std::vector<std::string> CaptureArgs(const std::vector<std::string>& args) const {
    std::vector<std::string> all = {kCapture, "--camera", "127.0.0.1", "--out", out_.string()};
    all.insert(all.end(), kFast.begin(), kFast.end());
    all.insert(all.end(), args.begin(), args.end());
    return all;
  }
  std::vector<Json> Manifest() const {
    std::vector<Json> lines;
    std::istringstream text(ReadText(out_ / "manifest.jsonl"));
    std::string line;
    while (std::getline(text, line)) lines.push_back(Json::parse(line));
    return lines;
  }

  fs::path dir_;
  fs::path out_;
  std::unique_ptr<FakeCamera> camera_;
};

// Fraction of pixels of the frame a manifest line names that match the fake
// camera's pattern for the line's exposure, gain and frame id (exact: 8-bit
// levels stored as level * 257).
double PatternMatch(const fs::path& out, const Json& line) {
  const Image image = ReadImage(out / line["file"].get<std::string>());
  const double scale =
      1.0 + line["gain"].get<double>() + std::log10(line["exposure_us"].get<double>() / 10000.0);
  const uint64_t frame_id = line["frame_id"].get<uint64_t>();
  size_t matches = 0;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      const double value = double((uint64_t(x + y) + frame_id) % 255) * scale;
      const int expected = value < 0 ? 0 : value > 255 ? 255 : int(value);
      const int stored = int(std::lround(image.at(x, y) * 65535.0));
      if (stored == expected * 257) {
        ++matches;
      } else if (std::getenv("IGI_TEST_DEBUG")) {
        std::fprintf(stderr, "%s (%d,%d): stored %d expected %d\n", line.dump().c_str(), x, y,
                     stored / 257, expected);
      }
    }
  }
  return double(matches) / double(image.width * image.height);
}

TEST_F(CaptureE2eTest, ListShowsTheCameraWithModelAndAddress) {
  StartCamera("IGIL1");
  std::string output;
  ASSERT_EQ(RunProcess({kCapture, "--list"}, 15, &output), 0) << output;
  EXPECT_NE(output.find("Aravis-Fake-IGIL1"), std::string::npos) << output;
  EXPECT_NE(output.find("Aravis Fake"), std::string::npos) << output;
  EXPECT_NE(output.find("127.0.0.1"), std::string::npos) << output;
}

TEST_F(CaptureE2eTest, BracketListsTheRightExposuresAndFramesMatchThem) {
  StartCamera("IGIB1");
  std::string output;
  // Opened by id: igi-capture resolves it to the camera's address.
  // At 1000 frames/s frames queue up while igi-capture writes, so frames
  // exposed before each change are waiting in the stream when it happens:
  // settling must drop them.
  std::vector<std::string> args =
      CaptureArgs({"--exposures-us", "10000,20000,50000", "--frames", "3", "--frame-rate", "1000"});
  args[2] = "Aravis-Fake-IGIB1";
  ASSERT_EQ(RunProcess(args, 20, &output), 0) << output;
  const std::vector<Json> lines = Manifest();
  ASSERT_EQ(lines.size(), 9u);
  const double expected_us[] = {10000, 20000, 50000};
  for (size_t i = 0; i < lines.size(); ++i) {
    const Json& line = lines[i];
    SCOPED_TRACE(line.dump());
    EXPECT_EQ(line["bracket"], int(i / 3));
    EXPECT_EQ(line["frame"], int(i % 3));
    EXPECT_DOUBLE_EQ(line["exposure_us"].get<double>(), expected_us[i / 3]);
    EXPECT_EQ(line["camera"], "Aravis-Fake-IGIB1");
    EXPECT_EQ(line["pixel_format"], "Mono8");
    EXPECT_DOUBLE_EQ(line["gain"].get<double>(), 0.0);
    EXPECT_TRUE(line["timestamp"].is_string());
    EXPECT_EQ(PatternMatch(out_, line), 1.0);
  }
}

TEST_F(CaptureE2eTest, CameraKilledMidBracketThenRestartedAndResumed) {
  StartCamera("IGIK1");
  const fs::path log = dir_ / "capture.log";
  // 2 x 40 frames at 20 frames/s: about 4 s, killed after the first few frames.
  std::vector<std::string> args =
      CaptureArgs({"--exposures-us", "10000,30000", "--frames", "40", "--frame-rate", "20"});
  ChildProcess capture(args, log);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (std::chrono::steady_clock::now() < deadline &&
         (!fs::exists(out_ / "manifest.jsonl") || Manifest().size() < 5)) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  camera_->Kill();
  ASSERT_EQ(capture.Wait(15), 3) << ReadText(log);
  EXPECT_NE(ReadText(log).find("--resume"), std::string::npos) << ReadText(log);
  const std::vector<Json> before = Manifest();
  ASSERT_GE(before.size(), 5u);
  ASSERT_LT(before.size(), 80u);
  for (const Json& line : before) EXPECT_EQ(PatternMatch(out_, line), 1.0) << line.dump();
  const std::string manifest_before = ReadText(out_ / "manifest.jsonl");

  StartCamera("IGIK1");
  std::string output;
  args = {kCapture,   "--camera",     "127.0.0.1", "--out",        out_.string(),
          "--resume", "--frame-rate", "100",       "--timeout-ms", "500"};
  ASSERT_EQ(RunProcess(args, 20, &output), 0) << output;
  const std::vector<Json> after = Manifest();
  ASSERT_EQ(after.size(), 80u);
  // Append-only: the lines of the first run are untouched; every slot appears
  // exactly once.
  EXPECT_EQ(ReadText(out_ / "manifest.jsonl").substr(0, manifest_before.size()), manifest_before);
  std::set<std::pair<int, int>> slots;
  for (const Json& line : after) {
    slots.insert({line["bracket"].get<int>(), line["frame"].get<int>()});
    EXPECT_EQ(PatternMatch(out_, line), 1.0) << line.dump();
  }
  EXPECT_EQ(slots.size(), 80u);
}

TEST_F(CaptureE2eTest, CameraThatDoesNotAnswerFailsAndWritesNothing) {
  std::string output;
  const auto start = std::chrono::steady_clock::now();
  const int code = RunProcess(CaptureArgs({"--exposures-us", "1000"}), 20, &output);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(code, 1) << output;
  EXPECT_NE(output.find("does not answer"), std::string::npos) << output;
  EXPECT_FALSE(fs::exists(out_)) << "nothing may be written";
  EXPECT_LT(seconds, 15.0);
}

TEST_F(CaptureE2eTest, LostPacketsEndTheRunWithExit3) {
  // The fake camera drops every packet; without resends no frame can complete.
  StartCamera("IGIP1", {"-r", "1000"});
  std::string output;
  const int code = RunProcess(
      CaptureArgs({"--exposures-us", "10000", "--frames", "3", "--no-packet-resend"}), 20, &output);
  EXPECT_EQ(code, 3) << output;
  EXPECT_NE(output.find("--resume"), std::string::npos) << output;
}

// A frame file that cannot be put in place (here a folder is in its way) ends
// the run with exit 3: the frames written before it are intact and listed, it
// is not, and --resume finishes the plan once the obstacle is gone.
TEST_F(CaptureE2eTest, AFrameThatCannotBeWrittenEndsTheRunWithExit3AndResumes) {
  StartCamera("IGIW1");
  const fs::path blocker = out_ / "frames" / "b00_e000010000us_f003.png";
  fs::create_directories(blocker / "in_the_way");
  std::string output;
  ASSERT_EQ(RunProcess(CaptureArgs({"--exposures-us", "10000", "--frames", "8"}), 20, &output), 3)
      << output;
  EXPECT_NE(output.find("could not be written"), std::string::npos) << output;
  EXPECT_NE(output.find("--resume"), std::string::npos) << output;
  std::vector<Json> lines = Manifest();
  ASSERT_GE(lines.size(), 3u);
  ASSERT_LT(lines.size(), 8u);
  for (size_t i = 0; i < lines.size(); ++i) {
    SCOPED_TRACE(lines[i].dump());
    if (i < 3) {
      EXPECT_EQ(lines[i]["frame"], int(i));
    }
    EXPECT_NE(lines[i]["frame"], 3);
    EXPECT_EQ(PatternMatch(out_, lines[i]), 1.0);
  }
  fs::remove_all(blocker);
  ASSERT_EQ(RunProcess(CaptureArgs({"--resume"}), 20, &output), 0) << output;
  lines = Manifest();
  std::set<int> frames;
  for (const Json& line : lines) {
    frames.insert(line["frame"].get<int>());
    EXPECT_EQ(PatternMatch(out_, line), 1.0) << line.dump();
  }
  EXPECT_EQ(lines.size(), 8u);
  EXPECT_EQ(frames.size(), 8u);
}

TEST_F(CaptureE2eTest, ExistingCaptureIsNotOverwrittenWithoutResume) {
  StartCamera("IGIR1");
  std::string output;
  ASSERT_EQ(RunProcess(CaptureArgs({"--exposures-us", "10000"}), 20, &output), 0) << output;
  const std::string manifest = ReadText(out_ / "manifest.jsonl");
  EXPECT_EQ(RunProcess(CaptureArgs({"--exposures-us", "20000"}), 20, &output), 2) << output;
  EXPECT_EQ(ReadText(out_ / "manifest.jsonl"), manifest);
  // Resuming a finished plan takes nothing more.
  EXPECT_EQ(RunProcess(CaptureArgs({"--resume"}), 20, &output), 0) << output;
  EXPECT_EQ(ReadText(out_ / "manifest.jsonl"), manifest);
}

TEST_F(CaptureE2eTest, AutoChoosesABracketFromUnclippedHighlights) {
  StartCamera("IGIA1");
  std::string output;
  // 256 x 256 shows the whole ramp (levels 0 … 254 at s = 1).
  std::vector<std::string> args = CaptureArgs({"--auto", "--stop-spacing", "2", "--max-exposure-us",
                                               "1000000", "--width", "256", "--height", "256"});
  ASSERT_EQ(RunProcess(args, 30, &output), 0) << output;
  const Json plan = ReadJsonFile(out_ / "plan.json");
  const std::vector<double> exposures = plan["exposures_us"].get<std::vector<double>>();
  ASSERT_GE(exposures.size(), 2u) << plan.dump();
  // The fake camera's levels grow with log10(exposure), so its shadows never
  // reach the target: the bracket runs from the highlight limit up to
  // --max-exposure-us in 2-stop steps.
  EXPECT_DOUBLE_EQ(exposures.back(), 1e6);
  for (size_t i = 1; i + 1 < exposures.size(); ++i) {
    EXPECT_NEAR(std::log2(exposures[i] / exposures[i - 1]), 2.0, 1e-9);
  }
  // Highlights of the shortest exposure: s = 1 + log10(e / 10^4) must keep 254
  // * s under the 0.85 target, and come within a quarter stop of it (the
  // metering's stopping rule).
  const double scale = 1.0 + std::log10(exposures.front() / 10000.0);
  EXPECT_LE(254.0 * scale, 0.85 * 255.0 + 1.0);
  EXPECT_GE(254.0 * scale, 0.84 * 0.85 * 255.0 - 1.0);
  EXPECT_EQ(Manifest().size(), exposures.size());
}

TEST_F(CaptureE2eTest, GainAndPixelFormatAreSettable) {
  StartCamera("IGIG1");
  std::string output;
  // Gain 1 raises the pattern's scale by 1: the content proves the camera applied it.
  ASSERT_EQ(RunProcess(CaptureArgs({"--exposures-us", "5000", "--gain", "1"}), 20, &output), 0)
      << output;
  std::vector<Json> lines = Manifest();
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_DOUBLE_EQ(lines[0]["gain"].get<double>(), 1.0);
  EXPECT_EQ(PatternMatch(out_, lines[0]), 1.0);
  fs::remove_all(out_);
  ASSERT_EQ(
      RunProcess(CaptureArgs({"--exposures-us", "5000", "--pixel-format", "Mono16"}), 20, &output),
      0)
      << output;
  lines = Manifest();
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_EQ(lines[0]["pixel_format"], "Mono16");
  EXPECT_EQ(lines[0]["significant_bits"], 16);
  EXPECT_EQ(ReadImageInfo(out_ / lines[0]["file"].get<std::string>()).bits_per_sample, 16);
  // A format the camera lacks is bad usage: exit 2, nothing written.
  fs::remove_all(out_);
  EXPECT_EQ(
      RunProcess(CaptureArgs({"--exposures-us", "5000", "--pixel-format", "Mono12"}), 20, &output),
      2)
      << output;
  EXPECT_FALSE(fs::exists(out_ / "manifest.jsonl"));
}

TEST_F(CaptureE2eTest, FromRawImportsIntoTheSameLayout) {
  std::string output;
  const std::string raw_dir = std::string(IGI_SHARED_DATA_DIR) + "/real/raw";
  ASSERT_EQ(RunProcess({kCapture, "--from-raw", raw_dir, "--out", out_.string()}, 20, &output), 0)
      << output;
  const std::vector<Json> lines = Manifest();
  ASSERT_EQ(lines.size(), 2u);
  for (const Json& line : lines) {
    for (const char* key : {"file", "camera", "exposure_us", "gain", "pixel_format", "timestamp"}) {
      EXPECT_TRUE(line.contains(key)) << key << " in " << line.dump();
    }
    EXPECT_TRUE(fs::exists(out_ / line["file"].get<std::string>()));
  }
  // A folder that does not exist is bad usage: exit 2, nothing written.
  const fs::path other = dir_ / "other";
  EXPECT_EQ(
      RunProcess({kCapture, "--from-raw", (dir_ / "missing").string(), "--out", other.string()}, 20,
                 &output),
      2)
      << output;
  EXPECT_FALSE(fs::exists(other));
}

}  // namespace
}  // namespace igi::capture::testing
