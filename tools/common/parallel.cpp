#include "tools/common/parallel.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <atomic>
#include <thread>

#include "tools/common/progress.h"

namespace igi {
namespace {
std::atomic<int> g_default_threads{0};
}  // namespace

void SetDefaultThreads(int num_threads) { g_default_threads = num_threads < 0 ? 0 : num_threads; }

int ResolveThreads(int num_threads) {
  if (num_threads <= 0) num_threads = g_default_threads.load();
  if (num_threads <= 0) num_threads = tbb::this_task_arena::max_concurrency();
  return num_threads < 1 ? 1 : num_threads;
}

void ParallelForRange(int64_t begin, int64_t end,
                      const std::function<void(int64_t, int64_t)>& fn, int num_threads,
                      int64_t grain) {
  if (end <= begin) return;
  if (CancelRequested()) throw Cancelled("parallel work");
  const int threads = ResolveThreads(num_threads);
  if (threads == 1 || end - begin <= grain) {
    fn(begin, end);
    return;
  }
  tbb::task_arena arena(threads);
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<int64_t>(begin, end, grain < 1 ? 1 : grain),
                      [&](const tbb::blocked_range<int64_t>& r) {
                        if (CancelRequested()) throw Cancelled("parallel work");
                        fn(r.begin(), r.end());
                      });
  });
}

void ParallelFor(int64_t begin, int64_t end, const std::function<void(int64_t)>& fn,
                 int num_threads, int64_t grain) {
  ParallelForRange(
      begin, end,
      [&fn](int64_t b, int64_t e) {
        for (int64_t i = b; i < e; ++i) {
          if (CancelRequested()) throw Cancelled("parallel work");
          fn(i);
        }
      },
      num_threads, grain);
}

}  // namespace igi
