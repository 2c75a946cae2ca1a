#include "tools/common/parallel.h"

#include <gtest/gtest.h>

#include <atomic>
#include <mutex>
#include <set>
#include <stdexcept>
#include <thread>
#include <vector>

namespace igi {
namespace {

TEST(ParallelTest, VisitsEveryIndexOnce) {
  std::vector<std::atomic<int>> hits(10007);
  ParallelFor(0, 10007, [&](int64_t i) { hits[i]++; });
  for (auto& h : hits) EXPECT_EQ(h.load(), 1);
}

TEST(ParallelTest, RangesCoverWithoutOverlap) {
  std::vector<int> hits(1000, 0);
  std::mutex m;
  ParallelForRange(0, 1000, [&](int64_t b, int64_t e) {
    std::lock_guard<std::mutex> lock(m);
    for (int64_t i = b; i < e; ++i) hits[i]++;
  }, 0, 64);
  for (int h : hits) EXPECT_EQ(h, 1);
}

TEST(ParallelTest, OneThreadRunsOnTheCaller) {
  std::set<std::thread::id> ids;
  std::mutex m;
  ParallelFor(0, 100, [&](int64_t) {
    std::lock_guard<std::mutex> lock(m);
    ids.insert(std::this_thread::get_id());
  }, 1);
  ASSERT_EQ(ids.size(), 1u);
  EXPECT_EQ(*ids.begin(), std::this_thread::get_id());
}

TEST(ParallelTest, ExceptionsReachTheCaller) {
  EXPECT_THROW(ParallelFor(0, 100, [](int64_t i) {
    if (i == 42) throw std::runtime_error("boom");
  }), std::runtime_error);
}

TEST(ParallelTest, ResolveThreadsHonoursDefault) {
  SetDefaultThreads(3);
  EXPECT_EQ(ResolveThreads(0), 3);
  EXPECT_EQ(ResolveThreads(2), 2);
  SetDefaultThreads(0);
  EXPECT_GE(ResolveThreads(0), 1);
}

}  // namespace
}  // namespace igi
