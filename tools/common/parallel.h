#pragma once
// The one parallel primitive of igi (STYLE.md §8): ParallelFor over TBB, in an arena limited to
// `num_threads` (0 = the process default, set by --threads; that default 0 = all cores).
// An exception thrown by `fn` stops the loop and is rethrown in the caller. Once cancellation is
// requested (tools/common/progress.h RequestCancel) no further item starts: the loop throws
// Cancelled, so every parallel stage stops within one item, reporting progress or not.

#include <cstdint>
#include <functional>

namespace igi {

// Sets the default used when a call passes num_threads = 0 (0 here = all cores).
void SetDefaultThreads(int num_threads);
// The thread count a call with `num_threads` will use (>= 1).
int ResolveThreads(int num_threads = 0);

// Calls fn(i) for every i in [begin, end).
void ParallelFor(int64_t begin, int64_t end, const std::function<void(int64_t)>& fn,
                 int num_threads = 0, int64_t grain = 1);

// Calls fn(chunk_begin, chunk_end) over disjoint chunks covering [begin, end).
void ParallelForRange(int64_t begin, int64_t end,
                      const std::function<void(int64_t, int64_t)>& fn, int num_threads = 0,
                      int64_t grain = 1);

}  // namespace igi
