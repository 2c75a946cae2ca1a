#pragma once
// Writes frames on writer threads while the caller keeps receiving: a bounded
// queue of frames in memory, `writer_threads` threads that write each frame's
// file (atomically, see frame_writer.h), and the manifest lines appended in the
// order the frames were pushed, each only after its file is renamed into place.
//
// Nothing hidden, nothing lost:
// - Push() blocks while the queue is full (the disk is slower than the
//   camera): the camera's own buffers then fill and the frames it cannot hand
//   over show up as frame_id gaps, which the capture reports as skipped.
// - A frame that cannot be written stops the pipeline: its slot is left out of
//   the manifest, frames still queued are dropped (not listed), frames already
//   written keep their lines, and error() says why. Push() then returns false.
// - Finish() writes everything still queued (unless failed) and joins the
//   threads; the destructor does the same.

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "capture/camera.h"
#include "capture/manifest.h"

namespace igi::capture {

struct FrameJob {
  std::filesystem::path file;  // where the frame goes (absolute, or relative to the cwd)
  Frame frame;
  ManifestEntry entry;  // its manifest line, appended once the file is in place
};

// Writes `frame` to `path`; throws igi::Error on failure (WriteFrame by default).
using FrameFileWriter = std::function<void(const std::filesystem::path& path, const Frame& frame)>;

struct FramePipelineOptions {
  std::filesystem::path manifest_path;  // DIR/manifest.jsonl
  int writer_threads = 2;               // files written at once
  // Memory for frames waiting for a writer (their data), in bytes; one frame
  // is always let in, however large.
  size_t queue_bytes = size_t(256) << 20;
  bool durable = true;         // fsync each file and manifest line (see frame_writer.h)
  FrameFileWriter write_file;  // empty: WriteFrame(path, frame, durable)

  // InputError naming the flag (--writer-threads, --queue-mib) when out of
  // range.
  void Validate() const;
};

// Called after each manifest line, under the pipeline's lock (one at a time, in
// push order), with the number of frames listed so far.
using FrameListedCallback = std::function<void(int frames_listed)>;

class FramePipeline {
 public:
  explicit FramePipeline(FramePipelineOptions options, FrameListedCallback on_listed = {});
  ~FramePipeline();
  FramePipeline(const FramePipeline&) = delete;
  FramePipeline& operator=(const FramePipeline&) = delete;

  // Queues a frame; blocks while the queue is full. False (frame not queued)
  // once a write has failed or after Finish().
  bool Push(FrameJob job);
  // Writes what is queued (unless a write failed), then joins the writers.
  void Finish();

  // Frames whose file and manifest line are both in place.
  int frames_listed() const;
  // Seconds from construction to the last manifest line.
  double seconds_to_last_listed() const;
  // The first write failure, if any.
  std::optional<std::string> error() const;

 private:
  struct Job {
    uint64_t sequence = 0;
    size_t bytes = 0;
    FrameJob frame;
  };
  void WriterLoop();
  void ListInOrder(uint64_t sequence, const ManifestEntry* entry);

  FramePipelineOptions options_;
  FrameListedCallback on_listed_;
  void RecordError(const std::string& message);

  // The queue. Lock order: list_mutex_ before queue_mutex_, never the reverse.
  mutable std::mutex queue_mutex_;
  std::condition_variable queue_changed_;  // a job was queued or taken, or the state changed
  std::deque<Job> queue_;
  size_t queued_bytes_ = 0;
  uint64_t next_sequence_ = 0;  // given to the next pushed frame
  bool finishing_ = false;
  std::optional<std::string> error_;
  // The manifest, appended in push order (a writer waits for its turn).
  mutable std::mutex list_mutex_;
  std::condition_variable turn_changed_;  // next_to_list_ advanced
  uint64_t next_to_list_ = 0;             // the frame whose manifest line comes next
  int frames_listed_ = 0;
  double seconds_to_last_listed_ = 0.0;
  std::chrono::steady_clock::time_point start_;
  std::vector<std::thread> writers_;
};

}  // namespace igi::capture
