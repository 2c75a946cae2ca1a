#pragma once
// A progress bar for long work: drawn on stderr when stderr is a terminal, silent in pipes, in
// CI (CI set) and when IGI_NO_PROGRESS is set. It appears only once the work has run for
// `delay_s` (about two seconds, docs/ARCHITECTURE.md), so quick jobs stay quiet. Thread-safe.

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <mutex>
#include <string>

#include "tools/common/error.h"

namespace igi {

// True when progress should be drawn: stderr is a TTY and neither CI nor IGI_NO_PROGRESS is set.
bool ProgressAllowed();

// A process-wide observer of every Progress, drawn or not (the Python package's progress
// callback): called with the label, the units done and the total at most ten times a second per
// Progress, and once when it finishes. Calls for one Progress do not overlap; calls for different
// ones (work running side by side) may, so the observer serialises what it needs to. An empty
// function removes the observer.
using ProgressObserver = std::function<void(const std::string& label, int64_t done, int64_t total)>;
void SetProgressObserver(ProgressObserver observer);

// Cancellation of long work (Ctrl-C in the Python package): once requested, every Progress::Add
// throws Cancelled, so the work stops at its next unit and unwinds; outputs are written
// atomically after the work, so nothing partial is left. Cleared by ClearCancel.
void RequestCancel();
void ClearCancel();
bool CancelRequested();

// The work stopped because cancellation was requested (exit code 1).
class Cancelled : public Error {
 public:
  explicit Cancelled(const std::string& label) : Error(label + ": cancelled") {}
};

class Progress {
 public:
  Progress(std::string label, int64_t total, double delay_s = 2.0,
           bool enabled = ProgressAllowed());
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  // Adds `n` finished units; redraws and tells the observer at most ten times a second. Throws
  // Cancelled once cancellation is requested.
  void Add(int64_t n = 1);
  int64_t done() const { return done_.load(); }
  // Draws the final state (if the bar was shown) and ends the line.
  void Finish();

 private:
  void Draw(bool final_draw);
  void Notify();
  std::string label_;
  int64_t total_;
  double delay_s_;
  bool enabled_;
  bool shown_ = false;
  bool finished_ = false;
  std::atomic<int64_t> done_{0};
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_draw_;
  std::chrono::steady_clock::time_point last_notify_;
  std::mutex mutex_;
};

}  // namespace igi
