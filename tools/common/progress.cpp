#include "tools/common/progress.h"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <memory>

namespace igi {
namespace {

std::mutex g_observer_mutex;
std::shared_ptr<const ProgressObserver> g_observer;
std::atomic<bool> g_observed{false};
std::atomic<bool> g_cancel{false};

std::shared_ptr<const ProgressObserver> CurrentObserver() {
  std::lock_guard<std::mutex> lock(g_observer_mutex);
  return g_observer;
}

}  // namespace

void SetProgressObserver(ProgressObserver observer) {
  std::lock_guard<std::mutex> lock(g_observer_mutex);
  g_observer = observer ? std::make_shared<const ProgressObserver>(std::move(observer)) : nullptr;
  g_observed.store(g_observer != nullptr);
}

void RequestCancel() { g_cancel.store(true); }
void ClearCancel() { g_cancel.store(false); }
bool CancelRequested() { return g_cancel.load(std::memory_order_relaxed); }

bool ProgressAllowed() {
  if (std::getenv("CI") != nullptr || std::getenv("IGI_NO_PROGRESS") != nullptr) return false;
  const char* term = std::getenv("TERM");
  if (term != nullptr && std::string(term) == "dumb") return false;
  return isatty(STDERR_FILENO) == 1;
}

Progress::Progress(std::string label, int64_t total, double delay_s, bool enabled)
    : label_(std::move(label)),
      total_(total),
      delay_s_(delay_s),
      enabled_(enabled),
      start_(std::chrono::steady_clock::now()),
      last_draw_(start_),
      last_notify_(start_) {}

Progress::~Progress() { Finish(); }

void Progress::Add(int64_t n) {
  done_.fetch_add(n);
  if (CancelRequested()) throw Cancelled(label_);
  const bool observed = g_observed.load(std::memory_order_relaxed);
  if (!enabled_ && !observed) return;
  const auto now = std::chrono::steady_clock::now();
  std::unique_lock<std::mutex> lock(mutex_, std::try_to_lock);
  if (!lock.owns_lock() || finished_) return;
  if (observed && std::chrono::duration<double>(now - last_notify_).count() >= 0.1) {
    last_notify_ = now;
    Notify();
  }
  if (!enabled_) return;
  const double since_start = std::chrono::duration<double>(now - start_).count();
  const double since_draw = std::chrono::duration<double>(now - last_draw_).count();
  if (since_start < delay_s_ || (shown_ && since_draw < 0.1)) return;
  last_draw_ = now;
  Draw(false);
}

void Progress::Finish() {
  if (!enabled_ && !g_observed.load()) return;
  std::lock_guard<std::mutex> lock(mutex_);
  if (finished_) return;
  finished_ = true;
  Notify();
  if (shown_) Draw(true);
}

void Progress::Notify() {
  if (const std::shared_ptr<const ProgressObserver> observer = CurrentObserver()) {
    (*observer)(label_, done_.load(), total_);
  }
}

void Progress::Draw(bool final_draw) {
  shown_ = true;
  const int64_t done = done_.load();
  const double fraction = total_ > 0 ? std::min(1.0, double(done) / double(total_)) : 0.0;
  constexpr int kWidth = 30;
  const int filled = static_cast<int>(fraction * kWidth + 0.5);
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  const double eta = fraction > 0 ? elapsed * (1 - fraction) / fraction : 0.0;
  std::string bar(filled, '#');
  bar.append(kWidth - filled, '-');
  std::fprintf(stderr, "\r%s [%s] %3.0f%% %lld/%lld %.0fs%s", label_.c_str(), bar.c_str(),
               fraction * 100, static_cast<long long>(done), static_cast<long long>(total_),
               final_draw ? elapsed : eta, final_draw ? "    \n" : " left");
  std::fflush(stderr);
}

}  // namespace igi
