#include "capture/frame_pipeline.h"

#include <spdlog/spdlog.h>

#include "capture/frame_writer.h"
#include "tools/common/error.h"

namespace igi::capture {

void FramePipelineOptions::Validate() const {
  ProblemList problems;
  if (writer_threads < 1 || writer_threads > 64) {
    problems.Add("", "--writer-threads", std::to_string(writer_threads), "must be in [1, 64]");
  }
  if (queue_bytes < 1) problems.Add("", "--queue-mib", "0", "must be > 0");
  problems.ThrowIfAny();
}

FramePipeline::FramePipeline(FramePipelineOptions options, FrameListedCallback on_listed)
    : options_(std::move(options)),
      on_listed_(std::move(on_listed)),
      start_(std::chrono::steady_clock::now()) {
  options_.Validate();
  if (!options_.write_file) {
    const bool durable = options_.durable;
    options_.write_file = [durable](const std::filesystem::path& path, const Frame& frame) {
      WriteFrame(path, frame, durable);
    };
  }
  for (int i = 0; i < options_.writer_threads; ++i) {
    writers_.emplace_back([this] { WriterLoop(); });
  }
}

FramePipeline::~FramePipeline() { Finish(); }

bool FramePipeline::Push(FrameJob job) {
  const size_t bytes = job.frame.data.size();
  std::unique_lock lock(queue_mutex_);
  queue_changed_.wait(lock, [&] {
    return queue_.empty() || queued_bytes_ + bytes <= options_.queue_bytes || error_ || finishing_;
  });
  if (error_ || finishing_) return false;
  queued_bytes_ += bytes;
  queue_.push_back({next_sequence_++, bytes, std::move(job)});
  lock.unlock();
  queue_changed_.notify_all();
  return true;
}

void FramePipeline::Finish() {
  {
    std::lock_guard lock(queue_mutex_);
    finishing_ = true;
  }
  queue_changed_.notify_all();
  for (std::thread& writer : writers_) {
    if (writer.joinable()) writer.join();
  }
}

int FramePipeline::frames_listed() const {
  std::lock_guard lock(list_mutex_);
  return frames_listed_;
}

double FramePipeline::seconds_to_last_listed() const {
  std::lock_guard lock(list_mutex_);
  return seconds_to_last_listed_;
}

std::optional<std::string> FramePipeline::error() const {
  std::lock_guard lock(queue_mutex_);
  return error_;
}

void FramePipeline::RecordError(const std::string& message) {
  {
    std::lock_guard lock(queue_mutex_);
    if (!error_) error_ = message;
    // Frames not yet started are dropped: nothing after a failure is listed
    // out of turn, and the run ends as soon as the receiver sees the error.
    queue_.clear();
    queued_bytes_ = 0;
  }
  queue_changed_.notify_all();
}

void FramePipeline::WriterLoop() {
  for (;;) {
    Job job;
    {
      std::unique_lock lock(queue_mutex_);
      queue_changed_.wait(lock, [&] { return !queue_.empty() || finishing_ || error_; });
      if (queue_.empty()) return;  // finishing, or failed (the queue was cleared)
      job = std::move(queue_.front());
      queue_.pop_front();
      queued_bytes_ -= job.bytes;
    }
    queue_changed_.notify_all();  // room for Push
    bool written = false;
    try {
      options_.write_file(job.frame.file, job.frame.frame);
      written = true;
    } catch (const std::exception& e) {
      spdlog::error("{}", e.what());
      RecordError(e.what());
    }
    // The line waits for every earlier frame: the manifest keeps push order.
    ListInOrder(job.sequence, written ? &job.frame.entry : nullptr);
  }
}

void FramePipeline::ListInOrder(uint64_t sequence, const ManifestEntry* entry) {
  std::unique_lock lock(list_mutex_);
  turn_changed_.wait(lock, [&] { return next_to_list_ == sequence; });
  if (entry != nullptr) {
    try {
      AppendManifest(options_.manifest_path, *entry, options_.durable);
      ++frames_listed_;
      seconds_to_last_listed_ =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
      if (on_listed_) on_listed_(frames_listed_);
    } catch (const std::exception& e) {
      spdlog::error("{}", e.what());
      RecordError(e.what());
    }
  }
  ++next_to_list_;
  lock.unlock();
  turn_changed_.notify_all();
}

}  // namespace igi::capture
