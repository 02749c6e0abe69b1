#include "util/parallel_for.h"

#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>
#include <vector>

namespace dgmm {
namespace {

TEST(ParallelFor, RunsEveryTaskOnceWhateverTheThreadCount) {
  for (int threads : {1, 2, 7, 100}) {
    std::vector<int> runs(50, 0);
    ParallelFor(50, threads, [&](int t) { ++runs[t]; });
    for (int t = 0; t < 50; ++t) EXPECT_EQ(runs[t], 1) << "task " << t << ", " << threads << " threads";
  }
  ParallelFor(0, 4, [](int) { FAIL() << "no task expected"; });
}

TEST(ParallelFor, StartsNoTaskAfterOneHasFailed) {
  // On one thread the tasks run in order: task 3 throws, and 4 .. 99 must not start.
  std::atomic<int> started{0};
  EXPECT_THROW(ParallelFor(100, 1,
                           [&](int t) {
                             ++started;
                             if (t == 3) throw std::runtime_error("task 3");
                           }),
               std::runtime_error);
  EXPECT_EQ(started.load(), 4);
}

TEST(ParallelFor, RethrowsTheFailureAfterTheRunningTasksFinish) {
  // Two threads: task 0 throws while task 1 is still running; task 1 completes before the rethrow.
  std::atomic<bool> throwing{false}, slow_done{false};
  std::atomic<int> started{0};
  try {
    ParallelFor(2, 2, [&](int t) {
      ++started;
      while (started.load() < 2) {}  // both tasks are running
      if (t == 0) {
        throwing = true;
        throw std::invalid_argument("task 0");
      }
      while (!throwing.load()) {}
      for (volatile int i = 0; i < 1000000; i = i + 1) {}
      slow_done = true;
    });
    FAIL() << "expected the failure to be rethrown";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "task 0");
  }
  EXPECT_TRUE(slow_done.load());
}

}  // namespace
}  // namespace dgmm
