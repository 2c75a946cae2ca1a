#pragma once
// A progress bar for long work: drawn on stderr when stderr is a terminal, silent in pipes, in
// CI (CI set) and when IGI_NO_PROGRESS is set. It appears only once the work has run for
// `delay_s` (about two seconds, docs/ARCHITECTURE.md), so quick jobs stay quiet. Thread-safe.

#include <atomic>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>

namespace igi {

// True when progress should be drawn: stderr is a TTY and neither CI nor IGI_NO_PROGRESS is set.
bool ProgressAllowed();

class Progress {
 public:
  Progress(std::string label, int64_t total, double delay_s = 2.0, bool enabled = ProgressAllowed());
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  // Adds `n` finished units; redraws at most ten times a second.
  void Add(int64_t n = 1);
  int64_t done() const { return done_.load(); }
  // Draws the final state (if the bar was shown) and ends the line.
  void Finish();

 private:
  void Draw(bool final_draw);
  std::string label_;
  int64_t total_;
  double delay_s_;
  bool enabled_;
  bool shown_ = false;
  bool finished_ = false;
  std::atomic<int64_t> done_{0};
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_draw_;
  std::mutex mutex_;
};

}  // namespace igi
