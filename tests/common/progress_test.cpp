#include "tools/common/progress.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "tools/common/parallel.h"

namespace igi {
namespace {

// Runs `fn` with stderr sent to a file of this process's own (ctest runs the tests of this file
// as parallel processes: a shared name let one test read the other's progress bar) and returns
// what it wrote.
template <typename Fn>
std::string CaptureStderr(Fn fn) {
  static int calls = 0;
  const auto path =
      std::filesystem::temp_directory_path() /
      ("igi_progress_stderr_" + std::to_string(getpid()) + "_" + std::to_string(calls++) + ".txt");
  std::fflush(stderr);
  const int saved = dup(STDERR_FILENO);
  const int fd = open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  dup2(fd, STDERR_FILENO);
  close(fd);
  fn();
  std::fflush(stderr);
  dup2(saved, STDERR_FILENO);
  close(saved);
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  std::filesystem::remove(path);
  return ss.str();
}

TEST(ProgressTest, QuietInPipesAndCi) {
  // stderr is a file here, not a terminal.
  EXPECT_EQ(CaptureStderr([] { EXPECT_FALSE(ProgressAllowed()); }), "");
  setenv("CI", "true", 1);
  EXPECT_FALSE(ProgressAllowed());
  unsetenv("CI");
  const std::string out = CaptureStderr([] {
    Progress progress("work", 10);  // enabled only on a terminal: not here
    for (int i = 0; i < 10; ++i) progress.Add();
  });
  EXPECT_EQ(out, "");
}

TEST(ProgressTest, DrawsWhenEnabledAndAfterTheDelay) {
  const std::string shown = CaptureStderr([] {
    Progress progress("render", 4, /*delay_s=*/0.0, /*enabled=*/true);
    for (int i = 0; i < 4; ++i) progress.Add();
    progress.Finish();
    EXPECT_EQ(progress.done(), 4);
  });
  EXPECT_NE(shown.find("render ["), std::string::npos) << shown;
  EXPECT_NE(shown.find("100%"), std::string::npos) << shown;
  EXPECT_EQ(shown.back(), '\n');
  // Work shorter than the delay draws nothing.
  const std::string quick = CaptureStderr([] {
    Progress progress("quick", 4, /*delay_s=*/60.0, /*enabled=*/true);
    progress.Add(4);
  });
  EXPECT_EQ(quick, "");
}

// The observer sees every Progress, drawn or not, and the final count once it finishes.
TEST(Progress, ObserverSeesUndrawnWorkAndItsEnd) {
  std::vector<std::pair<int64_t, int64_t>> seen;
  std::string label;
  SetProgressObserver([&](const std::string& l, int64_t done, int64_t total) {
    label = l;
    seen.emplace_back(done, total);
  });
  {
    Progress progress("observed", 5, 2.0, /*enabled=*/false);
    for (int i = 0; i < 5; ++i) progress.Add();
  }
  SetProgressObserver(nullptr);
  {
    Progress progress("unobserved", 5, 2.0, false);
    progress.Add(5);
  }
  EXPECT_EQ(label, "observed");
  ASSERT_FALSE(seen.empty());
  EXPECT_EQ(seen.back(), std::make_pair(int64_t{5}, int64_t{5}));
}

// A requested cancellation stops parallel work at its next unit with Cancelled, in the caller's
// thread, and work after ClearCancel runs to the end.
TEST(Progress, CancellationStopsParallelWorkWithCancelled) {
  std::atomic<int64_t> ran{0};
  const auto work = [&] {
    Progress progress("cancellable", 1000, 2.0, false);
    ParallelFor(0, 1000, [&](int64_t i) {
      if (i == 10) RequestCancel();
      ++ran;
      progress.Add();
    });
  };
  try {
    work();
    FAIL() << "no Cancelled thrown";
  } catch (const Cancelled& e) {
    // The item that asked stops in its Progress::Add, other workers before their next item.
    const std::string what = e.what();
    EXPECT_TRUE(what == "cancellable: cancelled" || what == "parallel work: cancelled") << what;
    EXPECT_EQ(e.code(), ExitCode::kFailed);
  }
  EXPECT_LT(ran.load(), 1000);
  ClearCancel();
  ran = 0;
  Progress progress("after", 1000, 2.0, false);
  EXPECT_NO_THROW(ParallelFor(0, 1000, [&](int64_t) {
    ++ran;
    progress.Add();
  }));
  EXPECT_EQ(ran.load(), 1000);
}

// A loop that reports no progress stops too: no item starts once cancellation is requested,
// whether the loop runs on one thread or several.
TEST(Progress, CancellationStopsALoopThatReportsNoProgress) {
  for (const int threads : {1, 2}) {
    std::atomic<int64_t> ran{0};
    EXPECT_THROW(ParallelFor(
                     0, 1000,
                     [&](int64_t i) {
                       if (i == 10) RequestCancel();
                       ++ran;
                     },
                     threads),
                 Cancelled);
    EXPECT_LT(ran.load(), 1000) << threads;
    EXPECT_THROW(ParallelFor(0, 10, [&](int64_t) { ++ran; }, threads), Cancelled);
    ClearCancel();
    ran = 0;
    ParallelFor(0, 1000, [&](int64_t) { ++ran; }, threads);
    EXPECT_EQ(ran.load(), 1000) << threads;
  }
}

}  // namespace
}  // namespace igi
