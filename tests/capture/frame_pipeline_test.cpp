#include "capture/frame_pipeline.h"

#include <gtest/gtest.h>

#include <atomic>
#include <filesystem>
#include <set>
#include <thread>

#include "capture/frame_writer.h"
#include "tests/temp_dir.h"
#include "tools/common/error.h"

namespace igi::capture {
namespace {
namespace fs = std::filesystem;

// A 16 x 8 Mono8 frame whose levels encode `index`.
FrameJob MakeJob(const fs::path& dir, int index) {
  FrameJob job;
  job.frame.width = 16;
  job.frame.height = 8;
  job.frame.format = *FindPixelFormat("Mono8");
  job.frame.data.assign(16 * 8, uint8_t(index % 256));
  job.frame.frame_id = uint64_t(index + 1);
  job.file = dir / "frames" / ("f" + std::to_string(index) + ".tif");
  job.entry.file = "frames/f" + std::to_string(index) + ".tif";
  job.entry.camera = "test";
  job.entry.pixel_format = "Mono8";
  job.entry.exposure_us = 1000.0;
  job.entry.frame = index;
  return job;
}

std::vector<int> ListedFrames(const fs::path& manifest) {
  std::vector<int> frames;
  if (!fs::exists(manifest)) return frames;
  for (const ManifestEntry& entry : ReadManifest(manifest).entries) frames.push_back(entry.frame);
  return frames;
}

// Later frames are written faster than earlier ones, so the writers finish out
// of order; the manifest must still list them in push order, each line only
// once its file is in place.
TEST(FramePipeline, ListsEveryFrameInPushOrderAfterItsFileIsInPlace) {
  const fs::path dir = test::UniqueTempDir("igi_frame_pipeline");
  fs::create_directories(dir / "frames");
  constexpr int kFrames = 40;
  FramePipelineOptions options;
  options.manifest_path = dir / "manifest.jsonl";
  options.writer_threads = 4;
  options.durable = false;
  options.write_file = [](const fs::path& path, const Frame& frame) {
    const int index = frame.data[0];
    std::this_thread::sleep_for(std::chrono::microseconds(200 * (kFrames - index) % 3000));
    WriteFrame(path, frame, /*durable=*/false);
  };
  std::atomic<int> missing_files{0};
  std::atomic<int> callbacks{0};
  FramePipeline pipeline(options, [&](int listed) {
    ++callbacks;
    const std::string file = "f" + std::to_string(listed - 1) + ".tif";
    if (!fs::exists(dir / "frames" / file)) ++missing_files;
  });
  for (int i = 0; i < kFrames; ++i) ASSERT_TRUE(pipeline.Push(MakeJob(dir, i)));
  pipeline.Finish();
  EXPECT_FALSE(pipeline.error());
  EXPECT_EQ(pipeline.frames_listed(), kFrames);
  EXPECT_EQ(callbacks.load(), kFrames);
  EXPECT_EQ(missing_files.load(), 0);
  std::vector<int> expected(kFrames);
  for (int i = 0; i < kFrames; ++i) expected[size_t(i)] = i;
  EXPECT_EQ(ListedFrames(options.manifest_path), expected);
  // No temporary file is left behind: exactly the frames.
  int files = 0;
  for ([[maybe_unused]] const auto& item : fs::directory_iterator(dir / "frames")) ++files;
  EXPECT_EQ(files, kFrames);
  EXPECT_FALSE(pipeline.Push(MakeJob(dir, 99))) << "no frame after Finish";
  fs::remove_all(dir);
}

// A frame that cannot be written stops the pipeline: it is never listed, what
// was written before keeps its lines (in order), and Push says so.
TEST(FramePipeline, AWriteFailureStopsThePipelineAndKeepsWhatWasWritten) {
  const fs::path dir = test::UniqueTempDir("igi_frame_pipeline");
  fs::create_directories(dir / "frames");
  FramePipelineOptions options;
  options.manifest_path = dir / "manifest.jsonl";
  options.writer_threads = 2;
  options.durable = false;
  options.write_file = [](const fs::path& path, const Frame& frame) {
    if (frame.data[0] == 5) throw Error(path.string() + ": cannot write: disk full");
    WriteFrame(path, frame, /*durable=*/false);
  };
  options.queue_bytes = 4 * 16 * 8;  // four frames: Push soon waits
  FramePipeline pipeline(options);
  int pushed = 0;
  for (int i = 0; i < 100000; ++i) {
    if (!pipeline.Push(MakeJob(dir, i % 200))) break;
    ++pushed;
  }
  pipeline.Finish();
  ASSERT_TRUE(pipeline.error());
  EXPECT_NE(pipeline.error()->find("disk full"), std::string::npos);
  EXPECT_LT(pushed, 100000) << "Push must refuse frames once a write failed";
  const std::vector<int> listed = ListedFrames(options.manifest_path);
  EXPECT_EQ(int(listed.size()), pipeline.frames_listed());
  ASSERT_GE(listed.size(), 5u);
  for (int i = 0; i < 5; ++i) EXPECT_EQ(listed[size_t(i)], i);
  std::set<int> seen;
  for (size_t i = 0; i < listed.size(); ++i) {
    EXPECT_NE(listed[i], 5) << "the failed frame must not be listed";
    if (i > 0) {
      EXPECT_GT(listed[i], listed[i - 1]) << "push order";
    }
    EXPECT_TRUE(fs::exists(dir / "frames" / ("f" + std::to_string(listed[i]) + ".tif")));
  }
  EXPECT_FALSE(fs::exists(dir / "frames" / "f5.tif"));
  fs::remove_all(dir);
}

// A manifest that cannot be appended to is a failure too (not a lost line).
TEST(FramePipeline, AManifestFailureIsReported) {
  const fs::path dir = test::UniqueTempDir("igi_frame_pipeline");
  fs::create_directories(dir / "frames");
  FramePipelineOptions options;
  options.manifest_path = dir / "no_such_folder" / "manifest.jsonl";
  options.writer_threads = 1;
  options.durable = false;
  FramePipeline pipeline(options);
  pipeline.Push(MakeJob(dir, 0));
  pipeline.Finish();
  ASSERT_TRUE(pipeline.error());
  EXPECT_EQ(pipeline.frames_listed(), 0);
  fs::remove_all(dir);
}

// With the writer stuck, Push blocks once the queue's memory is used up (the
// camera's buffers then fill: frames lost are counted there, not hidden), and
// resumes as soon as a writer takes a frame.
TEST(FramePipeline, PushBlocksWhileTheQueueIsFull) {
  const fs::path dir = test::UniqueTempDir("igi_frame_pipeline");
  fs::create_directories(dir / "frames");
  std::atomic<bool> release{false};
  FramePipelineOptions options;
  options.manifest_path = dir / "manifest.jsonl";
  options.writer_threads = 1;
  options.durable = false;
  options.queue_bytes = 2 * 16 * 8;  // two frames
  options.write_file = [&](const fs::path& path, const Frame& frame) {
    while (!release.load()) std::this_thread::yield();
    WriteFrame(path, frame, /*durable=*/false);
  };
  FramePipeline pipeline(options);
  // The writer holds at most one frame and the queue two more: the 4th Push
  // (or at the latest the 5th) must wait.
  std::atomic<int> pushed{0};
  std::thread producer([&] {
    for (int i = 0; i < 6; ++i) {
      if (pipeline.Push(MakeJob(dir, i))) ++pushed;
    }
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  EXPECT_LE(pushed.load(), 3);
  release.store(true);
  producer.join();
  pipeline.Finish();
  EXPECT_EQ(pushed.load(), 6);
  EXPECT_EQ(ListedFrames(options.manifest_path), (std::vector<int>{0, 1, 2, 3, 4, 5}));
  fs::remove_all(dir);
}

TEST(FramePipelineOptions, RejectsBadValues) {
  FramePipelineOptions options;
  options.writer_threads = 0;
  EXPECT_THROW(options.Validate(), InputError);
  options.writer_threads = 2;
  options.queue_bytes = 0;
  EXPECT_THROW(options.Validate(), InputError);
}

}  // namespace
}  // namespace igi::capture
